//! Import of Pupil Labs Neon native recordings (the folder the Companion app writes).
//!
//! Streams read (`NAME psN.raw` with `NAME psN.time`, layouts in `NAME.dtype`; see `raw.rs`):
//!
//! | stream | fields read | use |
//! |---|---|---|
//! | `gaze psN` | `x`, `y` (float32, scene-image pixels) | the visual gaze direction |
//! | `eye_state psN` | `eyeball_center_{left,right}_{x,y,z}` (mm), `pupil_diameter_{left,right}_mm` | eye ray origins, pupils |
//! | `blinks psN` (optional) | `start_timestamp_ns`, `end_timestamp_ns` (int64) | eyes invalid inside a blink |
//! | `imu psN` (optional) | `quaternion_{w,x,y,z}` (float32) | head orientation |
//!
//! `calibration.bin` gives the scene camera model ([`camera`]); without it the nominal
//! camera is assumed. `info.json`, when present, must be valid JSON; its `wearer_ied` is
//! not needed.
//!
//! Conversions, into the OpenXR conventions of this crate:
//! - **Frames**: Neon's 3D eye data are in the scene camera's frame (OpenCV axes: +x right,
//!   +y down, +z forward, mm). The trace's head frame is that frame turned half a turn
//!   about x: `(x, y, z) -> (x, -y, -z)`, millimetres to metres, with its origin then moved
//!   from the scene camera to the middle of the eyes (the median midpoint of the two eyeball
//!   centres over the recording).
//! - **Gaze**: the gaze point (pixels) is undistorted into a direction from the scene camera.
//!   That is the *visual* gaze. The eye-state optical axes are not used: the optical axis is
//!   about 5 degrees from the visual axis, so their vergence says nothing about depth.
//! - **Depth is not measured**: Neon gives one gaze point, not a binocular one. Each eye's
//!   ray starts at its eyeball centre and runs parallel to the visual gaze direction, so the
//!   two rays meet at infinity; the combined ray is the visual gaze from the scene camera.
//! - **Validity**: an eye is invalid inside a marked blink, when the gaze point is not finite
//!   or not invertible, or when no eye-state record lies within 25 ms of the gaze sample.
//!   Pupil diameters outside 1-10 mm are left out and counted.
//! - **Head**: position is not recorded (kept at the origin). The rotation is the IMU's own
//!   orientation (IMU frame: +x right, +y forward, +z up; world: +z up, +y magnetic north)
//!   turned into the scene camera frame (fixed 102-degree turn about x between the two, the
//!   module's mounting), then into OpenXR axes, re-anchored so the first sample faces -z.
//! - **Time**: nanoseconds since the first gaze sample (the `.time` files hold Unix-epoch
//!   nanoseconds). Gaze samples whose time is not after the previous kept one are dropped
//!   and counted; the trace limits (10-minute gap, 24-hour span) fail the import.

pub mod camera;
mod raw;
#[cfg(test)]
mod tests;

use std::path::Path;

use glam::{DVec3, Quat, Vec3};

use super::eye_centre::centre_on_eyes;
use super::orientation::{OrientationTrack, unyaw};
use super::{HeadSource, RecordingError, RecordingReport};
use crate::frame::{GazeRay, GazeSample, Pose};
use crate::trace::{PUPIL_RANGE_M, TraceSample, check_span, clean_ray};
pub use camera::SceneCamera;
use raw::{Scalar, Stream, read_stream};

/// The recording format, as reports name it.
pub const FORMAT: &str = "Pupil Labs Neon";

/// The longest time between a gaze sample and the eye-state record paired with it.
pub const EYE_STATE_MAX_GAP_NS: i64 = 25_000_000;

/// The fixed turn about +x from the scene camera frame to the IMU frame, degrees.
const SCENE_TO_IMU_DEG: f32 = -102.0;

/// The layout of `gaze psN.raw` when there is no `gaze.dtype`.
const GAZE_LAYOUT: &[(&str, Scalar)] = &[("x", Scalar::F32), ("y", Scalar::F32)];

