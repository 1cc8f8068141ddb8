//! `vitreous view` in a virtual X server (xvfb-run; `wayland.rs`: in a headless weston) on the
//! machine's Vulkan device (lavapipe in CI) with validation on: screenshots measured in the
//! glass's projected region and away from it, a scripted key press, scripted scene edits
//! (reload, and a broken edit kept out), and the window closed (`close.rs`); recorded and
//! played sessions are `recording.rs`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod close;
mod recording;
mod shots;
#[cfg(feature = "wayland")]
mod wayland;

use shots::{Shot, WINDOW, assert_glass_shown_alone, glass_discs, regions, root, scene};

/// `xvfb-run`, or None outside CI when it is missing (in CI, a missing one fails the test).
fn xvfb_run() -> Option<PathBuf> {
    shots::program(
        "xvfb-run",
        "tools/ensure-vulkan --window (Debian: xvfb, xauth)",
    )
}

/// Runs `vitreous view` in a virtual X server with validation on.
fn view(xvfb: &Path, scene: &Path, args: &[&str], cwd: &Path) -> Output {
    let size = format!("{}x{}", WINDOW.0, WINDOW.1);
    // Each run starts its search for a free display at its own number: runs started at once
    // by parallel tests would otherwise race for the same one.
    static RUNS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let first_display = 100 + 10 * RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = Command::new(xvfb)
        .args(["-a", "-n", &first_display.to_string()])
        .args(["-s", "-screen 0 640x480x24"])
        .arg(env!("CARGO_BIN_EXE_vitreous"))
        .arg("view")
        .arg(scene)
        .args(["--window", &size, "--validate", "--no-overlay"])
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("running xvfb-run");
    shots::succeeded(out)
}

#[test]
fn view_shows_the_glass_where_it_projects_and_black_elsewhere() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere.toml");
    let shot = dir.path().join("shot.png");
    view(
        &xvfb,
        &scene,
        &["--frames", "6", "--screenshot", shot.to_str().unwrap()],
        dir.path(),
    );
    assert_glass_shown_alone(&shot, &scene);
}

#[test]
fn a_scripted_key_changes_the_glass_and_nothing_else() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere.toml");
    let script = dir.path().join("o4.script");
    // Key 3: condition O4 (per-eye refraction to the background plane); Esc at frame 6
    // ends the session as --frames 6 does.
    std::fs::write(&script, "1 key 3\n6 key escape\n").unwrap();
    let (before, after) = (dir.path().join("none.png"), dir.path().join("o4.png"));
    let common = ["--effects", "none", "--screenshot"];
    let mut args = common.to_vec();
    args.extend([before.to_str().unwrap(), "--frames", "6"]);
    view(&xvfb, &scene, &args, dir.path());
    let out_dir = dir.path().join("out");
    let mut args = common.to_vec();
    args.extend([
        after.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
    ]);
    args.extend(["--frames", "100", "--out", out_dir.to_str().unwrap()]);
    let out = view(&xvfb, &scene, &args, dir.path());
    let s = summary(&out_dir);
    assert_eq!(s["frames"], 6, "Esc ended the session: {s:#}");
    assert_eq!(s["final_condition"], "disparity", "{s:#}");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("effects now disparity"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (a, b) = (Shot::read(&before), Shot::read(&after));
    let (inside, outside) = regions(&glass_discs(&scene));
    let diff = |&(x, y): &(u32, u32)| (a.luma(x, y) - b.luma(x, y)).abs();
    let inside_diff = inside.iter().map(diff).sum::<f32>() / inside.len() as f32;
    let changed_outside = outside.iter().filter(|p| diff(p) > 8.0).count();
    assert!(
        inside_diff > 3.0,
        "the glass changed by {inside_diff} on average"
    );
    assert!(
        (changed_outside as f32) < 0.005 * outside.len() as f32,
        "{changed_outside} of {} px changed away from the glass",
        outside.len()
    );
}

/// A copy of a shipped scene in `dir` with its asset paths made absolute, so edits of the copy
/// load the same assets.
fn scene_copy(name: &str, dir: &Path) -> (PathBuf, String) {
    let text = std::fs::read_to_string(scene(name)).unwrap();
    let config = root().join("config").canonicalize().unwrap();
    let text = text.replace("\"../", &format!("\"{}/", config.display()));
    let path = dir.join("scene.toml");
    std::fs::write(&path, &text).unwrap();
    (path, text)
}

