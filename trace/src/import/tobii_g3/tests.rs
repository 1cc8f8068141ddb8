//! Imports of synthetic Tobii Pro Glasses 3 recordings made from known geometry, of the
//! committed fixture in trace/tests/data/tobii_g3, and of malformed files.

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::Compression;
use flate2::write::GzEncoder;
use glam::DVec3;
use proptest::prelude::*;
use serde_json::{Value, json};

use super::*;
use crate::crossing::{RayCrossing, closest_approach};

/// Eye centres in Tobii's frame (mm): the left eye is at +x.
const LEFT_EYE: [f64; 3] = [31.0, -9.0, -28.0];
const RIGHT_EYE: [f64; 3] = [-32.0, -8.0, -27.0];

/// One eye of a gaze line looking at `target` (Tobii frame, mm).
fn eye(origin: [f64; 3], target: DVec3, pupil_mm: f64) -> Value {
    let o = DVec3::from_array(origin);
    json!({
        "gazeorigin": origin,
        "gazedirection": (target - o).normalize().to_array(),
        "pupildiameter": pupil_mm,
    })
}

/// A gaze line with both eyes looking at `target` (Tobii frame, mm).
fn gaze_line(t_s: f64, target: DVec3) -> String {
    json!({
        "type": "gaze",
        "timestamp": t_s,
        "data": {
            "gaze2d": [0.5, 0.5],
            "gaze3d": target.to_array(),
            "eyeleft": eye(LEFT_EYE, target, 3.9),
            "eyeright": eye(RIGHT_EYE, target, 4.1),
        }
    })
    .to_string()
}

fn gzip(text: &str) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::default());
    e.write_all(text.as_bytes()).unwrap();
    e.finish().unwrap()
}

fn parse(
    gaze: &[u8],
    imu: Option<&[u8]>,
) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
    match imu {
        Some(mut imu) => parse_tobii_g3(gaze, "gazedata.gz", Some((&mut imu, "imudata.gz"))),
        None => parse_tobii_g3(gaze, "gazedata.gz", None),
    }
}

/// The fixture's targets (Tobii frame, mm), either side of the 0.22 m threshold between the
/// images of `config/scenes/visual-effects.toml`: near (0.14 m from the scene camera, a little
/// right and down) and far (0.45 m, left and up).
const NEAR: [f64; 3] = [-15.0, -25.0, 135.0];
const FAR: [f64; 3] = [40.0, 30.0, 445.0];

/// The gaze and IMU text of the fixture: 4 s at 50 Hz, the gaze switching between the near
/// and far targets every 0.5 s, both eyes lost for 100 ms at 1.2 s, the left eye alone lost
/// at 1.5 s; the head turning left at 10 deg/s while level, the IMU at 100 Hz with
/// magnetometer lines at 10 Hz.
fn fixture_text() -> (String, String) {
    let mut gaze = String::new();
    for i in 0..200 {
        let t = 0.02 * f64::from(i) + 3.5;
        let target = DVec3::from_array(if (i / 25) % 2 == 0 { NEAR } else { FAR });
        let line = match i {
            60..=64 => json!({"type": "gaze", "timestamp": t, "data": {}}).to_string(),
            75 => json!({"type": "gaze", "timestamp": t, "data": {
                "eyeright": eye(RIGHT_EYE, target, 4.1),
            }})
            .to_string(),
            _ => gaze_line(t, target),
        };
        gaze.push_str(&line);
        gaze.push('\n');
    }
    let mut imu = String::new();
    for i in 0..=400 {
        let t = 0.01 * f64::from(i) + 3.5;
        let line = json!({"type": "imu", "timestamp": t, "data": {
            "accelerometer": [0.02, 9.81, -0.01],
            "gyroscope": [0.0, 10.0, 0.0],
        }});
        imu.push_str(&line.to_string());
        imu.push('\n');
        if i % 10 == 0 {
            let line = json!({"type": "imu", "timestamp": t + 0.001, "data": {
                "magnetometer": [20.1, -3.2, 40.5],
            }});
            imu.push_str(&line.to_string());
            imu.push('\n');
        }
    }
    (gaze, imu)
}

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/tobii_g3")
}

