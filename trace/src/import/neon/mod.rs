//! Import of Pupil Labs Neon native recordings (the folder the Companion app writes).
//!
//! Streams read (`NAME psN.raw` with `NAME psN.time`, layouts in `NAME.dtype`; see `raw.rs`):
//!
//! | stream | fields read | use |
//! |---|---|---|
//! | `gaze psN` | `x`, `y` (float32, scene-image pixels) | the visual gaze direction |
//! | `eye_state psN` | `eyeball_center_{left,right}_{x,y,z}` (mm), `pupil_diameter_{left,right}_mm` | eye ray origins, pupils |
//! | `eye_state psN`, without a gaze stream | also `optical_axis_{left,right}_{x,y,z}` (unit vectors) | each eye's gaze direction |
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
//!   That is the *visual* gaze. The eye-state optical axes are not used when there is a gaze
//!   stream: the optical axis is about 5 degrees from the visual axis, by an angle Neon does
//!   not measure per wearer.
//! - **Depth is not measured**: Neon gives one gaze point, not a binocular one. Each eye's
//!   ray starts at its eyeball centre and runs parallel to the visual gaze direction, so the
//!   two rays meet at infinity; the combined ray is the visual gaze from the scene camera.
//! - **Without a gaze stream** (or with [`GazeSource::EyeState`]), the samples are the
//!   eye-state records instead: each eye's ray runs from its eyeball centre along its optical
//!   axis turned toward the nose by the angle kappa ([`kappa`]; 5 degrees unless
//!   [`NeonOptions::kappa_deg`] says otherwise). The two rays then verge at a depth, but an
//!   unreliable one: kappa is a population mean, not the wearer's, and a degree in either
//!   eye moves a 2 m depth by metres. There is no combined ray.
//! - **Validity**: an eye is invalid inside a marked blink, when the gaze point is not finite
//!   or not invertible, or when no eye-state record lies within 25 ms of the gaze sample
//!   (eye-state gaze: when its optical axis or eyeball centre is not finite; a finite axis
//!   that is not a unit vector fails the import). Pupil diameters outside 1-10 mm are left out
//!   and counted.
//! - **Head**: position is not recorded (kept at the origin). The rotation is the IMU's own
//!   orientation (IMU frame: +x right, +y forward, +z up; world: +z up, +y magnetic north)
//!   turned into the scene camera frame (fixed 102-degree turn about x between the two, the
//!   module's mounting), then into OpenXR axes, re-anchored so the first sample faces -z.
//! - **Time**: nanoseconds since the first sample (gaze, or eye state without a gaze stream;
//!   the `.time` files hold Unix-epoch nanoseconds). Samples whose time is not after the
//!   previous kept one are dropped and counted; the trace limits (10-minute gap, 24-hour
//!   span) fail the import.

pub mod camera;
mod eye_state_gaze;
mod gaze_stream;
pub mod kappa;
mod raw;
#[cfg(test)]
mod tests;

use std::path::Path;

use glam::{DVec3, Quat, Vec3};

use super::eye_centre::centre_on_eyes;
use super::orientation::{OrientationTrack, unyaw};
use super::{HeadSource, RecordingError, RecordingReport};
use crate::format::{PUPIL_RANGE_M, TraceSample, check_span, clean_ray};
use crate::frame::{GazeRay, Pose};
pub use camera::SceneCamera;
use eye_state_gaze::EYE_AXIS_FIELDS;
pub use kappa::DEFAULT_KAPPA_DEG;
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

/// Where a Neon import takes the gaze from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GazeSource {
    /// The gaze stream, or the eye states' optical axes when the recording has no gaze
    /// stream.
    #[default]
    Auto,
    /// The eye states' optical axes, turned by kappa, even when there is a gaze stream.
    EyeState,
}

/// What a Neon import may choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeonOptions {
    /// Where the gaze comes from.
    pub gaze: GazeSource,
    /// Horizontal angle kappa between each eye's optical and visual axes, degrees, positive
    /// nasal (see [`kappa`]); used only when the gaze comes from the eye states.
    pub kappa_deg: f64,
}

impl Default for NeonOptions {
    fn default() -> Self {
        NeonOptions {
            gaze: GazeSource::Auto,
            kappa_deg: DEFAULT_KAPPA_DEG,
        }
    }
}

/// Imports the Neon native recording in `folder` with the default options.
pub fn import_neon(
    folder: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
    import_neon_with(folder, &NeonOptions::default())
}

