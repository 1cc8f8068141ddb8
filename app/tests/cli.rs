//! The `vitreous` command on bad input: a non-zero exit, a one-paragraph message naming the
//! culprit, no panic, and no output files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub(crate) fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub(crate) fn vitreous(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(args)
        .current_dir(cwd)
        .env("RUST_LOG", "warn")
        .output()
        .expect("the vitreous binary runs")
}

/// Asserts a failed run with one error paragraph that mentions every `needle`.
pub(crate) fn assert_clean_failure(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "expected failure, stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert!(!stderr.contains("RUST_BACKTRACE"), "panic: {stderr}");
    let message = stderr.trim();
    assert!(!message.is_empty(), "no message");
    assert!(
        !message.contains("\n\n"),
        "more than one paragraph: {message}"
    );
    for needle in needles {
        assert!(
            message.contains(needle),
            "'{needle}' missing from: {message}"
        );
    }
    message.to_owned()
}

pub(crate) fn scene(name: &str) -> String {
    workspace()
        .join("config/scenes")
        .join(name)
        .display()
        .to_string()
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// `vitreous replay SCENE --out OUT_DIR --quiet` run in `cwd`.
fn replay_into(scene: &str, out_dir: &Path, cwd: &Path) -> Output {
    let out_dir = out_dir.to_str().unwrap();
    vitreous(&["replay", scene, "--out", out_dir, "--quiet"], cwd)
}

#[test]
fn malformed_scene_names_file_and_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = write(
        dir.path(),
        "bad.toml",
        "[object]\nmodel = \"x.glb\"\ndiameter_m = oops\n",
    );
    let out_dir = dir.path().join("out");
    let out = replay_into(&bad, &out_dir, dir.path());
    assert_clean_failure(&out, &["bad.toml", ":3:"]);
    assert!(!out_dir.exists(), "output folder created on bad input");
}

#[test]
fn missing_trace_is_named_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--trace",
            "no-such-trace.csv",
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["no-such-trace.csv"]);
    assert!(!out_dir.exists());
}

#[test]
fn recorded_fields_need_a_recording_with_views_lines() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let trace = workspace().join("config/traces/neutral-then-turned.csv");
    let run = |fields: &str| {
        vitreous(
            &[
                "replay",
                &scene("glass-sphere.toml"),
                "--trace",
                trace.to_str().unwrap(),
                "--fields",
                fields,
                "--out",
                out_dir.to_str().unwrap(),
                "--quiet",
            ],
            dir.path(),
        )
    };
    let message = assert_clean_failure(&run("recorded"), &["neutral-then-turned.csv"]);
    assert!(message.contains("no views lines"), "{message}");
    assert_clean_failure(&run("headset"), &["--fields", "headset"]);
    assert!(!out_dir.exists());
}

#[test]
fn trace_with_nan_time_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let header = vitreous_trace::format::COLUMNS.join(",");
    let good = "0,0,0,0,0,0,0,1,0,0,,,,,,,0,,,,,,,,,,,,,,,,";
    let nan = "NaN,0,0,0,0,0,0,1,0,0,,,,,,,0,,,,,,,,,,,,,,,,";
    let trace = write(
        dir.path(),
        "nan.csv",
        &format!("# vitreous-trace v1\n{header}\n{good}\n{nan}\n"),
    );
    let out_dir = dir.path().join("out");
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--trace",
            &trace,
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["nan.csv", ":4"]);
    assert!(!out_dir.exists());
}

#[test]
fn truncated_trace_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let header = vitreous_trace::format::COLUMNS.join(",");
    let trace = write(
        dir.path(),
        "short.csv",
        &format!("# vitreous-trace v1\n{header}\n0,0,0,0,0,0\n"),
    );
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--trace",
            &trace,
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["short.csv", ":3"]);
    assert!(!dir.path().join("out").exists());
}

