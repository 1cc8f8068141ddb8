//! `vitreous trace import --from tobii-g3 | neon` on the synthetic recordings in
//! trace/tests/data: the trace written and read back, and clean failures on broken recordings.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use vitreous_trace::read_trace;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../trace/tests/data")
        .join(name)
}

fn import(from: &str, recording: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(["trace", "import", "--from", from])
        .arg(recording)
        .arg("-o")
        .arg(out)
        .env("RUST_LOG", "warn")
        .output()
        .expect("the vitreous binary runs")
}

/// Asserts a failed run with a one-paragraph message holding every needle; returns it.
fn assert_failure(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).trim().to_owned();
    assert!(!out.status.success(), "expected failure: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert!(
        !stderr.contains("\n\n"),
        "more than one paragraph: {stderr}"
    );
    for needle in needles {
        assert!(stderr.contains(needle), "'{needle}' missing from: {stderr}");
    }
    stderr
}

fn assert_success(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn import_tobii_g3_folder_and_gaze_file_write_the_same_trace() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.trace"), dir.path().join("b.trace"));
    let report = assert_success(&import("tobii-g3", &data("tobii_g3"), &a));
    for needle in [
        "Tobii Pro Glasses 3",
        "200 samples",
        "gyroscope",
        "approximated:",
    ] {
        assert!(report.contains(needle), "{needle}: {report}");
    }
    assert_success(&import("tobii-g3", &data("tobii_g3/gazedata.gz"), &b));
    let text = std::fs::read_to_string(&a).unwrap();
    assert!(text.starts_with("# vitreous-trace v1.1\n"), "{text}");
    assert_eq!(text, std::fs::read_to_string(&b).unwrap());
    let samples = read_trace(&a).unwrap();
    assert_eq!(samples.len(), 200);
    // Pupils carried into the v1.1 columns; both eyes valid where the recording has them.
    assert_eq!(
        samples[0].gaze.pupil_diameter_m,
        [Some(0.0039), Some(0.0041)]
    );
    assert!(samples[0].gaze.left.valid && samples[0].gaze.right.valid);
    assert!(samples[0].gaze.fixation.is_some());
}

#[test]
fn import_tobii_g3_of_a_broken_recording_fails_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec");
    std::fs::create_dir(&rec).unwrap();
    let target = dir.path().join("t.trace");
    // A gzip stream cut short.
    let gz = std::fs::read(data("tobii_g3/gazedata.gz")).unwrap();
    std::fs::write(rec.join("gazedata.gz"), &gz[..gz.len() - 40]).unwrap();
    let out = import("tobii-g3", &rec, &target);
    assert_failure(&out, &["gazedata.gz", "reading line", "cut short"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!target.exists());
    // A malformed JSON line, named by file and line.
    std::fs::write(
        rec.join("gazedata.gz"),
        "{\"type\":\"gaze\",\"timestamp\":0,\"data\":{}}\n{\"type\":\"gaze\",\n",
    )
    .unwrap();
    let out = import("tobii-g3", &rec, &target);
    assert_failure(&out, &["gazedata.gz:2: malformed JSON line"]);
    assert!(!target.exists());
    // No gaze data at all.
    std::fs::remove_file(rec.join("gazedata.gz")).unwrap();
    let out = import("tobii-g3", &rec, &target);
    assert_failure(&out, &["gazedata.gz: not found"]);
    assert!(!target.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn import_does_not_replace_a_file_of_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec");
    std::fs::create_dir(&rec).unwrap();
    for f in ["gazedata.gz", "imudata.gz"] {
        std::fs::copy(data("tobii_g3").join(f), rec.join(f)).unwrap();
    }
    let before = std::fs::read(rec.join("imudata.gz")).unwrap();
    let out = import(
        "tobii-g3",
        &rec.join("gazedata.gz"),
        &rec.join("imudata.gz"),
    );
    assert_failure(&out, &["-o", "is the input file"]);
    assert_eq!(std::fs::read(rec.join("imudata.gz")).unwrap(), before);
}

#[test]
fn import_neon_folder_writes_a_trace_and_names_broken_files() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("n.trace");
    let report = assert_success(&import("neon", &data("neon"), &target));
    for needle in [
        "Pupil Labs Neon",
        "200 samples",
        "21 inside marked blinks",
        "not measured",
    ] {
        assert!(report.contains(needle), "{needle}: {report}");
    }
    assert_eq!(read_trace(&target).unwrap().len(), 200);
    // A .time file that does not pair with its .raw file.
    let rec = dir.path().join("rec");
    std::fs::create_dir(&rec).unwrap();
    for entry in std::fs::read_dir(data("neon")).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, rec.join(path.file_name().unwrap())).unwrap();
    }
    let time = std::fs::read(rec.join("gaze ps1.time")).unwrap();
    std::fs::write(rec.join("gaze ps1.time"), &time[..time.len() - 16]).unwrap();
    let broken = dir.path().join("broken.trace");
    let out = import("neon", &rec, &broken);
    assert_failure(
        &out,
        &["gaze ps1.raw: 200 records", "gaze ps1.time has 198"],
    );
    assert!(!broken.exists());
}
