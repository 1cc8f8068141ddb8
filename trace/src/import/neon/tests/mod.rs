//! Imports of synthetic Neon recordings written from known geometry, of the committed
//! fixtures in trace/tests/data/neon and trace/tests/data/neon-eye-state, and of malformed
//! folders.

use std::path::{Path, PathBuf};

use glam::{DVec3, Quat, Vec3};
use proptest::prelude::*;

use super::kappa::Eye;
use super::*;

/// A wide-angle scene camera of the kind Neon has.
const CAMERA: SceneCamera = SceneCamera {
    fx: 892.5,
    fy: 891.7,
    cx: 812.3,
    cy: 597.6,
    distortion: [-0.05, 0.02, 4e-4, -3e-4, 0.0, 0.1, 0.01, 0.0],
};

/// Eyeball centres, scene camera frame (mm; +x right, +y down, +z forward).
const LEFT_EYE: [f32; 3] = [-31.5, 14.0, -22.0];
const RIGHT_EYE: [f32; 3] = [32.0, 13.5, -21.0];

const GAZE_DTYPE: &str = "[\n(\"x\", \"float32\"),\n(\"y\", \"float32\"),\n]\n";
const EYE_STATE_DTYPE: &str = "[\n(\"pupil_diameter_left_mm\",  \"float32\"),\n(\"eyeball_center_left_x\",   \"float32\"),\n(\"eyeball_center_left_y\",   \"float32\"),\n(\"eyeball_center_left_z\",   \"float32\"),\n(\"optical_axis_left_x\",     \"float32\"),\n(\"optical_axis_left_y\",     \"float32\"),\n(\"optical_axis_left_z\",     \"float32\"),\n(\"pupil_diameter_right_mm\", \"float32\"),\n(\"eyeball_center_right_x\",  \"float32\"),\n(\"eyeball_center_right_y\",  \"float32\"),\n(\"eyeball_center_right_z\",  \"float32\"),\n(\"optical_axis_right_x\",    \"float32\"),\n(\"optical_axis_right_y\",    \"float32\"),\n(\"optical_axis_right_z\",    \"float32\"),\n(\"eyelid_angle_top_left\",    \"float32\"),\n(\"eyelid_angle_bottom_left\", \"float32\"),\n(\"eyelid_aperture_left_mm\",  \"float32\"),\n(\"eyelid_angle_top_right\",   \"float32\"),\n(\"eyelid_angle_bottom_right\",\"float32\"),\n(\"eyelid_aperture_right_mm\", \"float32\"),\n]\n";
const BLINKS_DTYPE: &str = "[\n(\"event_type\",         \"int32\"),\n(\"start_timestamp_ns\", \"int64\"),\n(\"end_timestamp_ns\",   \"int64\"),\n]\n";
const IMU_DTYPE: &str = "[\n(\"timestamp_ns\", \"int64\"),\n(\"gyro_x\", \"float32\"),\n(\"gyro_y\", \"float32\"),\n(\"gyro_z\", \"float32\"),\n(\"accel_x\", \"float32\"),\n(\"accel_y\", \"float32\"), \n(\"accel_z\", \"float32\"), \n(\"quaternion_w\", \"float32\"),\n(\"quaternion_x\", \"float32\"), \n(\"quaternion_y\", \"float32\"), \n(\"quaternion_z\", \"float32\"), \n]\n";

/// The recording's start, Unix nanoseconds.
const START_NS: u64 = 1_733_000_000_000_000_000;