#[test]
fn absurd_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for size in ["0x0", "100000x10", "12x9"] {
        let out = vitreous(
            &[
                "replay",
                &scene("glass-sphere.toml"),
                "--size",
                size,
                "--quiet",
            ],
            dir.path(),
        );
        assert_clean_failure(&out, &["size"]);
    }
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--size",
            "wide",
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["WIDTHxHEIGHT"]);
    // `run` refuses one before it starts the runtime (there is none here).
    let out = vitreous(
        &["run", &scene("glass-sphere.toml"), "--size", "5x5"],
        dir.path(),
    );
    let message = assert_clean_failure(&out, &["eye image size 5x5 is outside 16..=8192"]);
    assert!(!message.contains("OpenXR"), "{message}");
    assert!(!dir.path().join("out").exists());
}

/// A pupil diameter outside 1-9 mm is refused whether or not the effects use it (the
/// glass sphere's condition c has no defocus).
#[test]
fn pupil_diameters_outside_the_human_range_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (command, pupil) in [
        ("replay", "-3"),
        ("replay", "0"),
        ("replay", "500"),
        ("bench", "4,50"),
    ] {
        let out = vitreous(
            &[
                command,
                &scene("glass-sphere.toml"),
                "--pupil-mm",
                pupil,
                "--frames",
                "2",
            ],
            dir.path(),
        );
        assert_clean_failure(&out, &["--pupil-mm", "is outside 1..=9 mm"]);
    }
    let out = vitreous(
        &["replay", &scene("glass-sphere.toml"), "--pupil-mm", "wide"],
        dir.path(),
    );
    assert_clean_failure(
        &out,
        &["--pupil-mm", "expected a pupil diameter in millimetres"],
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn unknown_and_unimplemented_effects_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--effects",
            "sparkle",
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["sparkle"]);
    // Every effect is implemented; the caustics need the scene's bake. A scene naming none
    // (torus.toml) and one naming a missing file are refused with the file named, and
    // nothing is written.
    let out = vitreous(
        &[
            "replay",
            &scene("torus.toml"),
            "--effects",
            "caustics",
            "--quiet",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["torus.toml", "caustics bake"]);
    let config = workspace().join("config").display().to_string();
    let text = std::fs::read_to_string(scene("glass-sphere.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{config}/"))
        .replace("bakes/glass-sphere.exr", "bakes/no-such-bake.exr");
    let missing = write(dir.path(), "sphere.toml", &text);
    let out = vitreous(
        &["replay", &missing, "--effects", "b", "--quiet"],
        dir.path(),
    );
    assert_clean_failure(&out, &["no-such-bake.exr", "vitreous bake"]);
    assert!(!dir.path().join("out").exists());
}

#[test]
fn import_of_header_only_recording_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let recording = workspace().join("trace/tests/data/sranipal/TESTVA03_2D_Spread9.csv");
    let target = dir.path().join("t.csv");
    let out = vitreous(
        &[
            "trace",
            "import",
            "--from",
            "sranipal",
            recording.to_str().unwrap(),
            "-o",
            target.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["TESTVA03_2D_Spread9.csv"]);
    assert!(!target.exists());
}

#[test]
fn import_from_unknown_format_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = vitreous(
        &["trace", "import", "--from", "tobii", "x.csv", "-o", "y.csv"],
        dir.path(),
    );
    assert_clean_failure(&out, &["tobii", "sranipal"]);
    assert!(!dir.path().join("y.csv").exists());
}

