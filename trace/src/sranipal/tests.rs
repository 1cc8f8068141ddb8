//! Imports of the recordings in trace/tests/data/sranipal and of small hand-made files.

use std::path::PathBuf;

use super::report::median_sorted;
use super::*;
use crate::frame::{GazeRay, Pose};

fn data(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/sranipal")
        .join(file)
}

const RECORDINGS: [&str; 3] = [
    "TESTNA01_2D_Fist3.csv",
    "TESTNA05_360VR_Spread7.csv",
    "TESTNA10_360VR_Fist3.csv",
];

/// The minimal header the importer needs, in a different order from the real files.
const MINI_HEADER: &str = "helmet_rot_x;helmet_rot_y;helmet_rot_z;helmet_pos_x;helmet_pos_y;helmet_pos_z;time(100ns);eye_valid_L;eye_valid_R;gaze_origin_L.x(mm);gaze_origin_L.y(mm);gaze_origin_L.z(mm);gaze_origin_R.x(mm);gaze_origin_R.y(mm);gaze_origin_R.z(mm);gaze_direct_L.x;gaze_direct_L.y;gaze_direct_L.z;gaze_direct_R.x;gaze_direct_R.y;gaze_direct_R.z";

/// One row of the minimal CSV: head pose (Unity), ticks, both eyes valid looking ahead.
fn mini_row(rot_deg: Vec3, pos_m: Vec3, ticks: i64) -> String {
    format!(
        "{};{};{};{};{};{};{ticks};31;31;32;0;-35;-32;0;-35;0;0;1;0;0;1",
        rot_deg.x, rot_deg.y, rot_deg.z, pos_m.x, pos_m.y, pos_m.z
    )
}

fn parse(text: &str) -> Result<(Vec<TraceSample>, ImportReport), ImportError> {
    parse_sranipal(text.as_bytes(), "mini.csv")
}

fn median(mut v: Vec<f32>) -> f32 {
    v.sort_by(f32::total_cmp);
    median_sorted(&v).unwrap()
}

#[test]
fn real_recordings_have_plausible_ipd_and_forward_gaze() {
    for file in RECORDINGS {
        let (samples, report) = import_sranipal_with_report(data(file)).unwrap();
        eprintln!("{report}");
        assert!(samples.len() > 1000, "{report}");
        let ipd = report.median_ipd_mm.unwrap();
        // TESTNA10 has both eyes valid in only ~1% of rows: its median is not meaningful.
        let ipd_range = if report.right_valid_fraction > 0.5 {
            60.0..=72.0
        } else {
            50.0..=80.0
        };
        assert!(ipd_range.contains(&ipd), "{report}");
        let rate = report.mean_rate_hz().unwrap();
        assert!((100.0..150.0).contains(&rate), "{report}");
        // Forward in the head frame is -z.
        let valid: Vec<Vec3> = samples
            .iter()
            .flat_map(|s| [s.gaze.left, s.gaze.right])
            .filter(|r| r.valid)
            .map(|r| r.direction)
            .collect();
        let dz = median(valid.iter().map(|d| d.z).collect());
        assert!(dz < -0.9, "{file}: median gaze z {dz}");
        // The left eye sits at negative x.
        let lx = median(
            samples
                .iter()
                .filter(|s| s.gaze.left.valid)
                .map(|s| s.gaze.left.origin.x)
                .collect(),
        );
        assert!(lx < -0.02, "{file}: left eye x {lx}");
        // Re-anchored: starts at the origin, facing -z; times start at 0 and increase.
        assert_eq!(samples[0].time_ns, 0);
        assert!(samples[0].head.position.length() < 1e-6);
        assert!(heading_rad(samples[0].head.orientation).abs() < 1e-4);
        assert!(samples.windows(2).all(|w| w[0].time_ns < w[1].time_ns));
        assert!(samples.iter().all(|s| s.gaze.sample_time_ns == s.time_ns));
    }
}

#[test]
fn mostly_invalid_recording_with_zero_head_pose_imports() {
    let (samples, report) = import_sranipal_with_report(data("TESTNA10_360VR_Fist3.csv")).unwrap();
    assert!(report.right_valid_fraction < 0.1, "{report}");
    assert!(report.left_valid_fraction > 0.5, "{report}");
    assert!(samples.iter().all(|s| s.head == Pose::IDENTITY));
}

