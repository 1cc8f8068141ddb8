//! The trace's eye data as a function of time, and the clock that maps runtime time onto it.
//!
//! Trace time starts at the first sample's `time_ns`, which is put at the predicted display
//! time of the session's first `xrWaitFrame` ([`TimeBase`]). Between two eye-tracker samples
//! (by their own `gaze_time_ns`) the data is interpolated: ray origins, fixation points and
//! pupil diameters linearly, ray directions by normalised linear interpolation; whether a ray
//! is valid, and anything only one of the two samples has (the tracker's report too), comes
//! from the nearer sample. Before the first sample the first is used, after the last the last,
//! each with its own time; or, looped (`VITREOUS_SIM_TRACE_LOOP=1`), the trace plays again from
//! its first sample one sample interval after its last (the mean interval between samples),
//! every time and stamp of a later pass a whole number of passes later, so a tracker replaying
//! it never stalls and its stamps keep going forward. The gaze behaviour at a time is that of
//! the nearer sample's episode ([`crate::behaviour`]), so a blink is answered exactly while the
//! eye rays are invalid.

use glam::Vec3;
use vitreous_trace::format::TraceSample;
use vitreous_trace::{GazeRay, GazeSample};

use crate::behaviour::{Behaviour, Episode, classify};

/// Maps runtime time (`XrTime`, ns) to trace time and back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimeBase {
    /// Runtime time of trace time `trace_start_ns`: the predicted display time of the
    /// session's first frame.
    pub first_display_ns: i64,
    /// The first trace sample's `time_ns`.
    pub trace_start_ns: i64,
}

impl TimeBase {
    /// The trace time of runtime time `runtime_ns`.
    pub fn to_trace(&self, runtime_ns: i64) -> i64 {
        self.trace_start_ns
            .saturating_add(runtime_ns.saturating_sub(self.first_display_ns))
    }

    /// The runtime time of trace time `trace_ns`.
    pub fn to_runtime(&self, trace_ns: i64) -> i64 {
        self.first_display_ns
            .saturating_add(trace_ns.saturating_sub(self.trace_start_ns))
    }
}

/// The eye-tracker samples of a trace, one per distinct `gaze_time_ns`, in time order.
#[derive(Clone, Debug)]
pub struct GazeTimeline {
    /// The samples; never empty.
    samples: Vec<GazeSample>,
    /// The gaze behaviour of each sample.
    episodes: Vec<Episode>,
    /// The first trace line's `time_ns`: trace time zero of the time base.
    start_ns: i64,
    /// One pass of a looped trace, nanoseconds (its samples' span and one mean interval);
    /// `None` when the last sample holds after the end.
    pass_ns: Option<i64>,
}

impl GazeTimeline {
    /// Takes the eye-tracker samples of a trace (a trace repeats a sample on every line until
    /// the tracker gives a new one; the repeats are dropped). `None` for an empty trace.
    pub fn new(trace: &[TraceSample]) -> Option<GazeTimeline> {
        let start_ns = trace.first()?.time_ns;
        let mut samples: Vec<GazeSample> = Vec::with_capacity(trace.len());
        for s in trace {
            match samples.last() {
                Some(last) if last.sample_time_ns >= s.gaze.sample_time_ns => {}
                _ => samples.push(s.gaze),
            }
        }
        let episodes = classify(&samples);
        Some(GazeTimeline {
            samples,
            episodes,
            start_ns,
            pass_ns: None,
        })
    }

    /// The timeline played over and over (a single sample simply holds).
    pub fn looped(mut self) -> GazeTimeline {
        let n = self.samples.len() as i64;
        let span =
            self.samples[self.samples.len() - 1].sample_time_ns - self.samples[0].sample_time_ns;
        self.pass_ns = (n >= 2 && span > 0).then(|| span + span / (n - 1));
        self
    }

    /// Trace time `t_ns` within the first pass, and how far later the pass it falls in is.
    fn in_pass(&self, t_ns: i64) -> (i64, i64) {
        match self.pass_ns {
            Some(pass) if t_ns > self.samples[0].sample_time_ns => {
                let shift = (t_ns - self.samples[0].sample_time_ns) / pass * pass;
                (t_ns - shift, shift)
            }
            _ => (t_ns, 0),
        }
    }