#[test]
fn imported_real_trace_replays_from_a_fresh_import() {
    let dir = tempfile::tempdir().unwrap();
    let recording = workspace().join("trace/tests/data/sranipal/TESTNA10_360VR_Fist3.csv");
    let target = dir.path().join("t.csv");
    let out = vitreous(
        &[
            "trace",
            "import",
            "--from",
            "sranipal",
            recording.to_str().unwrap(),
            "-o",
            target.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(report.contains("median IPD"), "{report}");
    let text = std::fs::read_to_string(&target).unwrap();
    assert!(text.starts_with("# vitreous-trace v1"));
}

#[test]
fn frame_counts_below_one_name_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    for bad in ["0", "-1"] {
        let out = vitreous(
            &[
                "replay",
                &scene("glass-sphere.toml"),
                "--frames",
                bad,
                "--out",
                out_dir.to_str().unwrap(),
            ],
            dir.path(),
        );
        assert_clean_failure(&out, &["--frames", "at least 1"]);
        assert!(
            !out_dir.exists(),
            "output folder created for --frames {bad}"
        );
    }
    let out = vitreous(
        &[
            "replay",
            &scene("glass-sphere.toml"),
            "--frames",
            "99999999999999999999",
        ],
        dir.path(),
    );
    assert_clean_failure(
        &out,
        &[
            "--frames",
            "99999999999999999999 is too large",
            "from 1 to 18446744073709551615",
        ],
    );
}

#[test]
fn import_onto_its_own_input_is_refused_and_the_recording_kept() {
    let dir = tempfile::tempdir().unwrap();
    let recording = dir.path().join("rec.csv");
    std::fs::write(&recording, "time(100ns),x\n1,2\n").unwrap();
    let before = std::fs::read(&recording).unwrap();
    let rec = recording.to_str().unwrap();
    let out = vitreous(
        &[
            "trace",
            "import",
            "--from",
            "sranipal",
            rec,
            "-o",
            "./rec.csv",
        ],
        dir.path(),
    );
    assert_clean_failure(&out, &["-o", "is the input file"]);
    assert_eq!(std::fs::read(&recording).unwrap(), before);
}

#[test]
fn an_unclosed_array_is_reported_on_its_own_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(workspace().join("config/scenes/glass-sphere.toml"))
        .unwrap()
        .replace(
            "position_m = [0.0, -0.26, -1.5]",
            "position_m = [0.0, -0.26, -1.5",
        );
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("position_m = [0.0, -0.26, -1.5"))
        .unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let bad = write(&scenes, "open.toml", &text);
    let out = vitreous(&["replay", &bad, "--frames", "1"], dir.path());
    let message = assert_clean_failure(&out, &["object.position_m", "never closed"]);
    assert!(
        message.contains(&format!("open.toml:{line}:")),
        "not reported at line {line}: {message}"
    );
}

#[test]
fn a_missing_scene_says_the_os_error_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = vitreous(&["replay", "nowhere.toml"], dir.path());
    let message = assert_clean_failure(&out, &["nowhere.toml"]);
    assert_eq!(message.matches("os error 2").count(), 1, "{message}");
}

#[test]
fn a_corrupt_bake_names_its_scene_and_the_command_that_bakes_it_again() {
    let dir = tempfile::tempdir().unwrap();
    let config = workspace().join("config");
    let broken = write(dir.path(), "broken.exr", "not an exr");
    let text = std::fs::read_to_string(config.join("scenes/glass-sphere.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", config.display()))
        .replace(
            &format!("\"{}/bakes/glass-sphere.exr\"", config.display()),
            &format!("{broken:?}"),
        );
    let scene = write(dir.path(), "copy.toml", &text);
    let out = vitreous(
        &["replay", &scene, "--effects", "c", "--frames", "1"],
        dir.path(),
    );
    let command = format!("`vitreous bake {scene} -o {broken}`");
    assert_clean_failure(
        &out,
        &[
            "is corrupt or not a caustics bake",
            &format!("(named by {scene})"),
            &command,
        ],
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_reference_of_the_saved_frames_while_saving_none_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    for option in ["--compare-reference", "--sphere-check"] {
        let out = vitreous(
            &[
                "replay",
                &scene("glass-sphere.toml"),
                option,
                "--save-every",
                "0",
                "--frames",
                "2",
                "--out",
                out_dir.to_str().unwrap(),
            ],
            dir.path(),
        );
        assert_clean_failure(&out, &[option, "--save-every 0 saves none"]);
        assert!(!out_dir.exists(), "output folder created with {option}");
    }
}

/// `vitreous bake SCENE -o OUTPUT` run in `cwd`, small and quick: 32 x 32 texels, 4096 rays,
/// no self-check.
fn bake_into(scene: &str, output: &Path, cwd: &Path) -> Output {
    let output = output.to_str().unwrap();
    let small = ["--resolution", "32", "--budget", "4096", "--no-self-check"];
    vitreous(&[&["bake", scene, "-o", output][..], &small].concat(), cwd)
}

#[test]
fn bake_writes_a_bake_its_scene_loads() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = scene("glass-sphere.toml");
    let output = dir.path().join("sphere.exr");
    let out = bake_into(&scene_path, &output, dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("sphere.exr"), "{stdout}");
    let scene = vitreous_scene::load_scene(Path::new(&scene_path)).unwrap();
    let bake = vitreous_scene::caustics::read_bake(&output, &scene.caustic_inputs_hash()).unwrap();
    assert_eq!((bake.width_px, bake.height_px), (32, 32));
    assert!(bake.gain.iter().any(|&g| g > 0.0));
}

