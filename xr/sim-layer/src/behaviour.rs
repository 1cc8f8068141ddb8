//! The gaze behaviour the layer answers for `xrGetEyeTrackerGazeBehaviorML`, classified from
//! the trace. This is the layer's simple stand-in, so that an app sees blinks, fixations,
//! pursuits and saccades where the replayed trace has them; it is not Magic Leap's classifier,
//! and an app must not tune itself to its thresholds.
//!
//! Each eye-tracker sample of the trace gets one behaviour:
//! - **blink** when it holds no valid gaze (neither eye ray nor a combined ray is valid); the
//!   answer turns to **eyes closed** once the eyes have been lost for longer than
//!   [`EYES_CLOSED_AFTER_NS`] (500 ms), as a tracker that cannot see the future would say;
//! - otherwise by the angular velocity of the gaze direction from the sample before (or, when
//!   that one has no gaze, to the sample after): above [`SACCADE_DEG_S`] (30 deg/s) a
//!   **saccade**, from [`PURSUIT_DEG_S`] (5 deg/s) to 30 deg/s a **pursuit**, below 5 deg/s a
//!   **fixation**; **unknown** for a lone sample with gaze between two without. The direction
//!   is the trace's own combined ray when both samples have a valid one, else the mean of the
//!   eye rays valid in both (the same eyes in both, so that one eye dropping out is not a
//!   jump); none in common is no velocity. Thresholds of this kind (velocity-threshold
//!   identification) are a common first classifier; on a tracker's raw noise they see
//!   saccades in jitter that a smoothed classifier would not.
//! - A sample whose trace line carries the tracker's report (trace v1.3) keeps the report's
//!   behaviour, whatever the velocity says.
//!
//! The onset of a behaviour is the time of the first sample of the run of samples with that
//! behaviour (the time the eyes were lost, for eyes closed too); its duration, the time since.

use glam::Vec3;
use vitreous_trace::{GazeBehaviour, GazeSample};

/// Above this angular velocity of the gaze, degrees per second, a sample is a saccade.
pub const SACCADE_DEG_S: f64 = 30.0;

/// From this angular velocity of the gaze up to [`SACCADE_DEG_S`], degrees per second, a sample
/// is a smooth pursuit; below it, a fixation.
pub const PURSUIT_DEG_S: f64 = 5.0;

/// After the eyes have been lost this long, nanoseconds, a blink is answered as eyes closed.
pub const EYES_CLOSED_AFTER_NS: i64 = 500_000_000;

/// The behaviour of one trace sample and when the run of it began.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Episode {
    /// The sample's behaviour ([`GazeBehaviour::Blink`] for every sample without gaze; see
    /// [`Episode::at`] for eyes closed).
    pub behaviour: GazeBehaviour,
    /// The gaze time of the first sample of the run this sample belongs to, trace clock.
    pub onset_ns: i64,
    /// Whether the behaviour is the trace's own report rather than the stand-in's.
    pub reported: bool,
}

/// The answer for one moment: what the eyes do, since when, for how long.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Behaviour {
    /// The behaviour.
    pub behaviour: GazeBehaviour,
    /// When it began, nanoseconds (on the clock of the time asked for).
    pub onset_ns: i64,
    /// How long it has lasted at the time asked for, nanoseconds.
    pub duration_ns: i64,
}

impl Episode {
    /// The answer at `t_ns` (trace clock) for a moment that belongs to this episode: a blink of
    /// the stand-in's that has lasted longer than [`EYES_CLOSED_AFTER_NS`] is eyes closed. A
    /// moment before the episode's first sample (nearer to it than to the sample before) sees
    /// it begin at that moment.
    pub fn at(&self, t_ns: i64) -> Behaviour {
        let onset_ns = self.onset_ns.min(t_ns);
        let duration_ns = t_ns.saturating_sub(onset_ns);
        let behaviour = match self.behaviour {
            GazeBehaviour::Blink if !self.reported && duration_ns > EYES_CLOSED_AFTER_NS => {
                GazeBehaviour::EyesClosed
            }
            b => b,
        };
        Behaviour {
            behaviour,
            onset_ns,
            duration_ns,
        }
    }
}