/// The eye-state fields read, in this order.
const EYE_FIELDS: &[(&str, Scalar)] = &[
    ("eyeball_center_left_x", Scalar::F32),
    ("eyeball_center_left_y", Scalar::F32),
    ("eyeball_center_left_z", Scalar::F32),
    ("pupil_diameter_left_mm", Scalar::F32),
    ("eyeball_center_right_x", Scalar::F32),
    ("eyeball_center_right_y", Scalar::F32),
    ("eyeball_center_right_z", Scalar::F32),
    ("pupil_diameter_right_mm", Scalar::F32),
];

/// The layout of `eye_state psN.raw` when there is no `eye_state.dtype`.
const EYE_STATE_LAYOUT: &[(&str, Scalar)] = &[
    ("pupil_diameter_left_mm", Scalar::F32),
    ("eyeball_center_left_x", Scalar::F32),
    ("eyeball_center_left_y", Scalar::F32),
    ("eyeball_center_left_z", Scalar::F32),
    ("optical_axis_left_x", Scalar::F32),
    ("optical_axis_left_y", Scalar::F32),
    ("optical_axis_left_z", Scalar::F32),
    ("pupil_diameter_right_mm", Scalar::F32),
    ("eyeball_center_right_x", Scalar::F32),
    ("eyeball_center_right_y", Scalar::F32),
    ("eyeball_center_right_z", Scalar::F32),
    ("optical_axis_right_x", Scalar::F32),
    ("optical_axis_right_y", Scalar::F32),
    ("optical_axis_right_z", Scalar::F32),
];

/// The blink fields read, and the layout of `blinks psN.raw` without `blinks.dtype`.
const BLINK_FIELDS: &[(&str, Scalar)] = &[
    ("start_timestamp_ns", Scalar::Int(8)),
    ("end_timestamp_ns", Scalar::Int(8)),
];

/// The IMU fields read, in this order.
const IMU_FIELDS: &[(&str, Scalar)] = &[
    ("quaternion_w", Scalar::F32),
    ("quaternion_x", Scalar::F32),
    ("quaternion_y", Scalar::F32),
    ("quaternion_z", Scalar::F32),
];

/// The layout of `imu psN.raw` when there is no `imu.dtype`.
const IMU_LAYOUT: &[(&str, Scalar)] = &[
    ("gyro_x", Scalar::F32),
    ("gyro_y", Scalar::F32),
    ("gyro_z", Scalar::F32),
    ("accel_x", Scalar::F32),
    ("accel_y", Scalar::F32),
    ("accel_z", Scalar::F32),
    ("quaternion_w", Scalar::F32),
    ("quaternion_x", Scalar::F32),
    ("quaternion_y", Scalar::F32),
    ("quaternion_z", Scalar::F32),
];

/// Converts a vector of Neon's scene-camera frame (+x right, +y down, +z forward) into the
/// OpenXR head frame (+x right, +y up, -z forward), keeping its unit.
pub fn neon_to_openxr(v: Vec3) -> Vec3 {
    Vec3::new(v.x, -v.y, -v.z)
}

/// The head orientation (OpenXR head frame to OpenXR world, +y up) of a Neon IMU orientation
/// quaternion (IMU frame to Neon world, +z up), before re-anchoring.
pub fn imu_to_head_orientation(imu: Quat) -> Quat {
    // OpenXR head -> scene camera (half turn about x) -> IMU -> Neon world -> OpenXR world
    // (-90 degrees about x takes +z up to +y up and +y north to -z).
    let head_to_imu = Quat::from_rotation_x((SCENE_TO_IMU_DEG + 180.0).to_radians());
    (Quat::from_rotation_x(-90f32.to_radians()) * imu * head_to_imu).normalize()
}