/// Imports the Neon native recording in `folder`.
pub fn import_neon_with(
    folder: impl AsRef<Path>,
    options: &NeonOptions,
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
        SceneCamera::NOMINAL
    };
    let missing = |base: &str, why: &'static str| RecordingError::Missing {
        file: folder.join(format!("{base} ps1.raw")).display().to_string(),
        why,
    };
    let gaze = match options.gaze {
        GazeSource::Auto => read_stream(folder, "gaze", GAZE_LAYOUT, GAZE_LAYOUT)?,
        GazeSource::EyeState => None,
    };
    let eyes = match &gaze {
        Some(_) => {
            read_stream(folder, "eye_state", EYE_FIELDS, EYE_STATE_LAYOUT)?.ok_or_else(|| {
                missing(
                    "eye_state",
                    "the eye-state stream (eyeball centres, pupils) is needed",
                )
            })?
        }
        None => {
            let why = match options.gaze {
                GazeSource::Auto => "the recording has no gaze stream",
                GazeSource::EyeState => "the eye-state gaze was asked for",
            };
            read_stream(folder, "eye_state", EYE_AXIS_FIELDS, EYE_STATE_LAYOUT)
                .map_err(|e| match e {
                    RecordingError::Dtype { file, message } => RecordingError::Dtype {
                        file,
                        message: format!(
                            "{message} (the gaze is taken from the eye states' optical axes: \
                             {why})"
                        ),
                    },
                    e => e,
                })?
                .ok_or_else(|| {
                    missing(
                        "gaze",
                        "the gaze stream is needed, or, without it, the eye-state stream \
                         (`eye_state ps1.raw`, whose optical axes give the gaze)",
                    )
                })?
        }
    };
    if gaze.is_some() && !calibration.is_file() {
        notes.push(
            "no calibration.bin: the nominal scene camera (891 px focal length, no lens \
             distortion) turns gaze pixels into directions, off by degrees near the image edges"
                .to_owned(),
        );
    }
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
    inputs.convert(notes, options.kappa_deg)
}

/// Everything read from a recording folder.
struct Inputs {
    /// The folder, for messages and the report.
    name: String,
    /// The scene camera model.
    camera: SceneCamera,
    /// Gaze: x, y pixels; `None` when the gaze comes from the eye states.
    gaze: Option<Stream>,
    /// Eye state: [`EYE_FIELDS`], or [`EYE_AXIS_FIELDS`] without a gaze stream.
    eyes: Stream,
    /// Blinks: start, end (ns); possibly empty.
    blinks: Stream,
    /// IMU: w, x, y, z; `None` without an IMU stream.
    imu: Option<Stream>,
}

/// The head track and blinks of a recording, on the clock of the stream that times the
/// samples.
struct Timeline {
    /// The first sample's time, Unix nanoseconds: trace time 0.
    t0: i64,
    /// The head orientations (identity throughout without an IMU).
    track: OrientationTrack,
    /// The turn that makes the first sample face -z.
    anchor: Quat,
    /// Blink starts (sorted), each with the latest end of the blinks up to it.
    blinks: Vec<(i64, i64)>,
}

impl Timeline {
    /// The head pose at `t` (Unix nanoseconds).
    fn head(&self, t: i64) -> Pose {
        Pose {
            position: Vec3::ZERO,
            orientation: (self.anchor * self.track.at(t)).normalize(),
        }
    }

    /// Whether `t` lies inside a marked blink.
    fn in_blink(&self, t: i64) -> bool {
        in_blink(&self.blinks, t)
    }
}

/// What a conversion counted, for the report.
#[derive(Default)]
struct Counts {
    /// Records dropped: time not after the last kept sample's.
    dropped: usize,
    /// Samples inside a marked blink.
    in_blinks: usize,
    /// Pupil diameters outside [`PUPIL_RANGE_M`].
    pupils_out: usize,
    /// Gaze samples without an eye-state record near them (gaze stream only).
    no_eye_state: usize,
    /// Eyes whose optical axis is not finite (eye-state gaze only).
    no_axis: usize,
}

impl Inputs {
    /// Builds the trace; `kappa_deg` turns the optical axes when the gaze comes from the eye
    /// states.
    fn convert(
        self,
        mut notes: Vec<String>,
        kappa_deg: f64,
    ) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
        let (clock, what) = match &self.gaze {
            Some(gaze) => (gaze, "gaze"),
            None => (&self.eyes, "eye-state"),
        };
        let Some(&t0) = clock.times_ns.first() else {
            return Err(RecordingError::Empty {
                file: clock.locate(0).0.to_owned(),
                what,
            });
        };
        let records = clock.len();
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
        let anchor = if track.is_empty() {
            Quat::IDENTITY
        } else {
            unyaw(track.at(t0))
        };
        let mut blinks: Vec<(i64, i64)> = (0..self.blinks.len())
            .map(|i| {
                let r = self.blinks.record(i);
                (r[0] as i64, r[1] as i64)
            })
            .collect();
        blinks.sort_unstable();
        // Each start paired with the latest end so far, so overlapping blinks are found too.
        let mut latest_end = i64::MIN;
        for span in &mut blinks {
            latest_end = latest_end.max(span.1);
            span.1 = latest_end;
        }
        let timeline = Timeline {
            t0,
            track,
            anchor,
            blinks,
        };