/// The episodes of a trace's distinct eye-tracker samples (in time order), one per sample.
pub fn classify(samples: &[GazeSample]) -> Vec<Episode> {
    let mut out: Vec<Episode> = Vec::with_capacity(samples.len());
    for (i, s) in samples.iter().enumerate() {
        let (behaviour, reported) = match s.report {
            Some(r) => (r.behaviour, true),
            None => (stand_in(samples, i), false),
        };
        let onset_ns = match out.last() {
            Some(before) if before.behaviour == behaviour && before.reported == reported => {
                before.onset_ns
            }
            _ => s.sample_time_ns,
        };
        out.push(Episode {
            behaviour,
            onset_ns,
            reported,
        });
    }
    out
}

/// The stand-in's behaviour of sample `i` (see the module doc).
fn stand_in(samples: &[GazeSample], i: usize) -> GazeBehaviour {
    let s = &samples[i];
    let gaze = s.left.valid || s.right.valid || s.combined.is_some_and(|c| c.valid);
    if !gaze {
        return GazeBehaviour::Blink;
    }
    let before = i
        .checked_sub(1)
        .and_then(|j| velocity_deg_s(&samples[j], s));
    let velocity = before.or_else(|| samples.get(i + 1).and_then(|n| velocity_deg_s(s, n)));
    match velocity {
        None => GazeBehaviour::Unknown,
        Some(v) if v > SACCADE_DEG_S => GazeBehaviour::Saccade,
        Some(v) if v >= PURSUIT_DEG_S => GazeBehaviour::Pursuit,
        Some(_) => GazeBehaviour::Fixation,
    }
}

/// The angular velocity of the gaze from `a` to `b` (b later), degrees per second, when both
/// have a gaze direction in common (see the module doc).
pub fn velocity_deg_s(a: &GazeSample, b: &GazeSample) -> Option<f64> {
    let dt_ns = b.sample_time_ns.checked_sub(a.sample_time_ns)?;
    if dt_ns <= 0 {
        return None;
    }
    let (da, db) = common_directions(a, b)?;
    // atan2 of sine and cosine: exact for the small angles between consecutive samples, where
    // acos of the dot product loses most of its digits.
    let angle_rad = f64::from(da.cross(db).length()).atan2(f64::from(da.dot(db)));
    Some(angle_rad.to_degrees() / (dt_ns as f64 * 1e-9))
}