/// Imports the Neon native recording in `folder`.
pub fn import_neon(
    folder: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
    let folder = folder.as_ref();
    let name = folder.display().to_string();
    if !folder.is_dir() {
        return Err(RecordingError::Missing {
            file: name,
            why: "a Neon native recording is a folder (with `gaze ps1.raw`, `eye_state ps1.raw`, ...)",
        });
    }
    let mut notes = vec!["head position is not recorded: the head stays at the origin".to_owned()];
    let info = folder.join("info.json");
    if info.is_file() {
        let text = std::fs::read_to_string(&info).map_err(|source| RecordingError::Io {
            file: info.display().to_string(),
            context: "reading".to_owned(),
            source,
        })?;
        serde_json::from_str::<serde_json::Value>(&text).map_err(|e| RecordingError::Json {
            file: info.display().to_string(),
            line: e.line(),
            message: format!("malformed JSON: {e}"),
        })?;
    }
    let calibration = folder.join("calibration.bin");
    let camera = if calibration.is_file() {
        let bytes = std::fs::read(&calibration).map_err(|source| RecordingError::Io {
            file: calibration.display().to_string(),
            context: "reading".to_owned(),
            source,
        })?;
        SceneCamera::from_calibration(&bytes, &calibration.display().to_string())?
    } else {
        notes.push(
            "no calibration.bin: the nominal scene camera (891 px focal length, no lens \
             distortion) turns gaze pixels into directions, off by degrees near the image edges"
                .to_owned(),
        );
        SceneCamera::NOMINAL
    };
    let missing = |base: &str, why: &'static str| RecordingError::Missing {
        file: folder.join(format!("{base} ps1.raw")).display().to_string(),
        why,
    };
    let gaze = read_stream(folder, "gaze", GAZE_LAYOUT, GAZE_LAYOUT)?
        .ok_or_else(|| missing("gaze", "the gaze stream is needed"))?;
    let eyes =
        read_stream(folder, "eye_state", EYE_FIELDS, EYE_STATE_LAYOUT)?.ok_or_else(|| {
            missing(
                "eye_state",
                "the eye-state stream (eyeball centres, pupils) is needed",
            )
        })?;
    let blinks = read_stream(folder, "blinks", BLINK_FIELDS, BLINK_FIELDS)?.unwrap_or_default();
    let imu = read_stream(folder, "imu", IMU_FIELDS, IMU_LAYOUT)?;
    let inputs = Inputs {
        name,
        camera,
        gaze,
        eyes,
        blinks,
        imu,
    };
    inputs.convert(notes)
}

/// Everything read from a recording folder.
struct Inputs {
    /// The folder, for messages and the report.
    name: String,
    /// The scene camera model.
    camera: SceneCamera,
    /// Gaze: x, y pixels.
    gaze: Stream,
    /// Eye state: [`EYE_FIELDS`].
    eyes: Stream,
    /// Blinks: start, end (ns); possibly empty.
    blinks: Stream,
    /// IMU: w, x, y, z; `None` without an IMU stream.
    imu: Option<Stream>,
}

impl Inputs {
    /// Builds the trace.
    fn convert(
        self,
        mut notes: Vec<String>,
    ) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
        let Some(&t0) = self.gaze.times_ns.first() else {
            return Err(RecordingError::Empty {
                file: self.gaze.locate(0).0.to_owned(),
                what: "gaze",
            });
        };
        let (track, head) = match &self.imu {
            Some(imu) if imu.len() > 0 => {
                let track = OrientationTrack::new((0..imu.len()).map(|i| {
                    let q = imu.record(i);
                    let q = Quat::from_xyzw(q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32);
                    (imu.times_ns[i], imu_to_head_orientation(q))
                }));
                notes.push(
                    "head rotation is the IMU's fused orientation turned by the module's fixed \
                     scene-camera-to-IMU mounting (102 degrees about x); heading relative to \
                     the first sample"
                        .to_owned(),
                );
                let records = track.len();
                (track, HeadSource::ImuOrientation { records })
            }
            _ => {
                notes.push("no IMU stream: head orientation fixed (identity)".to_owned());
                (OrientationTrack::default(), HeadSource::None)
            }
        };
        notes.push(
            "fixation depth is not measured (one gaze point, no binocular depth): both eye rays \
             run parallel to the visual gaze, meeting at infinity"
                .to_owned(),
        );
        let anchor = if track.is_empty() {
            Quat::IDENTITY
        } else {
            unyaw(track.at(t0))
        };
        let eye_order = sorted_by_time(&self.eyes.times_ns);
        let mut blink_spans: Vec<(i64, i64)> = (0..self.blinks.len())
            .map(|i| {
                let r = self.blinks.record(i);
                (r[0] as i64, r[1] as i64)
            })
            .collect();
        blink_spans.sort_unstable();
        // Each start paired with the latest end so far, so overlapping blinks are found too.
        let mut latest_end = i64::MIN;
        for span in &mut blink_spans {
            latest_end = latest_end.max(span.1);
            span.1 = latest_end;
        }

