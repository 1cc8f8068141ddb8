//! The gaze of a Neon recording from its eye states: each eye's optical axis turned toward
//! the nose by the angle kappa ([`super::kappa`]), from its eyeball centre, one sample per
//! eye-state record. Used when the recording has no gaze stream, or when asked for.

use glam::DVec3;

use super::kappa::{Eye, visual_axis};
use super::raw::{Scalar, Stream};
use super::{Counts, Inputs, Timeline, eye_ray, neon_to_openxr, pupil_m, sample_time};
use crate::format::TraceSample;
use crate::frame::{GazeRay, GazeSample};
use crate::import::RecordingError;

/// The eye-state fields read when the gaze comes from the eye states:
/// [`super::EYE_FIELDS`], then the optical axes (unit vectors, scene camera frame), in this
/// order.
pub(super) const EYE_AXIS_FIELDS: &[(&str, Scalar)] = &[
    ("eyeball_center_left_x", Scalar::F32),
    ("eyeball_center_left_y", Scalar::F32),
    ("eyeball_center_left_z", Scalar::F32),
    ("pupil_diameter_left_mm", Scalar::F32),
    ("eyeball_center_right_x", Scalar::F32),
    ("eyeball_center_right_y", Scalar::F32),
    ("eyeball_center_right_z", Scalar::F32),
    ("pupil_diameter_right_mm", Scalar::F32),
    ("optical_axis_left_x", Scalar::F32),
    ("optical_axis_left_y", Scalar::F32),
    ("optical_axis_left_z", Scalar::F32),
    ("optical_axis_right_x", Scalar::F32),
    ("optical_axis_right_y", Scalar::F32),
    ("optical_axis_right_z", Scalar::F32),
];

/// How far an optical axis's length may be from 1 (float32 rounding, a writer normalising
/// loosely) before the record is refused as malformed.
const AXIS_LENGTH_TOLERANCE: f64 = 0.1;

impl Inputs {
    /// The samples of the eye-state stream: each eye's optical axis, turned by `kappa_rad`
    /// toward the nose, from its eyeball centre. No combined ray: the eye state has none.
    pub(super) fn samples_from_eye_states(
        &self,
        timeline: &Timeline,
        kappa_rad: f64,
        counts: &mut Counts,
    ) -> Result<Vec<TraceSample>, RecordingError> {
        let eyes = &self.eyes;
        let mut samples: Vec<TraceSample> = Vec::with_capacity(eyes.len());
        for i in 0..eyes.len() {
            let t = eyes.times_ns[i];
            let Some(time_ns) = sample_time(eyes, i, timeline.t0, samples.last(), counts)? else {
                continue;
            };
            let blink = timeline.in_blink(t);
            counts.in_blinks += usize::from(blink);
            let e = eyes.record(i);
            let mut rays = [GazeRay::INVALID; 2];
            let mut pupils = [None; 2];
            for (side, eye) in Eye::BOTH.into_iter().enumerate() {
                if blink {
                    break;
                }
                let v = &e[4 * side..4 * side + 4];
                let a = &e[8 + 3 * side..11 + 3 * side];
                let optical = DVec3::new(a[0], a[1], a[2]);
                if optical.is_finite() {
                    check_axis(eyes, i, eye, optical)?;
                    if let Some(d) = visual_axis(optical, eye, kappa_rad) {
                        rays[side] = eye_ray(v, neon_to_openxr(d.as_vec3()));
                    }
                } else {
                    counts.no_axis += 1;
                }
                pupils[side] = pupil_m(v[3], &mut counts.pupils_out);
            }
            samples.push(TraceSample {
                time_ns,
                head: timeline.head(t),
                gaze: GazeSample {
                    sample_time_ns: time_ns,
                    left: rays[0],
                    right: rays[1],
                    combined: None,
                    fixation: None,
                    pupil_diameter_m: pupils,
                    report: None,
                },
            });
        }
        Ok(samples)
    }
}

/// Refuses a finite optical axis that is not a unit vector (a zero vector, or a layout that
/// does not match the file): record `i` of `eyes`, for `eye`.
fn check_axis(eyes: &Stream, i: usize, eye: Eye, axis: DVec3) -> Result<(), RecordingError> {
    let length = axis.length();
    if (1.0 - AXIS_LENGTH_TOLERANCE..=1.0 + AXIS_LENGTH_TOLERANCE).contains(&length) {
        return Ok(());
    }
    let (file, record) = eyes.locate(i);
    Err(RecordingError::BadValue {
        file: file.to_owned(),
        at: format!("record {record}"),
        field: format!("optical_axis_{}_{{x,y,z}}", eye.name()),
        found: format!("({}, {}, {}), of length {length}", axis.x, axis.y, axis.z),
        expected: "a unit vector (the direction from the eyeball centre through the pupil)",
    })
}