#[test]
fn scripted_scene_edits_reload_and_a_broken_edit_keeps_the_last_good_scene() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (path, text) = scene_copy("glass-sphere.toml", dir.path());
    let moved = text.replace(
        "position_m = [0.0, -0.26, -1.5]",
        "position_m = [0.1, -0.26, -1.5]",
    );
    assert_ne!(moved, text, "the edit applies");
    std::fs::write(dir.path().join("moved.toml"), &moved).unwrap();
    // Line 3 of the broken file has no value.
    std::fs::write(
        dir.path().join("broken.toml"),
        "[object]\nior = 1.5\ndiameter_m =\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("edits.script"),
        "2 copy moved.toml scene.toml\n6 copy broken.toml scene.toml\n",
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let shot = dir.path().join("shot.png");
    view(
        &xvfb,
        &path,
        &[
            "--frames",
            "10",
            "--script",
            "edits.script",
            "--screenshot",
            shot.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ],
        dir.path(),
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["reloads"], 1, "{summary:#}");
    let errors = summary["reload_errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{summary:#}");
    let error = errors[0].as_str().unwrap();
    assert!(
        error.contains("scene.toml") && error.contains('3'),
        "{error}"
    );
    // The moved scene kept running: its glass is where the moved sphere projects.
    let moved_path = dir.path().join("moved.toml");
    let img = Shot::read(&shot);
    let (inside, _) = regions(&glass_discs(&moved_path));
    let mean = inside.iter().map(|&(x, y)| img.luma(x, y)).sum::<f32>() / inside.len() as f32;
    assert!(mean > 20.0, "the moved glass has mean luma {mean}");
}

pub(crate) fn summary(out_dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap()
}

/// Writes a script into `dir` that asks for a 400 x 300 window at frame 2, and returns the
/// arguments of a 24-frame session that runs it and leaves `shot.png` and `out/` in `dir`.
pub(crate) fn resize_session(dir: &Path) -> Vec<String> {
    std::fs::write(dir.join("resize.script"), "2 resize 400 300\n").unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    [
        "--frames",
        "24",
        "--script",
        "resize.script",
        "--screenshot",
    ]
    .map(String::from)
    .into_iter()
    .chain([path("shot.png"), "--out".into(), path("out")])
    .collect()
}

/// Checks what [`resize_session`]'s session left: a 400 x 300 window, a renderer made for
/// it, and the glass drawn in it.
pub(crate) fn assert_resized(dir: &Path) {
    let s = summary(&dir.join("out"));
    assert_eq!(s["window_px"], serde_json::json!([400, 300]), "{s:#}");
    assert!(s["renderers_made"].as_u64().unwrap() >= 2, "{s:#}");
    let img = Shot::read_sized(&dir.join("shot.png"), (400, 300));
    let lit = img.pixels.chunks(4).filter(|p| p[1] > 40).count();
    assert!(
        lit > 100,
        "the glass is drawn after the resize: {lit} px lit"
    );
}

#[test]
fn a_live_scene_computes_its_caustics_as_the_light_moves() {
    // moving-light.toml names no bake: its caustics are computed for each pose.
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = view(
        &xvfb,
        &scene("moving-light.toml"),
        &[
            "--frames",
            "8",
            "--effects",
            "c",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        dir.path(),
    );
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(
        log.contains("caustics computed on the GPU for each pose"),
        "{log}"
    );
    let s = summary(&out_dir);
    assert_eq!(s["frames"], 8, "{s:#}");
    assert_eq!(s["moved_frames"], 7, "the light moves every frame: {s:#}");
    assert_eq!(s["validation"]["errors"], 0, "{s:#}");
    assert_eq!(s["validation"]["warnings"], 0, "{s:#}");
}

#[test]
fn a_resized_window_gets_a_new_swapchain_and_renderer() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let args = resize_session(dir.path());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    view(&xvfb, &scene("glass-sphere.toml"), &args, dir.path());
    assert_resized(dir.path());
}

