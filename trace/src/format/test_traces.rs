//! Traces for the tests of this module: samples, their text, and that text corrupted.

use glam::{Quat, Vec3};

use super::*;
use crate::frame::{GazeBehaviour, GazeRay, TrackerConfidence, TrackerReport};

pub(super) fn ray(origin: Vec3, direction: Vec3) -> GazeRay {
    GazeRay {
        origin,
        direction: direction.normalize(),
        valid: true,
    }
}

pub(super) fn sample(time_ns: i64) -> TraceSample {
    TraceSample {
        time_ns,
        head: Pose {
            position: Vec3::new(0.1, 1.6, -0.2),
            orientation: Quat::from_rotation_y(0.3),
        },
        gaze: GazeSample::binocular(
            time_ns - 5,
            ray(Vec3::new(-0.032, 0.0, 0.01), Vec3::new(0.1, 0.0, -1.0)),
            ray(Vec3::new(0.032, 0.0, 0.01), Vec3::new(-0.1, 0.0, -1.0)),
        ),
    }
}

/// The samples as trace text: version 1.1, or 1.3 when any sample carries a report.
pub(super) fn to_text(samples: &[TraceSample]) -> String {
    let version = if samples.iter().any(|s| s.gaze.report.is_some()) {
        TraceVersion::V1_3
    } else {
        TraceVersion::V1_1
    };
    let mut w = TraceWriter::with_version(Vec::new(), "<output>", version).unwrap();
    for s in samples {
        w.write(s).unwrap();
    }
    String::from_utf8(w.finish().unwrap()).unwrap()
}

pub(super) fn read_str(text: &str) -> Result<Vec<TraceSample>, TraceError> {
    TraceReader::new(text.as_bytes(), "test.trace")?.collect()
}

/// A valid trace text with `n` samples, for corrupting one line in the tests.
pub(super) fn good_text(n: i64) -> String {
    to_text(&(1..=n).map(|i| sample(i * 1000)).collect::<Vec<_>>())
}

/// A valid version-1.3 trace text with `n` samples, each with a report (high confidence, a
/// fixation).
pub(super) fn good_text_v1_3(n: i64) -> String {
    let samples: Vec<_> = (1..=n)
        .map(|i| {
            let mut s = sample(i * 1000);
            s.gaze.report = Some(TrackerReport {
                confidence: TrackerConfidence::High,
                behaviour: GazeBehaviour::Fixation,
            });
            s
        })
        .collect();
    to_text(&samples)
}

/// Replaces field `col` of physical line `line` (1-based).
pub(super) fn with_field(text: &str, line: usize, col: usize, value: &str) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line {
                let mut f: Vec<&str> = l.split(',').collect();
                f[col] = value;
                f.join(",")
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

pub(super) fn line_of(e: &TraceError) -> Option<usize> {
    use TraceError::*;
    match e {
        BadVersionLine { line, .. }
        | UnsupportedVersion { line, .. }
        | BadColumnHeader { line, .. }
        | FieldCount { line, .. }
        | BadField { line, .. }
        | NonFinite { line, .. }
        | NonUnitQuaternion { line, .. }
        | TimeNotIncreasing { line, .. }
        | GazeAfterPose { line, .. }
        | GazeTimeBackwards { line, .. }
        | PartialGroup { line, .. }
        | PupilOutOfRange { line, .. } => Some(*line),
        _ => None,
    }
}