/// Rewrites the committed fixture from [`fixture_text`]:
/// `cargo test -p vitreous-trace --lib write_tobii_fixture -- --ignored`.
#[test]
#[ignore = "rewrites trace/tests/data/tobii_g3"]
fn write_tobii_fixture() {
    let (gaze, imu) = fixture_text();
    std::fs::create_dir_all(data_dir()).unwrap();
    std::fs::write(data_dir().join("gazedata.gz"), gzip(&gaze)).unwrap();
    std::fs::write(data_dir().join("imudata.gz"), gzip(&imu)).unwrap();
}

/// Where a sample's two rays cross, head frame, metres.
fn crossing(s: &TraceSample) -> Vec3 {
    match closest_approach(&s.gaze.left, &s.gaze.right) {
        RayCrossing::Converge { point_m, .. } => point_m,
        other => panic!("rays do not cross: {other:?}"),
    }
}

#[test]
fn committed_fixture_gives_the_geometry_it_was_made_from() {
    let (samples, report) = import_tobii_g3(data_dir()).unwrap();
    eprintln!("{report}");
    assert_eq!((report.records, report.samples), (200, 200));
    assert_eq!((report.lost_samples, report.one_eye_samples), (5, 1));
    assert_eq!(report.head, HeadSource::Gyroscope { records: 401 });
    let ipd = report.median_ipd_mm.unwrap();
    assert!((ipd - 63.0).abs() < 0.2, "{ipd}");
    // Times start at 0 and step 20 ms.
    assert_eq!(samples[0].time_ns, 0);
    assert_eq!(samples[199].time_ns, 3_980_000_000);
    // The head frame's origin is the middle of the eyes, given from the scene camera.
    let to_openxr = |v: [f64; 3]| tobii_to_openxr(DVec3::from_array(v).as_vec3()) / 1000.0;
    let centre = (to_openxr(LEFT_EYE) + to_openxr(RIGHT_EYE)) / 2.0;
    let origin = report.head_origin_m.unwrap();
    assert!(origin.abs_diff_eq(centre, 1e-7), "{origin}");
    assert!(
        origin.y < 0.0 && origin.z > 0.0,
        "eyes below and behind the camera"
    );
    // The rays cross at the targets; the trace's fixation point is gaze3d.
    let near = to_openxr(NEAR) - centre;
    let far = to_openxr(FAR) - centre;
    for (i, s) in samples.iter().enumerate() {
        let target = if (i / 25) % 2 == 0 { near } else { far };
        if s.gaze.left.valid && s.gaze.right.valid {
            let p = crossing(s);
            assert!(p.distance(target) < 1e-3 * target.length(), "{i}: {p}");
            assert!(s.gaze.fixation.unwrap().abs_diff_eq(target, 1e-6));
            assert_eq!(s.gaze.pupil_diameter_m, [Some(0.0039), Some(0.0041)]);
        }
    }
    // Near target is to the wearer's right (+x) and below (-y), ahead (-z).
    assert!(near.x > 0.0 && near.y < 0.0 && near.z < 0.0);
    // The left eye sits at -x in OpenXR axes.
    assert!(samples[0].gaze.left.origin.x < -0.03);
    // The head turned left at 10 deg/s: 39.8 degrees by the last sample, staying level.
    let forward = samples[199].head.transform_vector(Vec3::NEG_Z);
    let expected = Quat::from_rotation_y(39.8f32.to_radians()) * Vec3::NEG_Z;
    assert!(
        forward.abs_diff_eq(expected, 2e-3),
        "{forward} vs {expected}"
    );
    assert!(samples.iter().all(|s| s.head.position == Vec3::ZERO));
}