        let mut counts = Counts::default();
        let mut samples = match &self.gaze {
            Some(gaze) => {
                notes.push(
                    "fixation depth is not measured (one gaze point, no binocular depth): both \
                     eye rays run parallel to the visual gaze, meeting at infinity"
                        .to_owned(),
                );
                self.samples_from_gaze(gaze, &timeline, &mut counts)?
            }
            None => {
                let kappa_from = if kappa_deg == DEFAULT_KAPPA_DEG {
                    "the default, a population mean for adults, not this wearer's"
                } else {
                    "as given, not measured for this wearer"
                };
                notes.push(format!(
                    "the gaze comes from the eye states' optical axes (no gaze stream is \
                     used), each turned {kappa_deg:.1} degrees toward the nose for angle kappa \
                     ({kappa_from}; Neon does not calibrate kappa)"
                ));
                notes.push(
                    "fixation depth from the vergence of these two rays is unreliable: with no \
                     per-wearer kappa each eye may be off by degrees, and for eyes 64 mm apart \
                     one degree in either eye moves a 2 m vergence depth to 1.3 m or 4.4 m \
                     (0.5 m to 0.44 m or 0.58 m)"
                        .to_owned(),
                );
                self.samples_from_eye_states(&timeline, kappa_deg.to_radians(), &mut counts)?
            }
        };
        if counts.no_eye_state > 0 {
            notes.push(format!(
                "{} gaze samples have no eye-state record within 25 ms: their eyes are written \
                 as invalid",
                counts.no_eye_state
            ));
        }
        if counts.no_axis > 0 {
            notes.push(format!(
                "{} eyes have no optical axis (not finite) in their eye-state record: those \
                 eyes are written as invalid",
                counts.no_axis
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
        report.records = records;
        report.dropped_records = counts.dropped;
        report.blink_samples = counts.in_blinks;
        report.pupils_out_of_range = counts.pupils_out;
        report.head = head;
        report.approximations = notes;
        Ok((samples, report))
    }
}

/// The trace time of record `i` of `stream` (timing the samples from `t0`), or `None`,
/// counted as dropped, when it is not after the `last` sample's; a gap past the trace limits
/// fails the import.
fn sample_time(
    stream: &Stream,
    i: usize,
    t0: i64,
    last: Option<&TraceSample>,
    counts: &mut Counts,
) -> Result<Option<i64>, RecordingError> {
    let time_ns = stream.times_ns[i] - t0;
    if let Some(last) = last {
        if time_ns <= last.time_ns {
            counts.dropped += 1;
            return Ok(None);
        }
        let (file, record) = stream.locate(i);
        check_span(file, record, time_ns, last.time_ns, 0)?;
    }
    Ok(Some(time_ns))
}

/// The ray of an eye from its eye-state values `v` (eyeball centre x, y, z in mm, then the
/// pupil) along `direction` (OpenXR head frame); invalid when either is not finite.
fn eye_ray(v: &[f64], direction: Vec3) -> GazeRay {
    let centre = DVec3::new(v[0], v[1], v[2]).as_vec3();
    clean_ray(GazeRay {
        origin: neon_to_openxr(centre) / 1000.0,
        direction,
        valid: true,
    })
}

/// A pupil diameter in metres from `mm`, `None` when unknown or outside [`PUPIL_RANGE_M`]
/// (counted in `out`).
fn pupil_m(mm: f64, out: &mut usize) -> Option<f32> {
    let pupil_m = (mm / 1000.0) as f32;
    if PUPIL_RANGE_M.contains(&pupil_m) {
        Some(pupil_m)
    } else {
        *out += usize::from(pupil_m.is_finite());
        None
    }
}

/// Whether `t` lies inside a blink; `spans` pairs each blink start (sorted) with the latest
/// end of the blinks up to it.
fn in_blink(spans: &[(i64, i64)], t: i64) -> bool {
    let k = spans.partition_point(|&(start, _)| start <= t);
    k > 0 && t <= spans[k - 1].1
}