fn f32s(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Writes stream `base` part `part`: records (already packed) and times.
fn write_part(dir: &Path, base: &str, part: u32, records: &[Vec<u8>], times: &[u64]) {
    let raw: Vec<u8> = records.concat();
    let time: Vec<u8> = times.iter().flat_map(|t| t.to_le_bytes()).collect();
    std::fs::write(dir.join(format!("{base} ps{part}.raw")), raw).unwrap();
    std::fs::write(dir.join(format!("{base} ps{part}.time")), time).unwrap();
}

fn calibration_bin(camera: &SceneCamera) -> Vec<u8> {
    let mut bytes = vec![1u8, b'0', b'0', b'0', b'1', b'2', b'3'];
    let k = [
        camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0,
    ];
    for v in k.iter().chain(&camera.distortion) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    // The two eye cameras' calibrations and the checksum, not read.
    bytes.resize(803, 0);
    bytes
}

/// Where the wearer looks at time `t_s` (scene camera frame, mm): 0.5 m ahead and a little
/// right, moving to 1.5 m up and left after 0.5 s.
fn target(t_s: f64) -> DVec3 {
    if t_s < 0.5 {
        DVec3::new(80.0, 40.0, 500.0)
    } else {
        DVec3::new(-300.0, -200.0, 1500.0)
    }
}

/// Writes a 1 s recording: gaze at 200 Hz, eye state at 200 Hz (2.5 ms later), a blink from
/// 0.30 to 0.40 s, the IMU at 110 Hz turning left about the vertical at 30 deg/s from level
/// and facing north, and the files Neon writes beside them.
fn write_recording(dir: &Path) {
    let times: Vec<u64> = (0..200).map(|i| START_NS + i * 5_000_000).collect();
    let gaze: Vec<Vec<u8>> = times
        .iter()
        .map(|&t| {
            let t_s = (t - START_NS) as f64 * 1e-9;
            let [u, v] = CAMERA.project(target(t_s).normalize()).unwrap();
            f32s(&[u as f32, v as f32])
        })
        .collect();
    write_part(dir, "gaze", 1, &gaze, &times);
    std::fs::write(dir.join("gaze.dtype"), GAZE_DTYPE).unwrap();
    let eye_times: Vec<u64> = times.iter().map(|t| t + 2_500_000).collect();
    let eye: Vec<Vec<u8>> = eye_times
        .iter()
        .map(|_| {
            let [lx, ly, lz] = LEFT_EYE;
            let [rx, ry, rz] = RIGHT_EYE;
            // The optical axes are deliberately wrong (5 degrees out): the import must not
            // use them.
            f32s(&[
                3.9, lx, ly, lz, 0.087, 0.0, 0.996, 4.2, rx, ry, rz, -0.087, 0.0, 0.996, 0.1, 0.2,
                9.0, 0.1, 0.2, 9.5,
            ])
        })
        .collect();
    write_part(dir, "eye_state", 1, &eye, &eye_times);
    std::fs::write(dir.join("eye_state.dtype"), EYE_STATE_DTYPE).unwrap();
    let blink = [
        1i32.to_le_bytes().to_vec(),
        (START_NS as i64 + 300_000_000).to_le_bytes().to_vec(),
        (START_NS as i64 + 400_000_000).to_le_bytes().to_vec(),
    ]
    .concat();
    write_part(dir, "blinks", 1, &[blink], &[START_NS + 300_000_000]);
    std::fs::write(dir.join("blinks.dtype"), BLINKS_DTYPE).unwrap();
    let imu_times: Vec<u64> = (0..111).map(|i| START_NS + i * 9_090_909).collect();
    let imu: Vec<Vec<u8>> = imu_times
        .iter()
        .map(|&t| {
            let t_s = (t - START_NS) as f32 * 1e-9;
            let q = Quat::from_rotation_z((30.0 * t_s).to_radians());
            let mut r = (t as i64).to_le_bytes().to_vec();
            r.extend(f32s(&[0.0, 0.0, 30.0, 0.0, 0.0, 9.81, q.w, q.x, q.y, q.z]));
            r
        })
        .collect();
    write_part(dir, "imu", 1, &imu, &imu_times);
    std::fs::write(dir.join("imu.dtype"), IMU_DTYPE).unwrap();
    std::fs::write(dir.join("calibration.bin"), calibration_bin(&CAMERA)).unwrap();
    std::fs::write(
        dir.join("info.json"),
        format!(
            "{{\"start_time\": {START_NS}, \"duration\": 1000000000, \"gaze_frequency\": 200, \
             \"data_format_version\": \"2.3\", \"wearer_ied\": 63.5}}\n"
        ),
    )
    .unwrap();
}

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/neon")
}

/// Rewrites the committed fixture from [`write_recording`]:
/// `cargo test -p vitreous-trace --lib write_neon_fixture -- --ignored`.
#[test]
#[ignore = "rewrites trace/tests/data/neon"]
fn write_neon_fixture() {
    std::fs::create_dir_all(data_dir()).unwrap();
    write_recording(&data_dir());
}

fn openxr(v: DVec3) -> Vec3 {
    neon_to_openxr(v.as_vec3())
}