#[test]
fn recording_folder_gaze_file_and_plain_text_import_alike() {
    let dir = tempfile::tempdir().unwrap();
    let (gaze, imu) = fixture_text();
    std::fs::write(dir.path().join("gazedata"), &gaze).unwrap();
    std::fs::write(dir.path().join("imudata.gz"), gzip(&imu)).unwrap();
    let (a, _) = import_tobii_g3(dir.path()).unwrap();
    let (b, _) = import_tobii_g3(dir.path().join("gazedata")).unwrap();
    let (c, _) = import_tobii_g3(data_dir().join("gazedata.gz")).unwrap();
    assert_eq!(a, b);
    assert_eq!(a, c);
    // Without imudata the head stays put, and the report says so.
    std::fs::remove_file(dir.path().join("imudata.gz")).unwrap();
    let (d, report) = import_tobii_g3(dir.path()).unwrap();
    assert!(d.iter().all(|s| s.head == Pose::IDENTITY));
    assert_eq!(report.head, HeadSource::None);
    assert!(report.to_string().contains("no imudata.gz"), "{report}");
    // Concatenated gzip members read as one stream.
    let lines: Vec<&str> = gaze.lines().collect();
    let mut two = gzip(&(lines[..40].join("\n") + "\n"));
    two.extend(gzip(&lines[40..].join("\n")));
    let (e, _) = parse(&two, None).unwrap();
    assert_eq!(e.len(), 200);
}

#[test]
fn gravity_sets_the_starting_pitch() {
    // Head pitched 15 degrees down: in OpenXR head axes, gravity's reaction points up and
    // toward the head's forward (-z).
    let truth = Quat::from_rotation_x(-15f32.to_radians());
    let up = tobii_to_openxr(truth.inverse() * Vec3::Y * 9.81);
    let imu: String = (0..20)
        .map(|i| {
            json!({"type": "imu", "timestamp": 0.01 * f64::from(i), "data": {
                "accelerometer": up.as_dvec3().to_array(), "gyroscope": [0.0, 0.0, 0.0]}})
            .to_string()
                + "\n"
        })
        .collect();
    let gaze = gaze_line(0.05, DVec3::new(0.0, 0.0, 500.0));
    let (s, report) = parse(gaze.as_bytes(), Some(imu.as_bytes())).unwrap();
    let forward = s[0].head.transform_vector(Vec3::NEG_Z);
    assert!(forward.abs_diff_eq(truth * Vec3::NEG_Z, 1e-4), "{forward}");
    assert!(
        !report.to_string().contains("assumed to start level"),
        "{report}"
    );
}

