//! Import of Tobii Pro Glasses 3 recordings: `gazedata.gz` (gzip-compressed JSON lines) and,
//! when it is there, `imudata.gz` beside it.
//!
//! Each gaze line is `{"type":"gaze","timestamp":S,"data":{...}}` with `timestamp` in seconds
//! since the recording started and `data` holding `gaze2d` (scene-image fraction, not read),
//! `gaze3d` (the binocular gaze point, mm) and per eye (`eyeleft`, `eyeright`) `gazeorigin`
//! (mm), `gazedirection` (unit vector) and `pupildiameter` (mm). `data` is `{}` while the
//! glasses lose both eyes, and either eye may be missing on its own. Lines of another `type`
//! are skipped and counted. IMU lines carry `accelerometer` (m/s²), `gyroscope` (deg/s) and,
//! on their own lines, `magnetometer` (µT, not read).
//!
//! Conversions, into the OpenXR conventions of this crate:
//! - **Frames**: Tobii's 3D data are in the scene camera's frame, origin at the camera,
//!   right-handed, **+x to the wearer's left, +y up, +z forward**, millimetres. The trace's
//!   head frame is this frame turned half a turn about y: `(x, y, z) -> (-x, y, -z)`,
//!   millimetres to metres, with its origin then moved from the scene camera to the middle of
//!   the eyes (the median midpoint of the two `gazeorigin`s over the recording).
//! - **Eyes**: an eye is valid when its `gazeorigin` and `gazedirection` are both present
//!   and make a finite ray with a non-zero direction. `gaze3d` becomes the trace's fixation
//!   point. Pupil diameters outside 1-10 mm are left out and counted.
//! - **Head**: position is not measured (the trace keeps it at the origin). The rotation is
//!   the gyroscope integrated over time (IMU axes as the gaze frame, which is how firmware
//!   1.29 and later write them), starting level as the accelerometer's gravity reading over
//!   the first half second says, and re-anchored so the first sample faces -z. Nothing
//!   corrects the integration: it drifts, typically by a few degrees a minute.
//! - **Time**: nanoseconds since the first gaze line; IMU times are on the same clock. Gaze
//!   lines whose time is not after the previous kept one are dropped and counted; the trace
//!   limits (10-minute gap, 24-hour span) fail the import.

mod json_lines;
#[cfg(test)]
mod tests;

use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::{DVec3, Quat, Vec3};
use serde::Deserialize;
use serde::de::DeserializeOwned;

use super::eye_centre::centre_on_eyes;
use super::orientation::{OrientationTrack, level_from_gravity, unyaw};
use super::{HeadSource, RecordingError, RecordingReport};
use crate::format::{PUPIL_RANGE_M, TraceSample, check_span, clean_ray};
use crate::frame::{GazeRay, GazeSample, Pose};
use json_lines::{for_each_line, open_text, text_reader};

/// The recording format, as reports name it.
pub const FORMAT: &str = "Tobii Pro Glasses 3";

/// How long after the first IMU record the accelerometer is averaged to level the head.
const LEVELLING_WINDOW_NS: i64 = 500_000_000;

/// Converts a vector of Tobii's scene-camera frame (+x left, +y up, +z forward) into the
/// OpenXR head frame (+x right, +y up, -z forward), keeping its unit.
pub fn tobii_to_openxr(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, v.y, -v.z)
}

/// Imports a Tobii Pro Glasses 3 recording: `path` is the recording folder or its
/// `gazedata.gz` (or the decompressed `gazedata`); `imudata.gz` beside it is read when there.
pub fn import_tobii_g3(
    path: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
    let path = path.as_ref();
    let (gaze_path, folder) = if path.is_dir() {
        let gaze = ["gazedata.gz", "gazedata"]
            .iter()
            .map(|n| path.join(n))
            .find(|p| p.exists())
            .unwrap_or_else(|| path.join("gazedata.gz"));
        (gaze, path.to_path_buf())
    } else {
        let folder = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        (path.to_path_buf(), folder)
    };
    let gaze_name = gaze_path.display().to_string();
    let gaze = open_text(
        &gaze_path,
        "the recording's gaze data (gazedata.gz) is needed",
    )?;
    let imu_path = ["imudata.gz", "imudata"]
        .iter()
        .map(|n| folder.join(n))
        .find(|p| p.is_file());
    match imu_path {
        Some(imu_path) => {
            let imu_name = imu_path.display().to_string();
            let mut imu = open_text(&imu_path, "the recording's IMU data")?;
            parse_tobii_g3(gaze, &gaze_name, Some((&mut imu, &imu_name)))
        }
        None => parse_tobii_g3(gaze, &gaze_name, None),
    }
}

