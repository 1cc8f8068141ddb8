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

/// The live commands check before a runtime or a window is asked for: `run` and `view` here
/// have neither, so each refusal is the guard's; `study plan` checks before reading.
#[test]
fn live_sessions_and_studies_refuse_outputs_over_their_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, assets) = crate::compare::sphere_copy(dir.path());
    let s = scene.to_str().unwrap();
    let floor = assets[1].to_str().unwrap();
    // A folder whose summary.json is the scene (a hard link), and one whose frames.csv is a
    // trace.
    let linked = dir.path().join("linked");
    std::fs::create_dir(&linked).unwrap();
    std::fs::hard_link(&scene, linked.join("summary.json")).unwrap();
    let logged = dir.path().join("logged");
    std::fs::create_dir(&logged).unwrap();
    let trace = logged.join("frames.csv");
    std::fs::write(&trace, "a trace").unwrap();
    let protocol = dir.path().join("study.toml");
    std::fs::write(&protocol, "a protocol").unwrap();
    let (l, g, t, p) = (
        linked.to_str().unwrap(),
        logged.to_str().unwrap(),
        trace.to_str().unwrap(),
        protocol.to_str().unwrap(),
    );
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["run", s, "--record", s],
            &["--record", "is the input file", "(SCENE)"],
        ),
        (
            &["run", s, "--gaze-trace", t, "--out", g],
            &["--out", "writes frames.csv there", "(--gaze-trace)"],
        ),
        (
            &["view", s, "--screenshot", floor],
            &["--screenshot", "(floor.photo in"],
        ),
        (
            &["view", s, "--out", l],
            &["--out", "writes summary.json there", "(SCENE)"],
        ),
        (
            &["view", s, "--trace", t, "--record", t],
            &["--record", "(--trace)"],
        ),
        (
            &[
                "study",
                "plan",
                p,
                "--participants",
                "1",
                "--seed",
                "1",
                "-o",
                p,
            ],
            &["--out", "(PROTOCOL)"],
        ),
    ];
    for (args, needles) in cases {
        let message = assert_clean_failure(&vitreous(args, dir.path()), needles);
        assert!(!message.contains("OpenXR"), "{message}");
    }
    assert_eq!(std::fs::read(&trace).unwrap(), b"a trace");
    assert_eq!(std::fs::read(&protocol).unwrap(), b"a protocol");
}
