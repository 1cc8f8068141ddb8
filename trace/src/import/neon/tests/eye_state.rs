//! Tests of the import from eye states (a recording without a gaze stream).

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use proptest::prelude::*;

use super::*;

/// The eye-state fields of a recording without a gaze stream, as newer Companion versions
/// write them (no eyelid fields: they are not read).
const EYE_AXES_DTYPE: &str = "[\n(\"pupil_diameter_left_mm\", \"float32\"),\n(\"eyeball_center_left_x\", \"float32\"),\n(\"eyeball_center_left_y\", \"float32\"),\n(\"eyeball_center_left_z\", \"float32\"),\n(\"optical_axis_left_x\", \"float32\"),\n(\"optical_axis_left_y\", \"float32\"),\n(\"optical_axis_left_z\", \"float32\"),\n(\"pupil_diameter_right_mm\", \"float32\"),\n(\"eyeball_center_right_x\", \"float32\"),\n(\"eyeball_center_right_y\", \"float32\"),\n(\"eyeball_center_right_z\", \"float32\"),\n(\"optical_axis_right_x\", \"float32\"),\n(\"optical_axis_right_y\", \"float32\"),\n(\"optical_axis_right_z\", \"float32\"),\n]\n";

/// An eye-state record (layout [`EYE_AXES_DTYPE`]) of eyes at `left` and `right` (scene
/// camera frame, mm) fixating `target`, their optical axes the visual axes turned back by
/// `kappa_deg`.
fn eye_state_record(left: DVec3, right: DVec3, target: DVec3, kappa_deg: f64) -> Vec<u8> {
    let mut record = Vec::new();
    for (eye, centre, pupil_mm) in [(Eye::Left, left, 3.9), (Eye::Right, right, 4.2)] {
        let axis = kappa::optical_axis(target - centre, eye, kappa_deg.to_radians()).unwrap();
        record.extend(f32s(&[pupil_mm]));
        record.extend(f32s(&centre.as_vec3().to_array()));
        record.extend(f32s(&axis.as_vec3().to_array()));
    }
    record
}

/// Writes the recording of [`write_recording`] without its gaze stream, its eye states the
/// eyes fixating [`target`] with optical axes [`DEFAULT_KAPPA_DEG`] temporal of the visual
/// axes.
fn write_eye_state_recording(dir: &Path) {
    write_recording(dir);
    for f in ["gaze ps1.raw", "gaze ps1.time", "gaze.dtype"] {
        std::fs::remove_file(dir.join(f)).unwrap();
    }
    let times: Vec<u64> = (0..200)
        .map(|i| START_NS + 2_500_000 + i * 5_000_000)
        .collect();
    let eyes = |c: [f32; 3]| DVec3::from_array(c.map(f64::from));
    let records: Vec<Vec<u8>> = times
        .iter()
        .map(|&t| {
            let t_s = (t - START_NS) as f64 * 1e-9;
            let target = target(t_s);
            eye_state_record(eyes(LEFT_EYE), eyes(RIGHT_EYE), target, DEFAULT_KAPPA_DEG)
        })
        .collect();
    write_part(dir, "eye_state", 1, &records, &times);
    std::fs::write(dir.join("eye_state.dtype"), EYE_AXES_DTYPE).unwrap();
}

fn eye_state_data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/neon-eye-state")
}

/// Rewrites the committed fixture from [`write_eye_state_recording`]:
/// `cargo test -p vitreous-trace --lib write_neon_eye_state_fixture -- --ignored`.
#[test]
#[ignore = "rewrites trace/tests/data/neon-eye-state"]
fn write_neon_eye_state_fixture() {
    let dir = eye_state_data_dir();
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    write_eye_state_recording(&dir);
}

/// Where `a` and `b` cross, asserting that they do.
fn crossing(a: &GazeRay, b: &GazeRay) -> Vec3 {
    match crate::crossing::closest_approach(a, b) {
        crate::crossing::RayCrossing::Converge { point_m, .. } => point_m,
        other => panic!("the rays do not cross: {other:?}"),
    }
}

