//! `vitreous view --record` and `--play`: a recorded session replays and its preview shows the
//! world, a played trace pauses and steps and the recording shows it, and scripted scene edits
//! are recorded so the replay ends where the session did.

use std::process::Command;

use super::shots::{Shot, scene};
use super::{summary, view, xvfb_run};

#[test]
fn a_recorded_session_replays_and_the_preview_shows_the_world() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("visual-effects.toml");
    let (shot, trace) = (
        dir.path().join("shot.png"),
        dir.path().join("session.trace"),
    );
    view(
        &xvfb,
        &scene,
        &[
            "--frames",
            "8",
            "--effects",
            "O5",
            "--preview",
            "--screenshot",
            shot.to_str().unwrap(),
            "--record",
            trace.to_str().unwrap(),
        ],
        dir.path(),
    );
    // The preview adds the real world's photos: bright everywhere, not black around the glass.
    let img = Shot::read(&shot);
    let dark = img
        .pixels
        .chunks(4)
        .filter(|p| p[0].max(p[1]).max(p[2]) < 10)
        .count();
    assert!(
        dark * 100 < img.pixels.len() / 4,
        "{dark} px black in the preview"
    );
    let samples = vitreous_trace::format::read_trace(&trace).expect("the recording is a trace");
    assert_eq!(samples.len(), 8);
    let out = Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .arg("replay")
        .arg(&scene)
        .args([
            "--trace",
            trace.to_str().unwrap(),
            "--at-samples",
            "--size",
            "64x48",
        ])
        .args([
            "--effects",
            "O5",
            "--save-every",
            "0",
            "--quiet",
            "--validate",
        ])
        .arg("--out")
        .arg(dir.path().join("replay"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = summary(&dir.path().join("replay"));
    assert_eq!(s["frames"], 8, "one frame per recorded sample: {s:#}");
}

#[test]
fn a_played_trace_pauses_and_steps_and_the_recording_shows_it() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere.toml");
    let trace = dir.path().join("synth.trace");
    let synth = Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(["trace", "synth", "--scene"])
        .arg(&scene)
        .arg("-o")
        .arg(&trace)
        .output()
        .unwrap();
    assert!(
        synth.status.success(),
        "{}",
        String::from_utf8_lossy(&synth.stderr)
    );
    // K pauses before frame 2 is drawn, L steps 1/60 s before frame 5.
    std::fs::write(dir.path().join("keys.script"), "2 key k\n5 key l\n").unwrap();
    let recorded = dir.path().join("rec.trace");
    view(
        &xvfb,
        &scene,
        &[
            "--frames",
            "8",
            "--trace",
            trace.to_str().unwrap(),
            "--script",
            "keys.script",
            "--record",
            recorded.to_str().unwrap(),
        ],
        dir.path(),
    );
    let samples = vitreous_trace::format::read_trace(&recorded).unwrap();
    // Frames 0 and 1 play, 2-4 stand still (not recorded again), 5 is one step on, 6-7 stand.
    let times: Vec<i64> = samples.iter().map(|s| s.time_ns).collect();
    assert_eq!(times.len(), 3, "{times:?}");
    assert_eq!(times[2] - times[1], 1_000_000_000 / 60, "{times:?}");
    let played = vitreous_trace::format::read_trace(&trace).unwrap();
    assert_eq!(
        samples[0].head, played[0].head,
        "the trace's first head pose"
    );
}

#[test]
fn scripted_scene_edits_are_recorded_and_the_replay_ends_where_the_session_did() {
    let Some(xvfb) = xvfb_run() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere.toml");
    let script = dir.path().join("edits.script");
    // The object 1 cm right, 1 mm away (Shift) and turned 1 degree (Shift); the light 1 cm
    // up; the world 1 cm left; then the object placed where the gaze (the cursor, low in the
    // left eye) meets the floor.
    std::fs::write(
        &script,
        "1 key right\n2 down shift\n2 key up\n2 key t\n2 up shift\n3 key b\n3 key pageup\n\
         4 key b\n4 key left\n5 move 0.25 0.95\n6 key m\n9 key escape\n",
    )
    .unwrap();
    let (trace, out_dir) = (dir.path().join("edits.trace"), dir.path().join("view"));
    let out = view(
        &xvfb,
        &scene,
        &[
            "--effects",
            "c",
            "--frames",
            "100",
            "--script",
            script.to_str().unwrap(),
            "--record",
            trace.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ],
        dir.path(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    let s = summary(&out_dir);
    assert_eq!(s["scene_edits"], 6, "{s:#}\n{stderr}");
    assert!(
        stderr.contains("move the object +10.0 mm along x: object at"),
        "{stderr}"
    );
    assert_eq!(
        stderr.matches("caustics are off").count(),
        1,
        "the stale bake is reported once: {stderr}"
    );
    let (samples, edits) =
        vitreous_trace::format::read_trace_with_edits(&trace).expect("the recording reads");
    let actions: Vec<&str> = edits.iter().map(|e| e.action.as_str()).collect();
    assert_eq!(
        actions,
        [
            "object+10mmx",
            "object-1mmz",
            "turn+1",
            "light+10mmy",
            "register-10mmx",
            "place"
        ]
    );
    assert_eq!(samples.len(), 9);
    assert!((edits[4].world_offset_m.x + 0.01).abs() < 1e-6);

    let replay_dir = dir.path().join("replay");
    let out = Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(["--log", "info", "replay"])
        .arg(&scene)
        .args(["--trace", trace.to_str().unwrap(), "--at-samples"])
        .args(["--size", "64x48", "--effects", "c", "--save-every", "0"])
        .args(["--quiet", "--validate", "--out"])
        .arg(&replay_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = summary(&replay_dir);
    assert_eq!(r["scene_edits"], 6, "{r:#}");
    assert_eq!(r["final_placement"], s["final_placement"], "{r:#}\n{s:#}");
    assert_eq!(r["moved_frames"], s["moved_frames"], "{r:#}\n{s:#}");
    // The recording played in the window: once its clock reaches the end (it holds there),
    // the scene is where the session left it. The clock follows the window's frames (at most
    // 0.1 s a frame), so a recording made on a loaded machine can outlast a few frames of
    // playback: Shift+L seeks forward 1 s, eight times, past its end.
    let seek = dir.path().join("seek.script");
    let mut seek_steps = String::from("2 down shift\n");
    for _ in 0..8 {
        seek_steps.push_str("2 key l\n");
    }
    seek_steps.push_str("2 up shift\n");
    std::fs::write(&seek, seek_steps).unwrap();
    let played_dir = dir.path().join("played");
    view(
        &xvfb,
        &scene,
        &[
            "--effects",
            "c",
            "--frames",
            "12",
            "--trace",
            trace.to_str().unwrap(),
            "--script",
            seek.to_str().unwrap(),
            "--out",
            played_dir.to_str().unwrap(),
        ],
        dir.path(),
    );
    let p = summary(&played_dir);
    assert_eq!(p["final_placement"], s["final_placement"], "{p:#}\n{s:#}");
    let placed = &s["final_placement"]["object_position_m"];
    let rest = vitreous_scene::load_scene(&scene).unwrap().object.center_m;
    assert!(
        (placed[2].as_f64().unwrap() - f64::from(rest.z)).abs() > 0.01,
        "placing moved the object: {placed} from {rest}"
    );
}