#[test]
fn header_only_recording_is_an_empty_trace() {
    let (samples, report) = import_sranipal_with_report(data("TESTVA03_2D_Spread9.csv")).unwrap();
    assert!(samples.is_empty());
    assert_eq!(report.rows, 0);
    assert_eq!(report.median_ipd_mm, None);
    assert!(report.to_string().contains("0 samples"));
}

#[test]
fn gaze_is_converted_to_openxr_head_frame() {
    let text = format!("{MINI_HEADER}\n{}\n", mini_row(Vec3::ZERO, Vec3::ZERO, 5));
    let (s, _) = parse(&text).unwrap();
    let g = s[0].gaze;
    assert!(
        g.left
            .origin
            .abs_diff_eq(Vec3::new(-0.032, 0.0, 0.035), 1e-6)
    );
    assert!(
        g.right
            .origin
            .abs_diff_eq(Vec3::new(0.032, 0.0, 0.035), 1e-6)
    );
    assert_eq!(g.left.direction, Vec3::NEG_Z);
}

#[test]
fn unity_yaw_right_stays_a_turn_right() {
    let text = format!(
        "{MINI_HEADER}\n{}\n{}\n{}\n",
        mini_row(Vec3::ZERO, Vec3::ZERO, 1000),
        mini_row(Vec3::new(0.0, 30.0, 0.0), Vec3::new(0.1, 0.0, 0.0), 2000),
        mini_row(Vec3::new(20.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.2), 3000),
    );
    let (s, _) = parse(&text).unwrap();
    assert_eq!(s[1].time_ns, 100_000);
    let forward = s[1].head.transform_vector(Vec3::NEG_Z);
    assert!(
        forward.abs_diff_eq(Vec3::new(0.5, 0.0, -(3f32.sqrt()) / 2.0), 1e-5),
        "{forward}"
    );
    assert!(
        s[1].head
            .position
            .abs_diff_eq(Vec3::new(0.1, 0.0, 0.0), 1e-6)
    );
    // Unity +x pitch tilts forward down; Unity +z forward is OpenXR -z.
    let forward = s[2].head.transform_vector(Vec3::NEG_Z);
    assert!(forward.y < -0.3 && forward.z < 0.0, "{forward}");
    assert!(
        s[2].head
            .position
            .abs_diff_eq(Vec3::new(0.0, 0.0, -0.2), 1e-6)
    );
}