    /// The first trace line's `time_ns`.
    pub fn start_ns(&self) -> i64 {
        self.start_ns
    }

    /// The number of distinct eye-tracker samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: a timeline has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The eye data at trace time `t_ns` (see the module doc); its `sample_time_ns` is `t_ns`
    /// between samples, else the time of the sample used.
    pub fn at(&self, t_ns: i64) -> GazeSample {
        let (t_ns, shift) = self.in_pass(t_ns);
        let mut s = self.at_once(t_ns);
        s.sample_time_ns += shift;
        s
    }

    /// [`GazeTimeline::at`] of one pass: the first sample before it, the last after it.
    fn at_once(&self, t_ns: i64) -> GazeSample {
        let first = &self.samples[0];
        let last = &self.samples[self.samples.len() - 1];
        if t_ns <= first.sample_time_ns {
            return *first;
        }
        if t_ns >= last.sample_time_ns {
            return *last;
        }
        // The first sample later than t: 1..len-1 by the checks above.
        let i = self.samples.partition_point(|s| s.sample_time_ns <= t_ns);
        let (a, b) = (&self.samples[i - 1], &self.samples[i]);
        let w = (t_ns - a.sample_time_ns) as f64 / (b.sample_time_ns - a.sample_time_ns) as f64;
        interpolate(a, b, w as f32, t_ns)
    }

    /// The gaze behaviour at trace time `t_ns`: the nearer sample's (the first before the
    /// trace, the last after it), its onset on the trace clock.
    pub fn behaviour_at(&self, t_ns: i64) -> Behaviour {
        let (t_ns, shift) = self.in_pass(t_ns);
        let mut b = self.behaviour_once(t_ns);
        b.onset_ns += shift;
        b
    }

    /// [`GazeTimeline::behaviour_at`] of one pass.
    fn behaviour_once(&self, t_ns: i64) -> Behaviour {
        // The first sample later than t, 0..=len.
        let i = self.samples.partition_point(|s| s.sample_time_ns <= t_ns);
        let nearer = match i {
            0 => 0,
            i if i == self.samples.len() => i - 1,
            i => {
                let (a, b) = (&self.samples[i - 1], &self.samples[i]);
                // Weighed as `at` weighs them: b from half-way on.
                let w =
                    (t_ns - a.sample_time_ns) as f64 / (b.sample_time_ns - a.sample_time_ns) as f64;
                if w as f32 >= 0.5 { i } else { i - 1 }
            }
        };
        self.episodes[nearer].at(t_ns)
    }
}

/// `a` to `b` at weight `w` in [0, 1], stamped with `time_ns`.
fn interpolate(a: &GazeSample, b: &GazeSample, w: f32, time_ns: i64) -> GazeSample {
    let b_nearer = w >= 0.5;
    let lerp_opt = |x: Option<Vec3>, y: Option<Vec3>| match (x, y) {
        (Some(x), Some(y)) => Some(x.lerp(y, w)),
        _ => nearer(b_nearer, x, y),
    };
    let lerp_f = |x: Option<f32>, y: Option<f32>| match (x, y) {
        (Some(x), Some(y)) => Some(x + (y - x) * w),
        _ => nearer(b_nearer, x, y),
    };
    let combined = match (a.combined, b.combined) {
        (Some(x), Some(y)) => Some(lerp_ray(&x, &y, w)),
        (x, y) => nearer(b_nearer, x, y),
    };
    GazeSample {
        sample_time_ns: time_ns,
        left: lerp_ray(&a.left, &b.left, w),
        right: lerp_ray(&a.right, &b.right, w),
        combined,
        fixation: lerp_opt(a.fixation, b.fixation),
        pupil_diameter_m: [
            lerp_f(a.pupil_diameter_m[0], b.pupil_diameter_m[0]),
            lerp_f(a.pupil_diameter_m[1], b.pupil_diameter_m[1]),
        ],
        report: nearer(b_nearer, a.report, b.report),
    }
}

/// `y` when `b_nearer`, else `x`.
fn nearer<T>(b_nearer: bool, x: T, y: T) -> T {
    if b_nearer { y } else { x }
}

