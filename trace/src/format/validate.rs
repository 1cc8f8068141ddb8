//! The checks every sample passes, in the reader and the writer alike: finite head pose,
//! unit quaternion, time order and the replay time limits; and the canonical gaze ray.

use glam::Quat;

use super::{
    COLUMNS, COLUMNS_V1_1, MAX_SAMPLE_GAP_NS, MAX_TRACE_SPAN_NS, MIN_DIRECTION_LENGTH,
    PUPIL_RANGE_M, PUPILS, QUAT_NORM_TOLERANCE, TraceError, TraceSample, UNIT_EPSILON,
};
use crate::frame::GazeRay;

/// What the checks of a sample need to know of the samples before it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Preceding {
    /// The first sample's time.
    first_ns: i64,
    /// The previous sample's time.
    time_ns: i64,
    /// The previous sample's gaze time.
    gaze_time_ns: i64,
}

impl Preceding {
    /// The previous sample's time.
    pub(super) fn time_ns(self) -> i64 {
        self.time_ns
    }

    /// What follows a sample accepted after `before`.
    pub(super) fn after(before: Option<Preceding>, sample: &TraceSample) -> Preceding {
        Preceding {
            first_ns: before.map_or(sample.time_ns, |b| b.first_ns),
            time_ns: sample.time_ns,
            gaze_time_ns: sample.gaze.sample_time_ns,
        }
    }
}

/// Nanoseconds from `from` to `to`, seconds (no overflow: computed in 128 bits).
fn span_s(from: i64, to: i64) -> f64 {
    (i128::from(to) - i128::from(from)) as f64 * 1e-9
}

/// Checks the replay time limits: the gap to the previous sample and the span from the first
/// are at most [`MAX_SAMPLE_GAP_NS`] and [`MAX_TRACE_SPAN_NS`]. `time_ns` is after both.
pub(crate) fn check_span(
    file: &str,
    line: usize,
    time_ns: i64,
    previous_ns: i64,
    first_ns: i64,
) -> Result<(), TraceError> {
    if i128::from(time_ns) - i128::from(previous_ns) > i128::from(MAX_SAMPLE_GAP_NS) {
        return Err(TraceError::GapTooLong {
            file: file.to_owned(),
            line,
            time_ns,
            previous_ns,
            gap_s: span_s(previous_ns, time_ns),
        });
    }
    if i128::from(time_ns) - i128::from(first_ns) > i128::from(MAX_TRACE_SPAN_NS) {
        return Err(TraceError::SpanTooLong {
            file: file.to_owned(),
            line,
            time_ns,
            first_ns,
            span_s: span_s(first_ns, time_ns),
        });
    }
    Ok(())
}

/// Checks a head pose and its times, and the pupil diameters (finite, within
/// [`PUPIL_RANGE_M`]); normalises small quaternion drift. Shared by the reader
/// and the writer so that what one accepts the other does too.
pub(super) fn check_sample(
    file: &str,
    line: usize,
    sample: &TraceSample,
    previous: Option<Preceding>,
) -> Result<TraceSample, TraceError> {
    let p = sample.head.position;
    let q = sample.head.orientation;
    let values = [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
    for (i, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            return Err(TraceError::NonFinite {
                file: file.to_owned(),
                line,
                column: COLUMNS[1 + i],
                value,
            });
        }
    }
    for (eye, pupil) in sample.gaze.pupil_diameter_m.iter().enumerate() {
        let Some(value) = *pupil else { continue };
        let column = COLUMNS_V1_1[PUPILS + eye];
        if !value.is_finite() {
            return Err(TraceError::NonFinite {
                file: file.to_owned(),
                line,
                column,
                value,
            });
        }
        if !PUPIL_RANGE_M.contains(&value) {
            return Err(TraceError::PupilOutOfRange {
                file: file.to_owned(),
                line,
                column,
                value,
            });
        }
    }
    let norm = q.length();
    if !norm.is_finite() || (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
        return Err(TraceError::NonUnitQuaternion {
            file: file.to_owned(),
            line,
            norm,
        });
    }
    let gaze_time_ns = sample.gaze.sample_time_ns;
    if let Some(before) = previous {
        if sample.time_ns <= before.time_ns {
            return Err(TraceError::TimeNotIncreasing {
                file: file.to_owned(),
                line,
                time_ns: sample.time_ns,
                previous_ns: before.time_ns,
            });
        }
        check_span(file, line, sample.time_ns, before.time_ns, before.first_ns)?;
        if gaze_time_ns < before.gaze_time_ns {
            return Err(TraceError::GazeTimeBackwards {
                file: file.to_owned(),
                line,
                gaze_time_ns,
                previous_ns: before.gaze_time_ns,
            });
        }
    }
    if gaze_time_ns > sample.time_ns {
        return Err(TraceError::GazeAfterPose {
            file: file.to_owned(),
            line,
            gaze_time_ns,
            time_ns: sample.time_ns,
        });
    }
    let mut out = *sample;
    out.head.orientation = unit_quat(q);
    out.gaze.left = clean_ray(sample.gaze.left);
    out.gaze.right = clean_ray(sample.gaze.right);
    out.gaze.combined = sample.gaze.combined.map(clean_ray);
    out.gaze.fixation = sample.gaze.fixation.filter(|f| f.is_finite());
    Ok(out)
}