#[test]
fn the_wheel_moves_the_gaze_to_the_refracted_image_through_the_gaze_pipeline() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    // The cursor on the middle of the left eye's image, on the glass; the wheel at frame 4
    // moves the fixation point from the glass's surface to the background behind it. The
    // scene's filter (eq. 15's 20-sample mean) then decides the refracted image.
    std::fs::write(
        dir.path().join("gaze.script"),
        "0 move 0.25 0.5\n4 wheel 1\n",
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    view(
        &xvfb,
        &scene("visual-effects.toml"),
        &[
            "--frames",
            "40",
            "--effects",
            "O3",
            "--script",
            "gaze.script",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        dir.path(),
    );
    let s = summary(&out_dir);
    let seen: Vec<&str> = s["gaze_images"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|v| v.as_str())
        .filter(|v| *v != "unknown")
        .collect();
    assert_eq!(seen, ["surface", "refracted"], "{s:#}");
}

#[test]
fn the_preview_of_a_dimmer_scene_shows_the_glass_darker_than_the_world_behind_it() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let shot_of = |name: &str| {
        let shot = dir.path().join(format!("{name}.png"));
        view(
            &xvfb,
            &scene(name),
            &[
                "--frames",
                "6",
                "--effects",
                "none",
                "--preview",
                "--screenshot",
                shot.to_str().unwrap(),
            ],
            dir.path(),
        );
        Shot::read(&shot)
    };
    let (dimmer, additive) = (
        shot_of("glass-sphere-ml2.toml"),
        shot_of("glass-sphere-real.toml"),
    );
    let (inside, outside) = regions(&glass_discs(&scene("glass-sphere-ml2.toml")));
    let mean = |img: &Shot, px: &[(u32, u32)]| {
        px.iter().map(|&(x, y)| img.luma(x, y)).sum::<f32>() / px.len() as f32
    };
    // An additive display shows at least the world behind the glass; the dimmer takes the
    // world away where the glass is darker than it.
    let (d, a) = (mean(&dimmer, &inside), mean(&additive, &inside));
    assert!(
        d < a - 5.0,
        "the glass at luma {d} with the dimmer, {a} without"
    );
    // Away from the glass (the window's top rows: the wall), the world is the same.
    let top: Vec<(u32, u32)> = outside.into_iter().filter(|&(_, y)| y < 40).collect();
    let (d, a) = (mean(&dimmer, &top), mean(&additive, &top));
    assert!(
        (d - a).abs() < 1.0,
        "the wall at luma {d} with the dimmer, {a} without"
    );
}

#[test]
fn key_x_shows_the_preview_with_the_display_misregistered() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere-ml2.toml");
    // Key X twice: the display 0.25 degrees right of the world.
    let script = dir.path().join("x.script");
    std::fs::write(&script, "1 key x\n2 key x\n6 key escape\n").unwrap();
    let (before, after) = (
        dir.path().join("registered.png"),
        dir.path().join("shifted.png"),
    );
    let common = ["--effects", "none", "--preview", "--screenshot"];
    let mut args = common.to_vec();
    args.extend([before.to_str().unwrap(), "--frames", "6"]);
    view(&xvfb, &scene, &args, dir.path());
    let mut args = common.to_vec();
    args.extend([
        after.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
    ]);
    args.extend(["--frames", "100"]);
    let out = view(&xvfb, &scene, &args, dir.path());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("0.25 degrees right of the world"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (a, b) = (Shot::read(&before), Shot::read(&after));
    let (inside, outside) = regions(&glass_discs(&scene));
    let diff = |&(x, y): &(u32, u32)| (a.luma(x, y) - b.luma(x, y)).abs();
    let inside_diff = inside.iter().map(diff).sum::<f32>() / inside.len() as f32;
    assert!(inside_diff > 2.0, "the glass changed by {inside_diff}");
    // Far from the glass (the wall's top rows) the display draws nothing: the same world.
    let top: Vec<(u32, u32)> = outside.into_iter().filter(|&(_, y)| y < 40).collect();
    let top_diff = top.iter().map(diff).sum::<f32>() / top.len() as f32;
    assert!(top_diff < 0.5, "the wall changed by {top_diff}");
}