#[test]
fn bake_of_a_missing_scene_names_it_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("x.exr");
    let out = vitreous(
        &["bake", "nowhere.toml", "-o", output.to_str().unwrap()],
        dir.path(),
    );
    assert_clean_failure(&out, &["nowhere.toml"]);
    assert!(!output.exists());
}

/// A drinking glass modelled as one sheet, as a first model often is: a cylinder wall and a
/// bottom disc of `segments` sides, open at the top and without thickness (glTF with an
/// external buffer `cup.bin`, flat normals).
fn write_single_sheet_cup(dir: &Path, segments: u16) {
    let (radius, height) = (0.04f32, 0.1f32);
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for ring in [0.0, height] {
        for k in 0..segments {
            let a = std::f32::consts::TAU * f32::from(k) / f32::from(segments);
            positions.push([radius * a.cos(), ring, -radius * a.sin()]);
        }
    }
    let mut indices: Vec<u16> = Vec::new();
    for k in 0..segments {
        let (bottom, next) = (1 + k, 1 + (k + 1) % segments);
        let (top, next_top) = (bottom + segments, next + segments);
        indices.extend([0, next, bottom]);
        indices.extend([bottom, next, next_top, bottom, next_top, top]);
    }
    let mut bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c: &f32| c.to_le_bytes())
        .collect();
    let index_offset = bytes.len();
    bytes.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("cup.bin"), &bytes).unwrap();
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"name":"Cup","mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":{},"uri":"cup.bin"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{index_offset}}},
                       {{"buffer":0,"byteOffset":{index_offset},"byteLength":{}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3",
                       "min":[-{radius},0,-{radius}],"max":[{radius},{height},{radius}]}},
                     {{"bufferView":1,"componentType":5123,"count":{},"type":"SCALAR"}}]}}"#,
        bytes.len(),
        bytes.len() - index_offset,
        positions.len(),
        indices.len()
    );
    std::fs::write(dir.join("cup.gltf"), gltf).unwrap();
}

#[test]
fn a_glass_modelled_as_one_sheet_is_refused_with_how_to_close_it() {
    let dir = tempfile::tempdir().unwrap();
    write_single_sheet_cup(dir.path(), 24);
    // glass-sphere-real.toml (two-surface refraction) with the cup in place of the ball.
    let config = workspace().join("config").display().to_string();
    let text = std::fs::read_to_string(scene("glass-sphere-real.toml"))
        .unwrap()
        .replace("\"../models/sphere.glb\"", "\"cup.gltf\"")
        .replace("\"../", &format!("\"{config}/"));
    assert!(text.contains("model = \"cup.gltf\"") && text.contains("two-surface"));
    let cup_scene = write(dir.path(), "cup.toml", &text);
    let out_dir = dir.path().join("out");
    let out = replay_into(&cup_scene, &out_dir, dir.path());
    let needles = [
        "cup.toml",
        "object.model",
        "cup.gltf",
        "closed solid",
        "24 edge(s)",
        "Solidify",
        "Merge by Distance",
    ];
    let message = assert_clean_failure(&out, &needles);
    assert!(
        !out_dir.exists(),
        "output written for a refused scene: {message}"
    );
    // The paper's refraction draws any triangles, but its caustics are light through the
    // volume: the bake refuses the sheet in the same words.
    let paper = write(
        dir.path(),
        "cup-paper.toml",
        &text.replace("refraction = \"two-surface\"", ""),
    );
    let bake = dir.path().join("cup.exr");
    let out = bake_into(&paper, &bake, dir.path());
    assert_clean_failure(
        &out,
        &needles
            .map(|n| n.replace("cup.toml", "cup-paper.toml"))
            .each_ref()
            .map(String::as_str),
    );
    assert!(!bake.exists());
}