#[test]
fn eye_state_fixture_without_gaze_verges_on_the_targets_it_was_made_from() {
    let (samples, report) = import_neon(eye_state_data_dir()).unwrap();
    eprintln!("{report}");
    assert_eq!((report.records, report.samples), (200, 200));
    assert_eq!(
        (
            report.blink_samples,
            report.lost_samples,
            report.one_eye_samples
        ),
        (20, 20, 0)
    );
    assert_eq!(report.head, HeadSource::ImuOrientation { records: 111 });
    let left = openxr(DVec3::from_array(LEFT_EYE.map(f64::from))) / 1000.0;
    let right = openxr(DVec3::from_array(RIGHT_EYE.map(f64::from))) / 1000.0;
    let centre = (left + right) / 2.0;
    assert!(report.head_origin_m.unwrap().abs_diff_eq(centre, 1e-7));
    // Times from the eye states, which start 2.5 ms after the recording.
    assert_eq!(samples[199].time_ns, 995_000_000);
    for (i, s) in samples.iter().enumerate() {
        let t_s = 0.0025 + i as f64 * 0.005;
        let blink = (0.3..=0.4).contains(&t_s);
        assert_eq!(s.gaze.left.valid, !blink, "{i}");
        assert_eq!(s.gaze.right.valid, !blink, "{i}");
        assert_eq!(s.gaze.combined, None);
        if blink {
            continue;
        }
        assert!(s.gaze.left.origin.abs_diff_eq(left - centre, 1e-7));
        assert!(s.gaze.right.origin.abs_diff_eq(right - centre, 1e-7));
        let expected = openxr(target(t_s)) / 1000.0 - centre;
        let point = crossing(&s.gaze.left, &s.gaze.right);
        assert!(
            point.distance(expected) < 1e-4,
            "{i}: {point} vs {expected}"
        );
        let [l, r] = s.gaze.pupil_diameter_m.map(Option::unwrap);
        assert!((l - 0.0039).abs() < 1e-9 && (r - 0.0042).abs() < 1e-9);
    }
    // The head turns as in the gaze recording.
    let pitch = Quat::from_rotation_x(-12f32.to_radians());
    let f0 = samples[0].head.transform_vector(Vec3::NEG_Z);
    assert!(f0.abs_diff_eq(pitch * Vec3::NEG_Z, 1e-5), "{f0}");
    let text = report.to_string();
    for needle in [
        "the gaze comes from the eye states' optical axes",
        "turned 5.0 degrees toward the nose",
        "the default, a population mean for adults, not this wearer's",
        "fixation depth from the vergence of these two rays is unreliable",
    ] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    assert!(!text.contains("not measured"), "{text}");
    assert!(!text.contains("calibration.bin"), "{text}");
}

#[test]
fn gaze_stream_is_preferred_and_eye_state_gaze_can_be_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    write_recording(dir.path());
    let (default, _) = import_neon(dir.path()).unwrap();
    let (auto, _) = import_neon_with(dir.path(), &NeonOptions::default()).unwrap();
    assert_eq!(auto, default);
    assert_eq!(
        default[0].gaze.left.direction,
        default[0].gaze.right.direction
    );
    // The fixture's optical axes are 5 degrees nasal of straight ahead; kappa turns them
    // further toward each other, and 0 keeps them.
    let optical = [
        DVec3::new(0.087, 0.0, 0.996),
        DVec3::new(-0.087, 0.0, 0.996),
    ];
    for kappa_deg in [0.0, 5.0, -2.0] {
        let options = NeonOptions {
            gaze: GazeSource::EyeState,
            kappa_deg,
        };
        let (samples, report) = import_neon_with(dir.path(), &options).unwrap();
        assert_eq!(report.samples, 200);
        let text = report.to_string();
        let kappa_from = if kappa_deg == DEFAULT_KAPPA_DEG {
            "the default, a population mean"
        } else {
            "as given, not measured for this wearer"
        };
        assert!(
            text.contains(&format!("turned {kappa_deg:.1} degrees toward the nose"))
                && text.contains(kappa_from),
            "{text}"
        );
        let s = &samples[0].gaze;
        for (ray, (axis, eye)) in [s.left, s.right].iter().zip(optical.iter().zip(Eye::BOTH)) {
            let expected = kappa::visual_axis(*axis, eye, kappa_deg.to_radians()).unwrap();
            assert!(
                ray.direction.abs_diff_eq(openxr(expected), 1e-6),
                "{kappa_deg}: {eye:?}"
            );
            let optical = openxr(*axis).as_dvec3();
            let turn = ray.direction.as_dvec3().angle_between(optical);
            assert!((turn - kappa_deg.abs().to_radians()).abs() < 1e-5, "{turn}");
        }
    }
}