        let mut samples: Vec<TraceSample> = Vec::with_capacity(self.gaze.len());
        let (mut dropped, mut in_blinks, mut no_eye_state, mut pupils_out) = (0, 0, 0, 0);
        for i in 0..self.gaze.len() {
            let t = self.gaze.times_ns[i];
            let time_ns = t - t0;
            if let Some(last) = samples.last() {
                if time_ns <= last.time_ns {
                    dropped += 1;
                    continue;
                }
                let (file, record) = self.gaze.locate(i);
                check_span(file, record, time_ns, last.time_ns, 0)?;
            }
            let blink = in_blink(&blink_spans, t);
            in_blinks += usize::from(blink);
            let px = self.gaze.record(i);
            let direction = self
                .camera
                .direction(px[0], px[1])
                .map(|d| neon_to_openxr(d.as_vec3()))
                .filter(|_| !blink);
            let eye = nearest(&eye_order, &self.eyes.times_ns, t).map(|k| self.eyes.record(k));
            no_eye_state += usize::from(eye.is_none());
            let mut rays = [GazeRay::INVALID; 2];
            let mut pupils = [None; 2];
            if let Some(e) = eye.filter(|_| !blink) {
                for side in 0..2 {
                    let v = &e[4 * side..4 * side + 4];
                    let centre = DVec3::new(v[0], v[1], v[2]).as_vec3();
                    if let Some(d) = direction {
                        rays[side] = clean_ray(GazeRay {
                            origin: neon_to_openxr(centre) / 1000.0,
                            direction: d,
                            valid: true,
                        });
                    }
                    let pupil_m = (v[3] / 1000.0) as f32;
                    if PUPIL_RANGE_M.contains(&pupil_m) {
                        pupils[side] = Some(pupil_m);
                    } else if pupil_m.is_finite() {
                        pupils_out += 1;
                    }
                }
            }
            let combined = direction.map_or(GazeRay::INVALID, |d| {
                clean_ray(GazeRay {
                    origin: Vec3::ZERO,
                    direction: d,
                    valid: true,
                })
            });
            samples.push(TraceSample {
                time_ns,
                head: Pose {
                    position: Vec3::ZERO,
                    orientation: (anchor * track.at(t)).normalize(),
                },
                gaze: GazeSample {
                    sample_time_ns: time_ns,
                    left: rays[0],
                    right: rays[1],
                    combined: Some(combined),
                    fixation: None,
                    pupil_diameter_m: pupils,
                    report: None,
                },
            });
        }
        if no_eye_state > 0 {
            notes.push(format!(
                "{no_eye_state} gaze samples have no eye-state record within 25 ms: their eyes \
                 are written as invalid"
            ));
        }
        let head_origin = centre_on_eyes(&mut samples);
        if head_origin.is_none() {
            notes.push(
                "no sample has both eyes valid: the head frame's origin stays at the scene camera"
                    .to_owned(),
            );
        }
        let mut report = RecordingReport::from_samples(FORMAT, self.name, &samples);
        report.head_origin_m = head_origin;
        report.records = self.gaze.len();
        report.dropped_records = dropped;
        report.blink_samples = in_blinks;
        report.pupils_out_of_range = pupils_out;
        report.head = head;
        report.approximations = notes;
        Ok((samples, report))
    }
}

/// Indices of `times` in increasing time order.
fn sorted_by_time(times: &[i64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..times.len()).collect();
    order.sort_by_key(|&i| times[i]);
    order
}

/// The index of the time in `times` (visited in `order`) nearest `t`, if within
/// [`EYE_STATE_MAX_GAP_NS`].
fn nearest(order: &[usize], times: &[i64], t: i64) -> Option<usize> {
    let k = order.partition_point(|&i| times[i] <= t);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter_map(|j| order.get(j).copied())
        .min_by_key(|&i| (times[i] - t).unsigned_abs())
        .filter(|&i| (times[i] - t).unsigned_abs() <= EYE_STATE_MAX_GAP_NS as u64)
}

/// Whether `t` lies inside a blink; `spans` pairs each blink start (sorted) with the latest
/// end of the blinks up to it.
fn in_blink(spans: &[(i64, i64)], t: i64) -> bool {
    let k = spans.partition_point(|&(start, _)| start <= t);
    k > 0 && t <= spans[k - 1].1
}