#[test]
fn initial_heading_is_removed_and_relative_motion_kept() {
    // Starts facing Unity +x (yaw 90), then turns 30 degrees further right and moves
    // 0.1 m along Unity +x, which is forward for this wearer.
    let text = format!(
        "{MINI_HEADER}\n{}\n{}\n",
        mini_row(Vec3::new(10.0, 90.0, 0.0), Vec3::new(1.0, 1.5, 2.0), 1000),
        mini_row(Vec3::new(10.0, 120.0, 0.0), Vec3::new(1.1, 1.5, 2.0), 2000),
    );
    let (s, report) = parse(&text).unwrap();
    assert!((report.removed_yaw_rad + std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    assert!(s[0].head.position.length() < 1e-6);
    // Pitch (10 degrees down) is kept, heading removed.
    let f0 = s[0].head.transform_vector(Vec3::NEG_Z);
    assert!(
        f0.abs_diff_eq(
            Vec3::new(
                0.0,
                -(10f32.to_radians().sin()),
                -(10f32.to_radians().cos())
            ),
            1e-5
        ),
        "{f0}"
    );
    assert!(
        s[1].head
            .position
            .abs_diff_eq(Vec3::new(0.0, 0.0, -0.1), 1e-5),
        "{}",
        s[1].head.position
    );
    assert!((heading_rad(s[1].head.orientation) + 30f32.to_radians()).abs() < 1e-4);
}

#[test]
fn invalid_eye_flags_and_bad_rays_give_invalid_rays() {
    let row = mini_row(Vec3::ZERO, Vec3::ZERO, 1);
    let partly = row.replacen(";31;31;", ";25;24;", 1);
    let nan = mini_row(Vec3::ZERO, Vec3::ZERO, 2).replacen(";0;0;1;0;0;1", ";NaN;0;1;0;0;0", 1);
    let (s, report) = parse(&format!("{MINI_HEADER}\n{partly}\n{nan}\n")).unwrap();
    assert_eq!(s[0].gaze.left, GazeRay::INVALID);
    assert_eq!(s[0].gaze.right, GazeRay::INVALID);
    assert_eq!(s[1].gaze.left, GazeRay::INVALID);
    assert_eq!(s[1].gaze.right, GazeRay::INVALID);
    assert_eq!(report.median_ipd_mm, None);
}

#[test]
fn malformed_rows_name_file_line_and_column() {
    let good = mini_row(Vec3::ZERO, Vec3::ZERO, 1);
    let bad_time = mini_row(Vec3::ZERO, Vec3::ZERO, 2).replacen(";2;", ";2x;", 1);
    let e = parse(&format!("{MINI_HEADER}\n{good}\n{bad_time}\n")).unwrap_err();
    assert!(
        matches!(
            e,
            ImportError::BadField {
                line: 3,
                column: TIME,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("mini.csv:3:"), "{e}");

    let short = format!("{MINI_HEADER}\n{good}\n\n1;2;3\n");
    let e = parse(&short).unwrap_err();
    assert!(
        matches!(
            e,
            ImportError::FieldCount {
                line: 4,
                found: 3,
                expected: 21,
                ..
            }
        ),
        "{e}"
    );

    let nan_head = format!("{MINI_HEADER}\nNaN{}\n", &good[1..]);
    let e = parse(&nan_head).unwrap_err();
    assert!(
        matches!(
            e,
            ImportError::NonFinite {
                line: 2,
                column: "helmet_rot_x",
                ..
            }
        ),
        "{e}"
    );

    let e = parse("time(100ns);eye_valid_L\n").unwrap_err();
    assert!(
        matches!(
            e,
            ImportError::MissingColumn {
                line: 1,
                column: "eye_valid_R",
                ..
            }
        ),
        "{e}"
    );
    assert!(matches!(parse(""), Err(ImportError::Empty { .. })));
}

#[test]
fn a_huge_row_is_refused_with_its_start_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.csv");
    let mut text = format!("{MINI_HEADER}\n").into_bytes();
    text.extend(std::iter::repeat_n(0u8, 2 << 20));
    std::fs::write(&path, &text).unwrap();
    let e = import_sranipal(&path).unwrap_err();
    assert!(matches!(e, ImportError::LineTooLong { line: 2, .. }), "{e}");
    let message = e.to_string();
    assert!(message.contains("huge.csv:2:"), "{message}");
    assert!(message.contains("\\0\\0"), "{message}");
    assert!(!message.contains('\0'), "{message}");
}

#[test]
fn clock_jumps_are_refused_with_the_line() {
    let a = mini_row(Vec3::ZERO, Vec3::ZERO, 10);
    // One hour later, in 100 ns ticks.
    let b = mini_row(Vec3::ZERO, Vec3::ZERO, 10 + 36_000_000_000);
    let e = parse(&format!("{MINI_HEADER}\n{a}\n{b}\n")).unwrap_err();
    assert!(matches!(e, ImportError::GapTooLong { line: 3, .. }), "{e}");
    let c = mini_row(Vec3::ZERO, Vec3::ZERO, i64::MAX);
    let e = parse(&format!("{MINI_HEADER}\n{a}\n{c}\n")).unwrap_err();
    assert!(matches!(e, ImportError::TimeRange { line: 3, .. }), "{e}");
}

#[test]
fn positions_too_far_apart_are_an_error_not_a_non_finite_pose() {
    let a = mini_row(Vec3::ZERO, Vec3::new(-3e38, 0.0, 0.0), 1);
    let b = mini_row(Vec3::ZERO, Vec3::new(3e38, 0.0, 0.0), 2);
    let e = parse(&format!("{MINI_HEADER}\n{a}\n{b}\n")).unwrap_err();
    assert!(
        matches!(
            e,
            ImportError::BadField {
                line: 3,
                column: "helmet_pos_x",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn repeated_times_are_dropped_and_counted() {
    let a = mini_row(Vec3::ZERO, Vec3::ZERO, 10);
    let b = mini_row(Vec3::ZERO, Vec3::ZERO, 10);
    let c = mini_row(Vec3::ZERO, Vec3::ZERO, 5);
    let (s, report) = parse(&format!("{MINI_HEADER}\n{a}\n{b}\n{c}\n")).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!((report.rows, report.dropped_rows), (3, 2));
}

#[test]
fn imported_trace_survives_the_trace_format() {
    let samples = import_sranipal(data("TESTNA01_2D_Fist3.csv")).unwrap();
    let mut w = crate::format::TraceWriter::new(Vec::new()).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    let text = w.finish().unwrap();
    let back: Vec<TraceSample> = crate::format::TraceReader::new(&text[..], "t")
        .unwrap()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(back, samples);
}