#[test]
fn committed_fixture_gives_the_geometry_it_was_made_from() {
    let (samples, report) = import_neon(data_dir()).unwrap();
    eprintln!("{report}");
    assert_eq!((report.records, report.samples), (200, 200));
    // 0.30 to 0.40 s inclusive at 5 ms: 21 samples in the blink, no valid eye.
    assert_eq!(
        (
            report.blink_samples,
            report.lost_samples,
            report.one_eye_samples
        ),
        (21, 21, 0)
    );
    assert_eq!(report.head, HeadSource::ImuOrientation { records: 111 });
    let ipd = report.median_ipd_mm.unwrap();
    assert!((ipd - 63.5).abs() < 0.1, "{ipd}");
    assert_eq!(samples[199].time_ns, 995_000_000);
    // The head frame's origin is the middle of the eyeball centres.
    let left = openxr(DVec3::from_array(LEFT_EYE.map(f64::from))) / 1000.0;
    let right = openxr(DVec3::from_array(RIGHT_EYE.map(f64::from))) / 1000.0;
    let centre = (left + right) / 2.0;
    let origin = report.head_origin_m.unwrap();
    assert!(origin.abs_diff_eq(centre, 1e-7), "{origin}");
    assert!(left.x < 0.0 && left.y < 0.0 && left.z > 0.0);
    for (i, s) in samples.iter().enumerate() {
        let t_s = i as f64 * 0.005;
        let blink = (0.3..=0.4).contains(&t_s);
        assert_eq!(s.gaze.left.valid, !blink, "{i}");
        if blink {
            assert_eq!(s.gaze.pupil_diameter_m, [None, None]);
            assert_eq!(s.gaze.combined, Some(GazeRay::INVALID));
            continue;
        }
        // The visual gaze direction, to a hundredth of a degree.
        let expected = openxr(target(t_s).normalize());
        let combined = s.gaze.combined.unwrap();
        assert!(combined.direction.angle_between(expected) < 2e-4, "{i}");
        assert!(
            combined.origin.abs_diff_eq(-centre, 1e-7),
            "from the scene camera"
        );
        // Eye rays from the eyeball centres, parallel to the visual gaze: depth is not
        // measured.
        assert!(s.gaze.left.origin.abs_diff_eq(left - centre, 1e-7));
        assert!(s.gaze.right.origin.abs_diff_eq(right - centre, 1e-7));
        assert_eq!(s.gaze.left.direction, combined.direction);
        assert_eq!(s.gaze.right.direction, combined.direction);
        let [l, r] = s.gaze.pupil_diameter_m.map(Option::unwrap);
        assert!(
            (l - 0.0039).abs() < 1e-9 && (r - 0.0042).abs() < 1e-9,
            "{l} {r}"
        );
        assert_eq!(s.gaze.fixation, None);
    }
    // The scene camera looks 12 degrees below the IMU's horizontal; the head turns left at
    // 30 deg/s and starts facing -z.
    let pitch = Quat::from_rotation_x(-12f32.to_radians());
    let f0 = samples[0].head.transform_vector(Vec3::NEG_Z);
    assert!(f0.abs_diff_eq(pitch * Vec3::NEG_Z, 1e-5), "{f0}");
    let f = samples[199].head.transform_vector(Vec3::NEG_Z);
    let expected = Quat::from_rotation_y(29.85f32.to_radians()) * pitch * Vec3::NEG_Z;
    assert!(f.abs_diff_eq(expected, 1e-3), "{f} vs {expected}");
}

#[test]
fn parts_concatenate_and_missing_optional_streams_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    write_recording(dir.path());
    let (whole, _) = import_neon(dir.path()).unwrap();
    // Split the gaze stream into two parts.
    let raw = std::fs::read(dir.path().join("gaze ps1.raw")).unwrap();
    let time = std::fs::read(dir.path().join("gaze ps1.time")).unwrap();
    std::fs::write(dir.path().join("gaze ps1.raw"), &raw[..80 * 8]).unwrap();
    std::fs::write(dir.path().join("gaze ps1.time"), &time[..80 * 8]).unwrap();
    std::fs::write(dir.path().join("gaze ps2.raw"), &raw[80 * 8..]).unwrap();
    std::fs::write(dir.path().join("gaze ps2.time"), &time[80 * 8..]).unwrap();
    let (split, _) = import_neon(dir.path()).unwrap();
    assert_eq!(split, whole);
    // Without IMU, blinks, dtype files and calibration the import still runs, and says what
    // it assumed.
    for f in [
        "imu ps1.raw",
        "blinks ps1.raw",
        "gaze.dtype",
        "calibration.bin",
    ] {
        std::fs::remove_file(dir.path().join(f)).unwrap();
    }
    let (s, report) = import_neon(dir.path()).unwrap();
    assert!(s.iter().all(|s| s.head == Pose::IDENTITY));
    assert_eq!(report.blink_samples, 0);
    let text = report.to_string();
    for needle in ["no IMU stream", "no calibration.bin", "not measured"] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
}

