//! A replay ended early leaves a folder that says so: SIGTERM finishes the frame in flight and
//! writes a summary marked `interrupted`; kill -9 leaves the `running` summary written before
//! the first frame; an earlier run's summary and frames never survive into a new run.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A long replay (the synthetic trace at 1000 Hz: 12,001 small frames, each saved).
fn start_long_replay(out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(["replay", "config/scenes/glass-sphere.toml", "--out"])
        .arg(out)
        .args([
            "--size",
            "64x48",
            "--rate",
            "1000",
            "--save-every",
            "1",
            "--quiet",
        ])
        .current_dir(workspace())
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the vitreous binary runs")
}

/// Waits until the replay has saved frame 2 (so it is past set-up and inside the loop).
fn wait_for_frames(child: &mut Child, out: &Path) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !out.join("frames/000002-left.png").exists() {
        if let Ok(Some(status)) = child.try_wait() {
            panic!("replay ended before saving frames: {status}");
        }
        assert!(
            Instant::now() < deadline,
            "no frames saved within 2 minutes"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([format!("-{name}"), child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is complete JSON")
}

/// A folder as an earlier, successful run left it.
fn earlier_run(out: &Path) {
    std::fs::create_dir_all(out.join("frames")).unwrap();
    std::fs::write(
        out.join("summary.json"),
        r#"{"status": "complete", "complete": true, "frames": 9999}"#,
    )
    .unwrap();
    std::fs::write(out.join("frames/009999-left.png"), b"old").unwrap();
    std::fs::write(out.join("frames/notes.txt"), b"mine").unwrap();
}

#[test]
fn sigterm_finishes_the_frame_and_marks_the_summary_interrupted() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    earlier_run(&out);
    let mut child = start_long_replay(&out);
    wait_for_frames(&mut child, &out);
    signal(&child, "TERM");
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success(),
        "an interrupted replay must not exit 0"
    );
    assert!(stderr.contains("interrupted after"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    let s = summary(&out);
    assert_eq!(s["status"], "interrupted");
    assert_eq!(s["complete"], false);
    let frames = s["frames"].as_u64().unwrap();
    assert!((3..12_001).contains(&frames), "{frames} frames");
    // Every frame the summary counts was saved, and nothing of the earlier run is left.
    let saved = s["saved"].as_array().unwrap();
    assert!(saved.len() as u64 >= frames * 2, "{} files", saved.len());
    for name in saved {
        assert!(out.join(name.as_str().unwrap()).exists(), "{name} missing");
    }
    assert!(!out.join("frames/009999-left.png").exists());
    assert!(
        out.join("frames/notes.txt").exists(),
        "a file of the user's was removed"
    );
    let partial = std::fs::read_dir(out.join("frames"))
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
        .count();
    assert_eq!(partial, 0, "temporary files left behind");
}

#[test]
fn kill_9_leaves_a_summary_that_says_the_run_is_incomplete() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    earlier_run(&out);
    let mut child = start_long_replay(&out);
    wait_for_frames(&mut child, &out);
    signal(&child, "KILL");
    let _ = child.wait();
    let s = summary(&out);
    assert_eq!(s["status"], "running");
    assert_eq!(s["complete"], false);
    assert!(s["scene"].as_str().unwrap().contains("glass-sphere"));
    assert!(!out.join("frames/009999-left.png").exists());
}