/// Imports Tobii Pro Glasses 3 gaze data, and IMU data when given, from readers of the file
/// contents (gzip-compressed or plain); the names are used in messages.
pub fn parse_tobii_g3(
    gaze: impl BufRead,
    gaze_name: &str,
    imu: Option<(&mut dyn BufRead, &str)>,
) -> Result<(Vec<TraceSample>, RecordingReport), RecordingError> {
    let gaze = read_gaze(text_reader(gaze, gaze_name)?, gaze_name)?;
    let Some(first) = gaze.records.first() else {
        return Err(RecordingError::Empty {
            file: gaze_name.to_owned(),
            what: "`gaze`",
        });
    };
    let t0 = first.time_ns;
    let (track, head, mut approximations) = match imu {
        Some((reader, imu_name)) => {
            let imu = read_imu(text_reader(reader, imu_name)?, imu_name)?;
            head_track(&imu, imu_name)
        }
        None => (
            OrientationTrack::default(),
            HeadSource::None,
            vec![
                "no imudata.gz beside the gaze data: head orientation fixed (identity)".to_owned(),
            ],
        ),
    };
    approximations.insert(
        0,
        "head position is not recorded: the head stays at the origin".to_owned(),
    );
    let anchor = unyaw(track.at(t0));

    let mut samples: Vec<TraceSample> = Vec::with_capacity(gaze.records.len());
    let mut dropped = 0usize;
    for r in &gaze.records {
        let time_ns = r.time_ns - t0;
        if let Some(last) = samples.last() {
            if time_ns <= last.time_ns {
                dropped += 1;
                continue;
            }
            check_span(gaze_name, r.line, time_ns, last.time_ns, 0)?;
        }
        samples.push(TraceSample {
            time_ns,
            head: Pose {
                position: Vec3::ZERO,
                orientation: (anchor * track.at(r.time_ns)).normalize(),
            },
            gaze: GazeSample {
                sample_time_ns: time_ns,
                left: r.eyes[0],
                right: r.eyes[1],
                combined: None,
                fixation: r.fixation,
                pupil_diameter_m: r.pupils_m,
                report: None,
            },
        });
    }
    if dropped > 0 {
        tracing::warn!(
            "{gaze_name}: {dropped} gaze lines whose time is not after the previous one dropped"
        );
    }
    let head_origin = centre_on_eyes(&mut samples);
    if head_origin.is_none() {
        approximations.push(
            "no sample has both eyes valid: the head frame's origin stays at the scene camera"
                .to_owned(),
        );
    }
    let mut report = RecordingReport::from_samples(FORMAT, gaze_name.to_owned(), &samples);
    report.head_origin_m = head_origin;
    report.records = gaze.records.len();
    report.dropped_records = dropped;
    report.skipped_lines = gaze.skipped;
    report.pupils_out_of_range = gaze.pupils_out_of_range;
    report.head = head;
    report.approximations = approximations;
    Ok((samples, report))
}

/// One `gaze` line, converted.
struct GazeRecord {
    /// Line number (1-based).
    line: usize,
    /// Time, nanoseconds since the recording started.
    time_ns: i64,
    /// Left and right rays, head frame (invalid where the line has none).
    eyes: [GazeRay; 2],
    /// `gaze3d`, head frame, metres.
    fixation: Option<Vec3>,
    /// Pupil diameters, metres, where given and within 1-10 mm.
    pupils_m: [Option<f32>; 2],
}