#[test]
fn malformed_recordings_name_the_file() {
    type Break = fn(&Path);
    let cases: [(Break, &str); 9] = [
        (
            |d| {
                let raw = std::fs::read(d.join("gaze ps1.raw")).unwrap();
                std::fs::write(d.join("gaze ps1.raw"), &raw[..raw.len() - 3]).unwrap();
            },
            "gaze ps1.raw: 1597 bytes is not a whole number of 8-byte records",
        ),
        (
            |d| {
                let t = std::fs::read(d.join("eye_state ps1.time")).unwrap();
                std::fs::write(d.join("eye_state ps1.time"), &t[..t.len() - 8]).unwrap();
            },
            "eye_state ps1.raw: 200 records, but",
        ),
        (
            |d| {
                std::fs::write(
                    d.join("gaze.dtype"),
                    "[(\"x\", \"float64\"), (\"y\", \"float64\")]",
                )
                .unwrap()
            },
            "gaze.dtype: field `x` is float64, expected float32",
        ),
        (
            |d| std::fs::write(d.join("eye_state.dtype"), "[(\"pupil\", \"float32\")]").unwrap(),
            "eye_state.dtype: no field `eyeball_center_left_x`",
        ),
        (
            |d| std::fs::write(d.join("imu.dtype"), "{'x': 1}").unwrap(),
            "imu.dtype: unexpected `{`",
        ),
        (
            |d| std::fs::remove_file(d.join("gaze ps1.time")).unwrap(),
            "gaze ps1.time: not found",
        ),
        (
            |d| std::fs::remove_file(d.join("eye_state ps1.raw")).unwrap(),
            "eye_state ps1.raw: not found",
        ),
        (
            |d| std::fs::write(d.join("info.json"), "{\n\"start_time\": 12,\n").unwrap(),
            "info.json:3: malformed JSON",
        ),
        (
            |d| std::fs::write(d.join("calibration.bin"), [0u8; 20]).unwrap(),
            "calibration.bin: 20 bytes",
        ),
    ];
    for (spoil, needle) in cases {
        let dir = tempfile::tempdir().unwrap();
        write_recording(dir.path());
        spoil(dir.path());
        let e = import_neon(dir.path()).unwrap_err().to_string();
        assert!(e.contains(needle), "{needle} not in: {e}");
    }
    let e = import_neon("/nonexistent/neon").unwrap_err().to_string();
    assert!(
        e.starts_with("/nonexistent/neon: not found; a Neon native recording is a folder"),
        "{e}"
    );
    // An empty gaze stream has nothing to import.
    let dir = tempfile::tempdir().unwrap();
    write_recording(dir.path());
    write_part(dir.path(), "gaze", 1, &[], &[]);
    let e = import_neon(dir.path()).unwrap_err().to_string();
    assert!(e.contains("gaze ps1.raw: no gaze records"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn imports_round_trip_through_the_trace_format(
        raw in proptest::collection::vec(
            (1u64..20_000_000, -100.0f32..1700.0, -100.0f32..1300.0, 0.5f32..11.0, any::<bool>()),
            1..30,
        ),
    ) {
        let dir = tempfile::tempdir().unwrap();
        write_recording(dir.path());
        let mut t = START_NS;
        let (mut gaze, mut times, mut eyes) = (Vec::new(), Vec::new(), Vec::new());
        for &(dt, u, v, pupil, nan) in &raw {
            t += dt;
            times.push(t);
            gaze.push(f32s(&[if nan { f32::NAN } else { u }, v]));
            let mut e = f32s(&[pupil, -30.0, 10.0, -20.0, 0.0, 0.0, 1.0, pupil, 30.0, 10.0, -20.0]);
            e.extend(f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
            eyes.push(e);
        }
        write_part(dir.path(), "gaze", 1, &gaze, &times);
        write_part(dir.path(), "eye_state", 1, &eyes, &times);
        let (samples, report) = import_neon(dir.path()).unwrap();
        prop_assert_eq!(samples.len(), raw.len());
        prop_assert_eq!(report.records, raw.len());
        prop_assert_eq!(crate::import::written_and_read(&samples), samples);
    }
}

mod eye_state;