/// One ray from `a` to `b` at weight `w`: interpolated when both are valid, else the nearer
/// one as it is.
fn lerp_ray(a: &GazeRay, b: &GazeRay, w: f32) -> GazeRay {
    let nearer = if w >= 0.5 { b } else { a };
    if !(a.valid && b.valid) {
        return if nearer.valid {
            *nearer
        } else {
            GazeRay::INVALID
        };
    }
    GazeRay {
        origin: a.origin.lerp(b.origin, w),
        direction: a
            .direction
            .lerp(b.direction, w)
            .normalize_or(nearer.direction),
        valid: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_trace::Pose;

    fn ray(x: f32, dir: Vec3) -> GazeRay {
        GazeRay {
            origin: Vec3::new(x, 0.0, 0.0),
            direction: dir.normalize(),
            valid: true,
        }
    }

    fn line(time_ns: i64, gaze_ns: i64, left: GazeRay, pupil: Option<f32>) -> TraceSample {
        TraceSample {
            time_ns,
            head: Pose::IDENTITY,
            gaze: GazeSample {
                sample_time_ns: gaze_ns,
                left,
                right: ray(0.03, Vec3::NEG_Z),
                combined: None,
                fixation: None,
                pupil_diameter_m: [pupil, None],
                report: None,
            },
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn a_looped_trace_plays_again_one_interval_after_its_end() {
        // Samples at 0, 10, 20 ns: one pass is 20 + 10 ns.
        let lines = [
            line(0, 0, ray(0.0, Vec3::NEG_Z), None),
            line(10, 10, ray(1.0, Vec3::NEG_Z), None),
            line(20, 20, ray(2.0, Vec3::NEG_Z), None),
        ];
        let held = GazeTimeline::new(&lines).unwrap();
        let looped = GazeTimeline::new(&lines).unwrap().looped();
        // The first pass as without the loop; held after the end without it.
        for t in [-5, 0, 5, 15, 20] {
            assert_eq!(looped.at(t), held.at(t), "{t}");
        }
        assert_eq!(held.at(65).sample_time_ns, 20);
        assert!(close(held.at(65).left.origin, Vec3::new(2.0, 0.0, 0.0)));
        // Between the last sample and the next pass the last holds, its stamp its own.
        assert_eq!(looped.at(25).sample_time_ns, 20);
        // Two passes later (60 ns) the data of 5 ns, stamped at 65 ns.
        let s = looped.at(65);
        assert_eq!(s.sample_time_ns, 65);
        assert!(close(s.left.origin, Vec3::new(0.5, 0.0, 0.0)));
        // Stamps never go back across a pass.
        let stamps: Vec<i64> = (0..200).map(|t| looped.at(t).sample_time_ns).collect();
        assert!(stamps.windows(2).all(|w| w[1] >= w[0]), "{stamps:?}");
        assert_eq!(
            looped.behaviour_at(65).onset_ns,
            held.behaviour_at(5).onset_ns + 60
        );
        // A single sample holds, looped or not.
        let one = GazeTimeline::new(&lines[..1]).unwrap().looped();
        assert_eq!(one.at(1000).sample_time_ns, 0);
    }

    #[test]
    fn repeated_tracker_samples_are_dropped() {
        let t = GazeTimeline::new(&[
            line(0, 0, ray(0.0, Vec3::NEG_Z), None),
            line(10, 0, ray(0.0, Vec3::NEG_Z), None),
            line(20, 20, ray(1.0, Vec3::NEG_Z), None),
        ])
        .unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.start_ns(), 0);
        assert!(GazeTimeline::new(&[]).is_none());
    }

    #[test]
    fn interpolation_matches_hand_computed_values() {
        // Left origin x from -0.03 to 0.01 and direction from -z to +x over 100 ns;
        // pupil 3 mm to 5 mm.
        let t = GazeTimeline::new(&[
            line(1000, 1000, ray(-0.03, Vec3::NEG_Z), Some(0.003)),
            line(1100, 1100, ray(0.01, Vec3::X), Some(0.005)),
        ])
        .unwrap();
        let s = t.at(1025);
        assert_eq!(s.sample_time_ns, 1025);
        // origin: -0.03 + 0.25 * 0.04 = -0.02
        assert!(close(s.left.origin, Vec3::new(-0.02, 0.0, 0.0)));
        // direction: normalise(0.75 * (0,0,-1) + 0.25 * (1,0,0)) = (0.25, 0, -0.75) / 0.790569
        assert!(close(
            s.left.direction,
            Vec3::new(0.316_227_76, 0.0, -0.948_683_3)
        ));
        // pupil: 0.003 + 0.25 * 0.002 = 0.0035
        assert!((s.pupil_diameter_m[0].unwrap() - 0.0035).abs() < 1e-9);
        assert_eq!(s.pupil_diameter_m[1], None);
        let s = t.at(1050);
        assert!(close(
            s.left.direction,
            Vec3::new(
                std::f32::consts::FRAC_1_SQRT_2,
                0.0,
                -std::f32::consts::FRAC_1_SQRT_2
            )
        ));
    }

    #[test]
    fn outside_the_trace_the_end_samples_hold_with_their_own_times() {
        let t = GazeTimeline::new(&[
            line(1000, 990, ray(-0.03, Vec3::NEG_Z), None),
            line(1100, 1100, ray(0.01, Vec3::NEG_Z), None),
        ])
        .unwrap();
        let s = t.at(0);
        assert_eq!((s.sample_time_ns, s.left.origin.x), (990, -0.03));
        let s = t.at(5000);
        assert_eq!((s.sample_time_ns, s.left.origin.x), (1100, 0.01));
    }

    #[test]
    fn validity_comes_from_the_nearer_sample() {
        let t = GazeTimeline::new(&[
            line(0, 0, ray(-0.03, Vec3::NEG_Z), Some(0.004)),
            line(100, 100, GazeRay::INVALID, None),
        ])
        .unwrap();
        let s = t.at(40);
        assert!(s.left.valid);
        assert_eq!(s.left.origin.x, -0.03, "the valid ray is used as is");
        assert_eq!(s.pupil_diameter_m[0], Some(0.004));
        let s = t.at(60);
        assert!(!s.left.valid);
        assert_eq!(s.pupil_diameter_m[0], None);
    }

    #[test]
    fn time_base_maps_the_first_frame_to_the_trace_start() {
        let base = TimeBase {
            first_display_ns: 5_000_000,
            trace_start_ns: 1000,
        };
        assert_eq!(base.to_trace(5_000_000), 1000);
        assert_eq!(base.to_trace(5_000_500), 1500);
        assert_eq!(base.to_runtime(1500), 5_000_500);
        assert_eq!(base.to_runtime(base.to_trace(123_456_789)), 123_456_789);
    }

    #[test]
    fn behaviour_and_report_come_from_the_nearer_sample() {
        use vitreous_trace::{GazeBehaviour, TrackerConfidence, TrackerReport};
        // Steady gaze, then the eyes lost from 200 ns to 400 ns.
        let mut lines = vec![
            line(0, 0, ray(-0.03, Vec3::NEG_Z), None),
            line(100, 100, ray(-0.03, Vec3::NEG_Z), None),
            line(200, 200, GazeRay::INVALID, None),
            line(300, 300, GazeRay::INVALID, None),
            line(400, 400, ray(-0.03, Vec3::NEG_Z), None),
        ];
        for l in &mut lines[2..4] {
            l.gaze.right = GazeRay::INVALID;
        }
        let report = TrackerReport {
            confidence: TrackerConfidence::Low,
            behaviour: GazeBehaviour::Saccade,
        };
        lines[4].gaze.report = Some(report);
        let t = GazeTimeline::new(&lines).unwrap();
        assert_eq!(t.behaviour_at(149).behaviour, GazeBehaviour::Fixation);
        let blink = t.behaviour_at(150);
        assert_eq!(blink.behaviour, GazeBehaviour::Blink);
        assert_eq!(
            (blink.onset_ns, blink.duration_ns),
            (150, 0),
            "begun at the time asked"
        );
        let blink = t.behaviour_at(320);
        assert_eq!((blink.onset_ns, blink.duration_ns), (200, 120));
        assert!(!t.at(320).left.valid && !t.at(320).right.valid);
        // The report rides with the nearer sample, and its behaviour is the answer.
        assert_eq!(t.at(349).report, None);
        assert_eq!(t.at(350).report, Some(report));
        assert_eq!(t.behaviour_at(350).behaviour, GazeBehaviour::Saccade);
        assert_eq!(t.behaviour_at(10_000).onset_ns, 400);
        assert_eq!(t.behaviour_at(-5).behaviour, GazeBehaviour::Fixation);
    }
}
