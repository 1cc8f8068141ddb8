//! No output replaces a file its command reads: an output file or folder aimed at a scene, one
//! of its assets or a trace is refused before anything is written, the input kept.

use crate::cli::{assert_clean_failure, vitreous};

#[test]
fn outputs_that_would_replace_an_input_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = crate::compare::sphere_copy(dir.path());
    let s = scene.to_str().unwrap();
    let out = dir.path().join("run");
    std::fs::create_dir_all(out.join("frames")).unwrap();
    // A trace kept where a replay writes its frame log, and one under a frame image's name.
    let trace = out.join("frames.csv");
    let made = vitreous(
        &[
            "trace",
            "synth",
            "--scene",
            s,
            "-o",
            trace.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(made.status.success(), "{made:?}");
    let framed = out.join("frames/000000-left.png");
    std::fs::copy(&trace, &framed).unwrap();
    let (o, t, f) = (
        out.to_str().unwrap(),
        trace.to_str().unwrap(),
        framed.to_str().unwrap(),
    );
    let scene_before = std::fs::read(&scene).unwrap();
    let trace_before = std::fs::read(&trace).unwrap();
    let frames = out.join("frames");
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["replay", s, "--trace", t, "--out", o, "--quiet"],
            &["--out", "writes frames.csv there", "is the input file"],
        ),
        (
            &["replay", s, "--trace", f, "--out", o, "--quiet"],
            &["--out", "frames/000000-left.png", "(--trace)"],
        ),
        (
            &[
                "reference",
                s,
                "--trace",
                f,
                "--out",
                frames.to_str().unwrap(),
            ],
            &["--out", "writes 000000-left.png there", "(--trace)"],
        ),
        (
            &["trace", "synth", "--scene", s, "-o", s],
            &["-o", "is the input file", "(--scene)"],
        ),
        (
            &["trace", "plot", t, "--scene", s, "-o", t],
            &["--out", "is the input file", "(TRACE)"],
        ),
        (
            &["soak", s, "--json", s, "--minutes", "0.01"],
            &["--json", "is the input file", "(SCENE)"],
        ),
    ];
    for (args, needles) in cases {
        assert_clean_failure(&vitreous(args, dir.path()), needles);
    }
    assert_eq!(std::fs::read(&scene).unwrap(), scene_before);
    assert_eq!(std::fs::read(&trace).unwrap(), trace_before);
    assert_eq!(std::fs::read(&framed).unwrap(), trace_before);
    assert!(!out.join("summary.json").exists());
}