#[test]
fn malformed_files_name_the_file_and_line() {
    let good = gaze_line(0.0, DVec3::new(0.0, 0.0, 500.0));
    let second = gaze_line(0.01, DVec3::new(0.0, 0.0, 500.0));
    for (text, needle) in [
        (
            format!("{good}\n{{\"type\":\"gaze\",\"timestamp\":0.02,\"data\":{{\n"),
            "gazedata.gz:2: malformed JSON line",
        ),
        (
            format!(
                "{good}\n\n{}\n",
                second.replace("\"timestamp\":0.01", "\"timestamp\":NaN")
            ),
            "gazedata.gz:3: malformed JSON line",
        ),
        (
            format!("{good}\n{}\n", second.replace("\"timestamp\":0.01,", "")),
            "gazedata.gz:2: field `timestamp`",
        ),
        (
            format!(
                "{good}\n{}\n",
                second.replace("\"timestamp\":0.01", "\"timestamp\":\"0.01\"")
            ),
            "gazedata.gz:2: malformed JSON line: invalid type: string",
        ),
        (
            format!(
                "{good}\n{}\n",
                json!({"type": "gaze", "timestamp": 1, "data": {"gaze3d": [1, 2]}})
            ),
            "gazedata.gz:2: malformed JSON line: invalid length 2",
        ),
        (
            format!(
                "{good}\n{}\n",
                second.replace("\"timestamp\":0.01", "\"timestamp\":1e300")
            ),
            "gazedata.gz:2: field `timestamp`",
        ),
        ("\n\n".to_owned(), "gazedata.gz: no `gaze` records"),
        (
            format!(
                "{}\n{}\n",
                good.replace("\"timestamp\":0.0", "\"timestamp\":-3.9e9"),
                second.replace("\"timestamp\":0.01", "\"timestamp\":3.9e9")
            ),
            "s after the previous sample's",
        ),
        (
            format!(
                "{good}\n{}\n",
                second.replace("\"timestamp\":0.01", "\"timestamp\":700")
            ),
            "gazedata.gz:2: column `time_ns`: 700000000000 is 700.0 s after",
        ),
    ] {
        for bytes in [text.clone().into_bytes(), gzip(&text)] {
            let e = parse(&bytes, None).unwrap_err().to_string();
            assert!(e.contains(needle), "{needle} not in: {e}");
        }
    }
    // A gzip stream cut short fails with the line it was reading.
    let (gaze, _) = fixture_text();
    let bytes = gzip(&gaze);
    let e = parse(&bytes[..bytes.len() / 2], None)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("gazedata.gz: reading line "), "{e}");
    assert!(e.contains("cut short"), "{e}");
    // Bad IMU lines are errors too, named by the IMU file.
    let e = parse(good.as_bytes(), Some(b"{\"type\":\"imu\"}\n"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("imudata.gz:1: field `timestamp`"), "{e}");
    // A missing file is named.
    let e = import_tobii_g3(Path::new("/nonexistent/rec"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/nonexistent/rec") && e.contains("not found"),
        "{e}"
    );
}

#[test]
fn other_line_types_are_skipped_and_backward_times_dropped() {
    let a = gaze_line(1.0, DVec3::new(0.0, 0.0, 500.0));
    let b = gaze_line(0.5, DVec3::new(0.0, 0.0, 500.0));
    let c = gaze_line(1.01, DVec3::new(0.0, 0.0, 500.0));
    let sync = r#"{"type":"syncport","timestamp":1.005,"data":{"direction":"in","value":1}}"#;
    let text = format!("{a}\n{sync}\n{b}\n{c}\n");
    let (s, report) = parse(text.as_bytes(), None).unwrap();
    assert_eq!(s.len(), 2);
    assert_eq!(s[1].time_ns, 10_000_000);
    assert_eq!(
        (report.records, report.skipped_lines, report.dropped_records),
        (3, 1, 1)
    );
    // Pupils outside 1-10 mm are left out and counted.
    let text = gaze_line(0.0, DVec3::new(0.0, 0.0, 500.0))
        .replace("3.9", "0")
        .replace("4.1", "11");
    let (s, report) = parse(text.as_bytes(), None).unwrap();
    assert_eq!(s[0].gaze.pupil_diameter_m, [None, None]);
    assert_eq!(report.pupils_out_of_range, 2);
}

/// One random gaze line: time step (ms), each eye present or not, a target, pupils.
fn arb_line() -> impl Strategy<Value = (u32, [bool; 2], [f64; 3], [f64; 2], bool)> {
    (
        1u32..50,
        any::<[bool; 2]>(),
        (-500.0..500.0, -500.0..500.0, 100.0..5000.0).prop_map(|(x, y, z)| [x, y, z]),
        [0.5f64..12.0, 0.5f64..12.0],
        any::<bool>(),
    )
}

proptest! {
    #[test]
    fn imports_round_trip_through_the_trace_format(
        lines in proptest::collection::vec(arb_line(), 1..40),
        with_imu in any::<bool>(),
    ) {
        let mut text = String::new();
        let mut t_ms = 0u32;
        for (dt, present, target, pupils, gaze3d) in &lines {
            t_ms += dt;
            let target = DVec3::from_array(*target);
            let mut data = serde_json::Map::new();
            if *gaze3d {
                data.insert("gaze3d".into(), json!(target.to_array()));
            }
            for (k, (name, origin)) in [("eyeleft", LEFT_EYE), ("eyeright", RIGHT_EYE)].into_iter().enumerate() {
                if present[k] {
                    data.insert(name.into(), eye(origin, target, pupils[k]));
                }
            }
            let line = json!({"type": "gaze", "timestamp": f64::from(t_ms) / 1000.0, "data": data});
            text.push_str(&line.to_string());
            text.push('\n');
        }
        let imu = fixture_text().1;
        let (samples, report) = parse(&gzip(&text), with_imu.then_some(imu.as_bytes())).unwrap();
        prop_assert_eq!(samples.len(), lines.len());
        prop_assert_eq!(report.samples, lines.len());
        prop_assert_eq!(crate::import::written_and_read(&samples), samples);
    }
}