/// Normalises a quaternion unless it already is unit to f32 precision (keeps round trips exact).
pub(super) fn unit_quat(q: Quat) -> Quat {
    if (q.length_squared() - 1.0).abs() <= UNIT_EPSILON {
        q
    } else {
        q.normalize()
    }
}

/// The canonical form of a gaze ray: invalid rays (flagged, non-finite, zero direction) become
/// [`GazeRay::INVALID`]; valid directions are unit length.
pub fn clean_ray(ray: GazeRay) -> GazeRay {
    if !ray.valid || !ray.origin.is_finite() || !ray.direction.is_finite() {
        return GazeRay::INVALID;
    }
    // Scaled by the largest component first so huge finite values do not overflow.
    let largest = ray.direction.abs().max_element();
    if largest < MIN_DIRECTION_LENGTH {
        return GazeRay::INVALID;
    }
    let direction = if (ray.direction.length_squared() - 1.0).abs() <= UNIT_EPSILON {
        ray.direction
    } else {
        (ray.direction / largest).normalize()
    };
    GazeRay {
        origin: ray.origin,
        direction,
        valid: true,
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::super::test_traces::*;
    use super::super::*;
    use crate::frame::GazeRay;

    #[test]
    fn non_finite_head_pose_is_refused() {
        for (col, v) in [(1, "NaN"), (3, "inf"), (7, "-inf")] {
            let text = with_field(&good_text(3), 4, col, v);
            let e = read_str(&text).unwrap_err();
            assert!(matches!(e, TraceError::NonFinite { line: 4, .. }), "{e}");
            assert_eq!(line_of(&e), Some(4));
        }
    }

    #[test]
    fn non_unit_quaternion_is_refused_and_drift_normalised() {
        let text = with_field(&good_text(2), 3, 7, "2");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::NonUnitQuaternion { line: 3, .. }),
            "{e}"
        );
        // (0,0,0,1.0004): small drift, normalised.
        let text = with_field(&with_field(&good_text(2), 3, 5, "0"), 3, 7, "1.0004");
        let samples = read_str(&text).unwrap();
        assert!(
            samples[0]
                .head
                .orientation
                .abs_diff_eq(Quat::IDENTITY, 1e-6)
        );
    }

    #[test]
    fn times_must_increase() {
        let text = with_field(&good_text(3), 5, 0, "2000");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::TimeNotIncreasing {
                    line: 5,
                    time_ns: 2000,
                    ..
                }
            ),
            "{e}"
        );
        let text = with_field(&good_text(3), 4, 8, "2001");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::GazeAfterPose { line: 4, .. }),
            "{e}"
        );
        let text = with_field(&good_text(3), 4, 8, "900");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::GazeTimeBackwards { line: 4, .. }),
            "{e}"
        );
        // Equal gaze times are fine: a faster head tracker repeats the gaze sample.
        let text = with_field(&good_text(3), 4, 8, "995");
        assert!(read_str(&text).is_ok());
    }

    #[test]
    fn traces_that_would_replay_for_ages_are_refused() {
        // A gap of years before the last sample.
        let years_ns = 3 * 365 * 86_400 * 1_000_000_000i64;
        let text = with_field(&good_text(3), 5, 0, &years_ns.to_string());
        let e = read_str(&text).unwrap_err();
        assert!(matches!(e, TraceError::GapTooLong { line: 5, .. }), "{e}");
        assert!(e.to_string().contains("test.trace:5"), "{e}");
        // A span overflowing 64-bit nanoseconds.
        let text = with_field(
            &with_field(&good_text(2), 3, 0, &i64::MIN.to_string()),
            3,
            8,
            &i64::MIN.to_string(),
        );
        let text = with_field(&text, 4, 0, &i64::MAX.to_string());
        let e = read_str(&text).unwrap_err();
        assert!(matches!(e, TraceError::GapTooLong { line: 4, .. }), "{e}");
        // Many gaps under the limit adding up to more than the longest trace.
        let step = MAX_SAMPLE_GAP_NS;
        let count = MAX_TRACE_SPAN_NS / step + 2;
        let samples: Vec<_> = (0..count).map(|i| sample(i * step + 10)).collect();
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        for s in &samples[..samples.len() - 1] {
            w.write(s).unwrap();
        }
        let e = w.write(&samples[samples.len() - 1]).unwrap_err();
        assert!(matches!(e, TraceError::SpanTooLong { .. }), "{e}");
        let mut text = String::from_utf8(w.finish().unwrap()).unwrap();
        let last = samples[samples.len() - 1];
        let last_line = to_text(&[last]).lines().nth(2).unwrap().to_owned();
        text.push_str(&last_line);
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::SpanTooLong { line, .. } if line == samples.len() + 2),
            "{e}"
        );
        assert!(
            e.to_string().contains("the longest trace is 86400 s"),
            "{e}"
        );
        // Exactly at the limits is fine.
        let at_limit = [sample(0), sample(MAX_SAMPLE_GAP_NS)];
        assert_eq!(read_str(&to_text(&at_limit)).unwrap().len(), 2);
    }

    #[test]
    fn bad_gaze_values_make_the_eye_invalid() {
        let text = with_field(&good_text(2), 3, LEFT + 4, "NaN");
        let s = read_str(&text).unwrap();
        assert_eq!(s[0].gaze.left, GazeRay::INVALID);
        assert!(s[0].gaze.right.valid);
        let zero = with_field(
            &with_field(
                &with_field(&good_text(2), 3, RIGHT + 4, "0"),
                3,
                RIGHT + 5,
                "0",
            ),
            3,
            RIGHT + 6,
            "0",
        );
        let s = read_str(&zero).unwrap();
        assert_eq!(s[0].gaze.right, GazeRay::INVALID);
        assert!(s[0].gaze.left.valid);
    }

    #[test]
    fn huge_finite_directions_are_normalised_not_invalid() {
        let text = with_field(&good_text(1), 3, LEFT + 6, "-3e38");
        let s = read_str(&text).unwrap();
        assert!(s[0].gaze.left.valid);
        assert!(s[0].gaze.left.direction.abs_diff_eq(Vec3::NEG_Z, 1e-6));
    }

    #[test]
    fn pupil_diameters_must_be_finite_plausible_numbers() {
        let text = with_field(&good_text(2), 3, PUPILS, "0.0041");
        let s = read_str(&text).unwrap();
        assert_eq!(s[0].gaze.pupil_diameter_m, [Some(0.0041), None]);
        let cases = [
            (PUPILS, "4.1", "left_pupil_m", "outside 1-10 mm"),
            (PUPILS + 1, "0", "right_pupil_m", "outside 1-10 mm"),
            (PUPILS + 1, "NaN", "right_pupil_m", "finite"),
            (PUPILS, "4mm", "left_pupil_m", "decimal"),
        ];
        for (col, value, column, says) in cases {
            let text = with_field(&good_text(2), 4, col, value);
            let e = read_str(&text).unwrap_err();
            assert_eq!(line_of(&e), Some(4), "{e}");
            let message = e.to_string();
            assert!(
                message.contains("test.trace:4") && message.contains(column),
                "{message}"
            );
            assert!(message.contains(says), "{message}");
        }
        let mut bad = sample(10);
        bad.gaze.pupil_diameter_m = [Some(0.02), None];
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        assert!(matches!(
            w.write(&bad),
            Err(TraceError::PupilOutOfRange { .. })
        ));
    }

    #[test]
    fn directions_are_normalised_on_read() {
        let text = with_field(&good_text(1), 3, LEFT + 6, "-10");
        let s = read_str(&text).unwrap();
        assert!((s[0].gaze.left.direction.length() - 1.0).abs() < 1e-6);
    }
}