/// The gaze lines of a file.
struct GazeLines {
    /// Converted `gaze` lines, in file order.
    records: Vec<GazeRecord>,
    /// Lines of another type.
    skipped: usize,
    /// Pupil diameters present but outside 1-10 mm.
    pupils_out_of_range: usize,
}

/// A line of `gazedata.gz` as JSON.
#[derive(Deserialize)]
struct GazeLine {
    /// Line type; `gaze` for gaze data.
    #[serde(rename = "type")]
    kind: Option<String>,
    /// Seconds since the recording started.
    timestamp: Option<f64>,
    /// The measurements (`{}` during loss).
    #[serde(default)]
    data: GazeData,
}

/// The `data` object of a gaze line.
#[derive(Deserialize, Default)]
struct GazeData {
    /// Binocular gaze point, scene-camera frame, mm.
    gaze3d: Option<[f64; 3]>,
    /// Left eye.
    eyeleft: Option<EyeData>,
    /// Right eye.
    eyeright: Option<EyeData>,
}

/// One eye of a gaze line.
#[derive(Deserialize)]
struct EyeData {
    /// Where the eye's ray starts, scene-camera frame, mm.
    gazeorigin: Option<[f64; 3]>,
    /// The eye's gaze direction, scene-camera frame, unit vector.
    gazedirection: Option<[f64; 3]>,
    /// Pupil diameter, mm.
    pupildiameter: Option<f64>,
}

/// A line of `imudata.gz` as JSON.
#[derive(Deserialize)]
struct ImuLine {
    /// Line type; `imu` for IMU data.
    #[serde(rename = "type")]
    kind: Option<String>,
    /// Seconds since the recording started.
    timestamp: Option<f64>,
    /// The measurements.
    #[serde(default)]
    data: ImuData,
}

/// The `data` object of an IMU line.
#[derive(Deserialize, Default)]
struct ImuData {
    /// Specific force, IMU axes (= gaze frame), m/s².
    accelerometer: Option<[f64; 3]>,
    /// Angular velocity, IMU axes, degrees per second.
    gyroscope: Option<[f64; 3]>,
}

/// The IMU lines of a file, converted to the trace head frame.
#[derive(Default)]
struct ImuRecords {
    /// Angular velocity, rad/s, by time (ns since the recording started).
    rates: Vec<(i64, Vec3)>,
    /// Specific force, m/s², by time.
    forces: Vec<(i64, Vec3)>,
}

/// Parses one JSON line, naming the file, line and column when it is malformed.
fn parse_line<T: DeserializeOwned>(
    text: &str,
    file: &str,
    line: usize,
) -> Result<T, RecordingError> {
    serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let message = message
            .rsplit_once(" at line ")
            .map_or(message.as_str(), |(m, _)| m);
        RecordingError::Json {
            file: file.to_owned(),
            line,
            message: format!("malformed JSON line: {message} (column {})", e.column()),
        }
    })
}

/// A line's `timestamp` in nanoseconds.
fn timestamp_ns(seconds: Option<f64>, file: &str, line: usize) -> Result<i64, RecordingError> {
    let bad = |found: String| RecordingError::BadValue {
        file: file.to_owned(),
        at: line.to_string(),
        field: "timestamp".to_owned(),
        found,
        expected: "seconds since the recording started (a finite number)",
    };
    let s = seconds.ok_or_else(|| bad("nothing".to_owned()))?;
    // 4e9 s (127 years) either way keeps nanoseconds, and the difference of two, in an i64.
    if !s.is_finite() || s.abs() > 4.0e9 {
        return Err(bad(s.to_string()));
    }
    Ok((s * 1e9).round() as i64)
}

/// A JSON triple as a vector; `None` when a component does not fit an `f32`.
fn vec3(v: [f64; 3]) -> Option<Vec3> {
    let v = DVec3::from_array(v).as_vec3();
    v.is_finite().then_some(v)
}