#[test]
fn malformed_eye_state_recordings_name_the_file_and_record() {
    type Break = fn(&Path);
    let cases: [(Break, &str); 7] = [
        (
            |d| {
                let raw = std::fs::read(d.join("eye_state ps1.raw")).unwrap();
                std::fs::write(d.join("eye_state ps1.raw"), &raw[..raw.len() - 5]).unwrap();
            },
            "eye_state ps1.raw: 11195 bytes is not a whole number of 56-byte records",
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
                // Record 7's left optical axis: zero.
                let mut raw = std::fs::read(d.join("eye_state ps1.raw")).unwrap();
                raw[6 * 56 + 16..6 * 56 + 28].fill(0);
                std::fs::write(d.join("eye_state ps1.raw"), raw).unwrap();
            },
            "eye_state ps1.raw:record 7: field `optical_axis_left_{x,y,z}`: expected a unit \
             vector",
        ),
        (
            |d| {
                // Record 3's right optical axis: twice its length.
                let mut raw = std::fs::read(d.join("eye_state ps1.raw")).unwrap();
                for k in 0..3 {
                    let at = 2 * 56 + 44 + 4 * k;
                    let v = f32::from_le_bytes(raw[at..at + 4].try_into().unwrap());
                    raw[at..at + 4].copy_from_slice(&(2.0 * v).to_le_bytes());
                }
                std::fs::write(d.join("eye_state ps1.raw"), raw).unwrap();
            },
            "record 3: field `optical_axis_right_{x,y,z}`",
        ),
        (
            |d| {
                std::fs::write(
                    d.join("eye_state.dtype"),
                    EYE_AXES_DTYPE.replace("optical_axis_left_y", "optical_axis_left_v"),
                )
                .unwrap()
            },
            "eye_state.dtype: no field `optical_axis_left_y` (float32 expected); fields: \
             pupil_diameter_left_mm",
        ),
        (
            |d| std::fs::remove_file(d.join("eye_state ps1.raw")).unwrap(),
            "gaze ps1.raw: not found; the gaze stream is needed, or, without it, the eye-state \
             stream",
        ),
        (
            |d| write_part(d, "eye_state", 1, &[], &[]),
            "eye_state ps1.raw: no eye-state records",
        ),
    ];
    for (spoil, needle) in cases {
        let dir = tempfile::tempdir().unwrap();
        write_eye_state_recording(dir.path());
        spoil(dir.path());
        let e = import_neon(dir.path()).unwrap_err().to_string();
        assert!(e.contains(needle), "{needle} not in: {e}");
    }
    // Without a gaze stream, a dtype without the optical axes says why they are needed.
    let dir = tempfile::tempdir().unwrap();
    write_eye_state_recording(dir.path());
    std::fs::write(
        dir.path().join("eye_state.dtype"),
        "[(\"pupil_diameter_left_mm\", \"float32\"), (\"eyeball_center_left_x\", \"float32\"), \
         (\"eyeball_center_left_y\", \"float32\"), (\"eyeball_center_left_z\", \"float32\"), \
         (\"pupil_diameter_right_mm\", \"float32\"), (\"eyeball_center_right_x\", \"float32\"), \
         (\"eyeball_center_right_y\", \"float32\"), (\"eyeball_center_right_z\", \"float32\"), \
         (\"rest\", \"float64\"), (\"more\", \"float64\"), (\"end\", \"float64\")]",
    )
    .unwrap();
    let e = import_neon(dir.path()).unwrap_err().to_string();
    assert!(
        e.contains("no field `optical_axis_left_x`")
            && e.contains("the recording has no gaze stream"),
        "{e}"
    );
}

#[test]
fn non_finite_optical_axes_make_their_eye_invalid_and_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    write_eye_state_recording(dir.path());
    let mut raw = std::fs::read(dir.path().join("eye_state ps1.raw")).unwrap();
    // Record 1's left axis has a NaN component, record 2's right axis an infinite one.
    raw[16..20].copy_from_slice(&f32::NAN.to_le_bytes());
    raw[56 + 48..56 + 52].copy_from_slice(&f32::INFINITY.to_le_bytes());
    std::fs::write(dir.path().join("eye_state ps1.raw"), raw).unwrap();
    let (samples, report) = import_neon(dir.path()).unwrap();
    assert!(!samples[0].gaze.left.valid && samples[0].gaze.right.valid);
    assert!(samples[1].gaze.left.valid && !samples[1].gaze.right.valid);
    // The pupils are still read.
    assert!(samples[0].gaze.pupil_diameter_m[0].is_some());
    assert_eq!(report.one_eye_samples, 2);
    let text = report.to_string();
    assert!(
        text.contains("2 eyes have no optical axis (not finite)"),
        "{text}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn optical_axes_turned_back_by_kappa_import_to_rays_that_meet_at_the_target(
        left in (-36.0f64..-26.0, 5.0f64..20.0, -30.0f64..-12.0),
        right in (26.0f64..36.0, 5.0f64..20.0, -30.0f64..-12.0),
        targets in proptest::collection::vec(
            (-600.0f64..600.0, -500.0f64..500.0, 200.0f64..3000.0),
            1..6,
        ),
        kappa_deg in -3.0f64..8.0,
    ) {
        let dir = tempfile::tempdir().unwrap();
        let (left, right) = (DVec3::from(left), DVec3::from(right));
        let targets: Vec<DVec3> = targets.into_iter().map(DVec3::from).collect();
        let times: Vec<u64> = (0..targets.len() as u64).map(|i| START_NS + i * 5_000_000).collect();
        let records: Vec<Vec<u8>> = targets
            .iter()
            .map(|&t| eye_state_record(left, right, t, kappa_deg))
            .collect();
        write_part(dir.path(), "eye_state", 1, &records, &times);
        std::fs::write(dir.path().join("eye_state.dtype"), EYE_AXES_DTYPE).unwrap();
        let options = NeonOptions { kappa_deg, ..NeonOptions::default() };
        let (samples, report) = import_neon_with(dir.path(), &options).unwrap();
        prop_assert_eq!(samples.len(), targets.len());
        let origin = report.head_origin_m.unwrap();
        for (s, &target) in samples.iter().zip(&targets) {
            let expected = openxr(target) / 1000.0 - origin;
            let point = crossing(&s.gaze.left, &s.gaze.right);
            // Float32 axes: well under a millimetre per metre of depth.
            let tolerance = 1e-4 + 1e-3 * expected.length();
            prop_assert!(
                point.distance(expected) < tolerance,
                "{} vs {}", point, expected
            );
        }
    }
}