/// The gaze directions of `a` and `b` from the same source: both combined rays when both are
/// valid, else the mean of the eyes valid in both.
fn common_directions(a: &GazeSample, b: &GazeSample) -> Option<(Vec3, Vec3)> {
    if let (Some(ca), Some(cb)) = (a.combined, b.combined)
        && ca.valid
        && cb.valid
    {
        return Some((ca.direction, cb.direction));
    }
    let eyes = [(a.left, b.left), (a.right, b.right)];
    let (mut da, mut db) = (Vec3::ZERO, Vec3::ZERO);
    for (ea, eb) in eyes {
        if ea.valid && eb.valid {
            da += ea.direction;
            db += eb.direction;
        }
    }
    Some((da.try_normalize()?, db.try_normalize()?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_trace::{GazeRay, TrackerConfidence, TrackerReport};

    /// Both eyes looking `yaw_deg` to the right of straight ahead at `time_ms`; no gaze when
    /// `yaw_deg` is `None`.
    fn looking(time_ms: i64, yaw_deg: Option<f32>) -> GazeSample {
        let ray = |x: f32| match yaw_deg {
            Some(yaw) => GazeRay {
                origin: Vec3::new(x, 0.0, 0.0),
                direction: glam::Quat::from_rotation_y(-yaw.to_radians()) * Vec3::NEG_Z,
                valid: true,
            },
            None => GazeRay::INVALID,
        };
        GazeSample {
            left: ray(-0.032),
            right: ray(0.032),
            ..GazeSample::none(time_ms * 1_000_000)
        }
    }

    fn behaviours(samples: &[GazeSample]) -> Vec<GazeBehaviour> {
        classify(samples).iter().map(|e| e.behaviour).collect()
    }

    #[test]
    fn velocity_thresholds_split_fixation_pursuit_and_saccade() {
        use GazeBehaviour::*;
        // 100 ms apart: 0.2 deg is 2 deg/s, 1 deg 10 deg/s, 5 deg 50 deg/s.
        let samples = [
            looking(0, Some(0.0)),
            looking(100, Some(0.2)),
            looking(200, Some(1.2)),
            looking(300, Some(6.2)),
            looking(400, Some(6.2)),
        ];
        assert_eq!(
            behaviours(&samples),
            [Fixation, Fixation, Pursuit, Saccade, Fixation]
        );
        let v = velocity_deg_s(&samples[2], &samples[3]).unwrap();
        assert!((v - 50.0).abs() < 0.01, "{v}");
        // Just either side of the thresholds (32 and 28 deg/s; 6 and 4 deg/s).
        for (step_deg, expected) in [
            (3.2, Saccade),
            (2.8, Pursuit),
            (0.6, Pursuit),
            (0.4, Fixation),
        ] {
            let s = [looking(0, Some(0.0)), looking(100, Some(step_deg))];
            assert_eq!(behaviours(&s)[1], expected, "{step_deg} deg in 100 ms");
        }
    }

    #[test]
    fn lost_eyes_are_a_blink_then_eyes_closed_after_half_a_second() {
        use GazeBehaviour::*;
        let mut samples = vec![looking(0, Some(0.0))];
        samples.extend((1..=8).map(|k| looking(k * 100, None)));
        samples.push(looking(900, Some(0.0)));
        samples.push(looking(1000, Some(0.1)));
        let episodes = classify(&samples);
        assert_eq!(episodes[1].behaviour, Blink);
        assert!(episodes[1..9].iter().all(|e| e.onset_ns == 100_000_000));
        let at = |i: usize, t_ms: i64| episodes[i].at(t_ms * 1_000_000);
        assert_eq!(at(3, 300).behaviour, Blink);
        assert_eq!(
            at(6, 600).behaviour,
            Blink,
            "500 ms exactly is still a blink"
        );
        let closed = at(7, 700);
        assert_eq!(closed.behaviour, EyesClosed);
        assert_eq!(
            (closed.onset_ns, closed.duration_ns),
            (100_000_000, 600_000_000)
        );
        // The first sample after the eyes come back measures against the next one.
        assert_eq!(episodes[9].behaviour, Fixation);
        assert_eq!(episodes[9].onset_ns, 900_000_000);
        // A lone sample with gaze between two without has no velocity.
        let lone = [looking(0, None), looking(10, Some(0.0)), looking(20, None)];
        assert_eq!(behaviours(&lone), [Blink, Unknown, Blink]);
    }

    #[test]
    fn one_eye_dropping_out_is_not_a_jump() {
        // Converging eyes: each eye's ray is several degrees off the mean of both.
        let mut a = looking(0, Some(0.0));
        a.left.direction = Vec3::new(0.06, 0.0, -1.0).normalize();
        a.right.direction = Vec3::new(-0.06, 0.0, -1.0).normalize();
        let mut b = a;
        b.sample_time_ns = 10_000_000;
        b.right = GazeRay::INVALID;
        assert_eq!(velocity_deg_s(&a, &b), Some(0.0));
        assert_eq!(behaviours(&[a, b])[1], GazeBehaviour::Fixation);
    }

    #[test]
    fn a_reported_behaviour_wins_and_runs_onset_where_it_began() {
        use GazeBehaviour::*;
        let report = |behaviour| {
            Some(TrackerReport {
                confidence: TrackerConfidence::Medium,
                behaviour,
            })
        };
        let mut samples: Vec<_> = (0..4).map(|k| looking(k * 100, Some(0.0))).collect();
        samples[1].report = report(Saccade);
        samples[2].report = report(Saccade);
        samples[3] = looking(300, None);
        samples[3].report = report(Blink);
        let episodes = classify(&samples);
        assert_eq!(
            episodes.iter().map(|e| e.behaviour).collect::<Vec<_>>(),
            [Fixation, Saccade, Saccade, Blink]
        );
        assert_eq!(episodes[2].onset_ns, 100_000_000);
        // The trace's own blink is answered as it is, however long it lasts.
        assert_eq!(episodes[3].at(5_000_000_000).behaviour, Blink);
    }
}