/// Reads every line of `gazedata`.
fn read_gaze(reader: impl BufRead, file: &str) -> Result<GazeLines, RecordingError> {
    let mut out = GazeLines {
        records: Vec::new(),
        skipped: 0,
        pupils_out_of_range: 0,
    };
    for_each_line(reader, file, |line, text| {
        let parsed: GazeLine = parse_line(text, file, line)?;
        if parsed.kind.as_deref() != Some("gaze") {
            out.skipped += 1;
            return Ok(());
        }
        let time_ns = timestamp_ns(parsed.timestamp, file, line)?;
        let mut eyes = [GazeRay::INVALID; 2];
        let mut pupils_m = [None; 2];
        for (i, eye) in [&parsed.data.eyeleft, &parsed.data.eyeright]
            .into_iter()
            .enumerate()
        {
            let Some(eye) = eye else { continue };
            if let (Some(o), Some(d)) = (
                eye.gazeorigin.and_then(vec3),
                eye.gazedirection.and_then(vec3),
            ) {
                eyes[i] = clean_ray(GazeRay {
                    origin: tobii_to_openxr(o) / 1000.0,
                    direction: tobii_to_openxr(d),
                    valid: true,
                });
            }
            if let Some(mm) = eye.pupildiameter {
                let m = (mm / 1000.0) as f32;
                if PUPIL_RANGE_M.contains(&m) {
                    pupils_m[i] = Some(m);
                } else {
                    out.pupils_out_of_range += 1;
                }
            }
        }
        let fixation = parsed
            .data
            .gaze3d
            .and_then(vec3)
            .map(|p| tobii_to_openxr(p) / 1000.0)
            .filter(|p| p.is_finite());
        out.records.push(GazeRecord {
            line,
            time_ns,
            eyes,
            fixation,
            pupils_m,
        });
        Ok(())
    })?;
    Ok(out)
}

/// Reads every line of `imudata`.
fn read_imu(reader: impl BufRead, file: &str) -> Result<ImuRecords, RecordingError> {
    let mut out = ImuRecords::default();
    for_each_line(reader, file, |line, text| {
        let parsed: ImuLine = parse_line(text, file, line)?;
        if parsed.kind.as_deref() != Some("imu") {
            return Ok(());
        }
        let t = timestamp_ns(parsed.timestamp, file, line)?;
        if let Some(w) = parsed.data.gyroscope.and_then(vec3) {
            out.rates.push((t, tobii_to_openxr(w).map(f32::to_radians)));
        }
        if let Some(a) = parsed.data.accelerometer.and_then(vec3) {
            out.forces.push((t, tobii_to_openxr(a)));
        }
        Ok(())
    })?;
    Ok(out)
}

/// The head orientation track from IMU records, where it comes from, and what it assumes.
fn head_track(imu: &ImuRecords, file: &str) -> (OrientationTrack, HeadSource, Vec<String>) {
    let mut notes = Vec::new();
    if imu.rates.len() < 2 {
        notes.push(format!(
            "{file} holds fewer than two gyroscope records: head orientation fixed (identity)"
        ));
        return (OrientationTrack::default(), HeadSource::None, notes);
    }
    let start = imu.rates[0].0;
    let early: Vec<Vec3> = imu
        .forces
        .iter()
        .filter(|(t, _)| (start..start + LEVELLING_WINDOW_NS).contains(t))
        .map(|&(_, a)| a)
        .collect();
    let mean = early.iter().copied().sum::<Vec3>() / early.len().max(1) as f32;
    let initial = level_from_gravity(mean).unwrap_or_else(|| {
        notes.push(
            "no steady accelerometer reading in the first 0.5 s: the head is assumed to start level"
                .to_owned(),
        );
        Quat::IDENTITY
    });
    let track = OrientationTrack::integrate_rates(initial, &imu.rates);
    notes.push(
        "head rotation is the gyroscope integrated without drift correction (a few degrees per \
         minute is typical); heading is relative to the first sample"
            .to_owned(),
    );
    let records = track.len();
    (track, HeadSource::Gyroscope { records }, notes)
}
