//! Gaze-image decisions that follow fixations (filter name `fixation`).
//!
//! The depth filters of [`super::filter`] smooth the depth sample by sample and let the
//! hysteresis of [`super::image`] decide; on a real tracker a noisy stretch, a blink or one
//! pair of diverging rays after a blink can then flip the image for a few tens of
//! milliseconds. Here the samples are first classified, and the gaze image is decided only
//! from the samples of one fixation that has lasted long enough.
//!
//! # Classification (I-VT)
//! Each tracker sample is classified online by [`VelocityClassifier`], the velocity-threshold
//! identification of Salvucci & Goldberg ("Identifying fixations and saccades in eye-tracking
//! protocols", ETRA 2000) with the thresholds of Tobii's I-VT fixation filter (Olsen, "The
//! Tobii I-VT Fixation Filter", Tobii Technology 2012):
//! - **gap** (blink, lost eye): the sample gives no depth or no gaze direction; a stretch of
//!   more than [`DROPOUT_NS`] (75 ms, Olsen's longest gap that is filled in rather than
//!   treated as lost data) between two consecutive samples is a dropout, a gap too;
//! - **saccade**: the angular velocity of the combined gaze direction ([`combined_direction`],
//!   the bisector of the two eyes' directions) from the previous sample exceeds
//!   [`FixationParams::velocity_deg_s`] (30 deg/s, Olsen's default), and the next sample
//!   confirms the move (it is not back within the threshold of where the gaze was before:
//!   Olsen's merging of adjacent fixations, online; at 30 Hz with 0.5 degree of noise about one
//!   sample in seven exceeds 30 deg/s from noise alone);
//! - **fixation**: otherwise. A fixation starts at the first sample after a gap or a saccade.
//!
//! # Decision
//! [`FixationFilter`] keeps the samples of the current fixation. Once the fixation has lasted
//! [`FixationParams::min_fixation_ms`] (60 ms: Olsen's shortest fixation kept) and holds at
//! least [`MIN_SAMPLES`] samples within its last [`FixationParams::window_ms`] (100 ms, the
//! shortest fixation of Salvucci & Goldberg's dispersion algorithm), the median vergence of
//! those samples (in dioptres; diverging rays count as the 10 m cap, i.e. far) is the
//! fixation's depth, and goes through the hysteresis of [`ImageSelector`]. The two images of a
//! glass lie behind one another, so a change of gaze between them is often a vergence movement
//! with no saccade: within a long fixation the window slides, and the decision follows once
//! most of the last 100 ms agree.
//!
//! A vergence change inside a fixation is seen best in the stretch of samples that starts at
//! it: a 100 ms window that still holds one sample from before the change, or an even number
//! of samples split about the threshold, can keep its median on the old side while every
//! longer stretch that starts at the change is past it. So the decision also tries each longer
//! trailing stretch of the fixation, up to [`FixationParams::max_window_ms`] (150 ms: a change
//! must be followed within 150 ms, so no useful stretch starts earlier), and switches if the
//! median of any of them is past the hysteresis threshold. Stretches of at least 100 ms keep
//! the noise of each median as low as the 100 ms window's; on the synthetic traces of
//! docs/gaze.md this brought the worst switch on changes not hidden by a blink from 167 ms to
//! 133 ms with no false switch, where a shorter window (67-99 ms: three samples at 30 Hz)
//! made 18 false switches.
//!
//! The decision is held through saccades and gaps, and a new decision is taken only when
//! - at least [`FixationParams::settle_ms`] (150 ms) have passed since the last gap ended
//!   (the start of tracking counts as one), so the first samples after a blink, which are
//!   often off while the lid opens, never decide; and
//! - at least `settle_ms` have passed since the last switch (or the first decision), so no
//!   decision episode is shorter.
//!
//! When the tracker is lost for longer than the vergence hold (300 ms), the filter resets: the
//! image is unknown (no defocus) until a fixation after the gap decides again under the same
//! rules. Neither one sample nor one pair of diverging rays decides alone: a decision takes
//! the median of at least three samples spanning 60 ms.

use std::collections::VecDeque;

use glam::Vec3;
use vitreous_trace::GazeSample;

use super::image::{GazeImage, ImageDistances, ImageSelector};
use super::vergence::{FixationDepth, Measurement, newer_sample};

/// Default I-VT threshold on the combined direction's angular velocity, degrees per second.
pub const DEFAULT_VELOCITY_DEG_S: f32 = 30.0;
/// Default shortest fixation that may decide, milliseconds.
pub const DEFAULT_MIN_FIXATION_MS: f32 = 60.0;
/// Default window of the median at the end of a fixation, milliseconds.
pub const DEFAULT_WINDOW_MS: f32 = 100.0;
/// Default longest trailing stretch of a fixation whose median may switch the decision (the
/// 150 ms latency bound of docs/gaze.md), milliseconds.
pub const DEFAULT_MAX_WINDOW_MS: f32 = 150.0;
/// Default quiet time after a gap ends and after a switch, milliseconds.
pub const DEFAULT_SETTLE_MS: f32 = 150.0;
/// Longest interval between consecutive tracker samples that is not a dropout, nanoseconds.
pub const DROPOUT_NS: i64 = 75_000_000;
/// Fewest samples a decision is taken from.
pub const MIN_SAMPLES: usize = 3;

/// Parameters of the fixation-based decision (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixationParams {
    /// I-VT threshold on the angular velocity of the combined gaze direction, degrees/second.
    pub velocity_deg_s: f32,
    /// How long a fixation must have lasted before it decides, milliseconds.
    pub min_fixation_ms: f32,
    /// The fixation's depth is the median of its samples in this last stretch, milliseconds.
    pub window_ms: f32,
    /// The decision also switches when the median of a longer trailing stretch of the
    /// fixation, up to this long, is past the hysteresis threshold, milliseconds (less than
    /// `window_ms` counts as `window_ms`).
    pub max_window_ms: f32,
    /// No decision within this long after a gap ends or after a switch, milliseconds.
    pub settle_ms: f32,
}

impl Default for FixationParams {
    fn default() -> Self {
        FixationParams {
            velocity_deg_s: DEFAULT_VELOCITY_DEG_S,
            min_fixation_ms: DEFAULT_MIN_FIXATION_MS,
            window_ms: DEFAULT_WINDOW_MS,
            max_window_ms: DEFAULT_MAX_WINDOW_MS,
            settle_ms: DEFAULT_SETTLE_MS,
        }
    }
}

impl FixationParams {
    /// Milliseconds (as the parameters are given) to nanoseconds (as sample times are).
    fn ms_to_ns(ms: f32) -> i64 {
        (f64::from(ms) * 1e6).round() as i64
    }
}

/// What one tracker sample is (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SampleClass {
    /// Part of a fixation.
    Fixation,
    /// Moving faster than the velocity threshold both into and out of this sample.
    Saccade,
    /// No depth or no direction (blink, lost eye).
    Gap,
}

/// How a tracker sample relates to the ones before, as the online classifier sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Step {
    /// No depth or no gaze direction: a blink or a lost eye.
    Gap,
    /// The first sample with a direction after a gap, a dropout or the start of tracking: a
    /// fixation starts here.
    AfterGap,
    /// The gaze moved faster than the threshold into this sample: a saccade, or a noise spike;
    /// the next sample tells which.
    Moving,
    /// The move into the previous sample was a saccade: a fixation started at that sample
    /// (`start_ns`) and continues here.
    NewFixation {
        /// Time of the fixation's first sample (the previous one), nanoseconds.
        start_ns: i64,
    },
    /// Continues the current fixation (after a [`Step::Moving`] sample, the gaze came back
    /// within the threshold of where it was before it: a noise spike, merged in).
    Continues,
}

/// The combined gaze direction of a sample (head frame, unit): the bisector of the two eyes'
/// directions when both are valid, else the tracker's combined ray, else the direction of its
/// fixation point, else the one valid eye's direction.
pub fn combined_direction(g: &GazeSample) -> Option<Vec3> {
    let unit = |v: Vec3| v.try_normalize().filter(|v| v.is_finite());
    if g.left.valid && g.right.valid {
        return unit(g.left.direction + g.right.direction);
    }
    if let Some(c) = g.combined.filter(|c| c.valid) {
        return unit(c.direction);
    }
    if let Some(p) = g.fixation {
        return unit(p);
    }
    [g.left, g.right]
        .into_iter()
        .find(|r| r.valid)
        .and_then(|r| unit(r.direction))
}

/// The online I-VT classifier (module docs). A move faster than the threshold is confirmed as
/// a saccade by the next sample: if that sample is within the threshold of where the gaze was
/// before the move (the velocity from there, over both intervals, is below it), the move was a
/// noise spike and the fixation continues. This is the merging of adjacent fixations of
/// Olsen's filter, done online, and it keeps a 30 Hz tracker's noise from cutting fixations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityClassifier {
    /// Threshold, radians per second.
    threshold_rad_s: f64,
    /// Time and direction of the previous sample with a direction, since the last gap.
    previous: Option<(i64, Vec3)>,
    /// While a move is unconfirmed: the time and direction of the last sample before it.
    anchor: Option<(i64, Vec3)>,
}

impl VelocityClassifier {
    /// A classifier with threshold `velocity_deg_s`, at the start of tracking.
    pub fn new(velocity_deg_s: f32) -> Self {
        VelocityClassifier {
            threshold_rad_s: f64::from(velocity_deg_s).to_radians(),
            previous: None,
            anchor: None,
        }
    }

    /// Whether the gaze moved faster than the threshold from `(t0, d0)` to `(t1, d1)`.
    fn fast(&self, (t0, d0): (i64, Vec3), (t1, d1): (i64, Vec3)) -> bool {
        let dt_s = ((t1 - t0) as f64 * 1e-9).max(1e-6);
        let angle_rad = f64::from(d0.dot(d1).clamp(-1.0, 1.0)).acos();
        angle_rad / dt_s > self.threshold_rad_s
    }

    /// Classifies the sample at `time_ns` with combined direction `direction` (`None`: none,
    /// or no depth). Samples come once each, in time order.
    pub fn step(&mut self, time_ns: i64, direction: Option<Vec3>) -> Step {
        let Some(direction) = direction else {
            self.reset();
            return Step::Gap;
        };
        let now = (time_ns, direction);
        let step = match self.previous {
            None => Step::AfterGap,
            Some((t, _)) if time_ns - t > DROPOUT_NS => Step::AfterGap,
            // Back within the threshold of where the gaze was before the move: a spike.
            Some(_) if self.anchor.is_some_and(|a| !self.fast(a, now)) => {
                self.anchor = None;
                Step::Continues
            }
            Some(previous) if self.fast(previous, now) => {
                self.anchor.get_or_insert(previous);
                Step::Moving
            }
            Some((t, _)) => match self.anchor.take() {
                None => Step::Continues,
                Some(_) => Step::NewFixation { start_ns: t },
            },
        };
        if step == Step::AfterGap {
            self.anchor = None;
        }
        self.previous = Some(now);
        step
    }

    /// Forgets the previous samples (the tracker was lost).
    pub fn reset(&mut self) {
        self.previous = None;
        self.anchor = None;
    }
}

/// The class of each sample from the online steps of a whole trace: a [`Step::Moving`] sample
/// followed by another is part of a saccade; followed by a fixation, it is that fixation's
/// first sample (or a merged noise spike).
pub fn classes_of(steps: &[Step]) -> Vec<SampleClass> {
    steps
        .iter()
        .enumerate()
        .map(|(i, step)| match step {
            Step::Gap => SampleClass::Gap,
            Step::Moving if steps.get(i + 1) == Some(&Step::Moving) => SampleClass::Saccade,
            _ => SampleClass::Fixation,
        })
        .collect()
}

/// The fixations of a trace as (first, last) sample times, nanoseconds, from its samples'
/// times and online steps; only those lasting at least `min_ns`.
pub fn fixation_spans(times_ns: &[i64], steps: &[Step], min_ns: i64) -> Vec<(i64, i64)> {
    let mut spans = Vec::new();
    let mut current: Option<(i64, i64)> = None;
    // The last sample before an unconfirmed move: where the current fixation ends if the move
    // is a saccade.
    let mut before_move: Option<i64> = None;
    let mut previous_t: Option<i64> = None;
    for (&t, &step) in times_ns.iter().zip(steps) {
        match step {
            Step::Gap => {
                spans.extend(current.take());
                before_move = None;
            }
            Step::AfterGap => {
                spans.extend(current.take());
                current = Some((t, t));
                before_move = None;
            }
            Step::Moving => {
                if before_move.is_none() {
                    before_move = previous_t;
                }
            }
            Step::NewFixation { start_ns } => {
                if let (Some(c), Some(end)) = (current.take(), before_move.take()) {
                    spans.push((c.0, end));
                }
                current = Some((start_ns, t));
            }
            Step::Continues => {
                before_move = None;
                if let Some(c) = &mut current {
                    c.1 = t;
                }
            }
        }
        previous_t = Some(t);
    }
    spans.extend(current);
    spans.retain(|(a, b)| b - a >= min_ns);
    spans
}

/// The fixation-based gaze-image decision (module docs), fed once per frame like the depth
/// filters; each tracker sample is ingested once.
#[derive(Clone, Debug)]
pub struct FixationFilter {
    /// Parameters.
    params: FixationParams,
    /// Sample classifier.
    classifier: VelocityClassifier,
    /// Threshold and hysteresis; holds the current decision.
    selector: ImageSelector,
    /// The current fixation's samples in the longest window: time, vergence in dioptres.
    window: VecDeque<(i64, f32)>,
    /// A sample the gaze moved to fast, until the next sample says whether a fixation starts
    /// there or it was a noise spike.
    pending: Option<(i64, f32)>,
    /// Time of the current fixation's first sample.
    fixation_start_ns: Option<i64>,
    /// Sample time of the last sample ingested.
    last_sample_ns: Option<i64>,
    /// When the last gap ended (the first sample after it), nanoseconds.
    gap_end_ns: Option<i64>,
    /// When the decision last changed between surface and refracted, or was first taken,
    /// nanoseconds.
    last_switch_ns: Option<i64>,
    /// The last image decided, kept across resets (so a decision after a reset that differs
    /// from it counts as a switch).
    shown: GazeImage,
    /// The last window median, metres, with the time of its newest sample.
    output: Option<(f32, i64)>,
}

impl FixationFilter {
    /// A filter with no history choosing between images at `distances`, with hysteresis
    /// `band` (see [`ImageSelector`]).
    pub fn new(params: FixationParams, distances: ImageDistances, band: f32) -> Self {
        FixationFilter {
            params,
            classifier: VelocityClassifier::new(params.velocity_deg_s),
            selector: ImageSelector::new(distances, band),
            window: VecDeque::new(),
            pending: None,
            fixation_start_ns: None,
            last_sample_ns: None,
            gap_end_ns: None,
            last_switch_ns: None,
            shown: GazeImage::Unknown,
            output: None,
        }
    }

    /// Moves the images (the viewer moved); the decision and the fixation are kept.
    pub fn set_distances(&mut self, distances: ImageDistances) {
        self.selector.distances = distances;
    }

    /// Feeds one frame: `gaze` is the frame's newest tracker sample, `raw` the vergence
    /// estimator's (held) depth for it and `measurement` what that sample itself measured.
    /// Returns the depth the decision rests on (the window median) and the gaze image.
    pub fn update(
        &mut self,
        gaze: Option<&GazeSample>,
        raw: &FixationDepth,
        measurement: Option<Measurement>,
    ) -> (FixationDepth, GazeImage) {
        if *raw == FixationDepth::Unknown {
            self.reset();
        } else if let Some(g) = newer_sample(gaze, &mut self.last_sample_ns) {
            let t = g.sample_time_ns;
            let measured = measurement.filter(|m| m.sample_time_ns == t);
            let direction = measured.and_then(|_| combined_direction(g));
            self.ingest(t, direction, measured);
        }
        let depth = match self.output {
            Some((depth_m, sample_time_ns)) => FixationDepth::Known {
                depth_m,
                sample_time_ns,
            },
            None => FixationDepth::Unknown,
        };
        (depth, self.selector.current())
    }

    /// One new tracker sample.
    fn ingest(&mut self, t: i64, direction: Option<Vec3>, measured: Option<Measurement>) {
        let step = self.classifier.step(t, direction);
        let Some(m) = measured.filter(|_| step != Step::Gap) else {
            self.window.clear();
            self.pending = None;
            self.fixation_start_ns = None;
            return;
        };
        let sample = (t, 1.0 / m.depth_m.max(1e-3));
        match step {
            Step::Gap => {}
            Step::Moving => {
                // Not part of the current fixation until the next sample says so; no decision.
                self.pending = Some(sample);
                return;
            }
            Step::AfterGap => {
                self.gap_end_ns = Some(t);
                self.window.clear();
                self.fixation_start_ns = Some(t);
            }
            Step::NewFixation { start_ns } => {
                self.window.clear();
                self.window.extend(self.pending.take());
                self.fixation_start_ns = Some(start_ns);
            }
            Step::Continues => {
                self.window.extend(self.pending.take());
                self.fixation_start_ns.get_or_insert(t);
            }
        }
        self.window.push_back(sample);
        let window_ns =
            FixationParams::ms_to_ns(self.params.window_ms.max(self.params.max_window_ms));
        while self.window.front().is_some_and(|&(w, _)| t - w > window_ns) {
            self.window.pop_front();
        }
        self.decide(t);
    }

    /// Decides from the current fixation's window if the rules allow (module docs).
    fn decide(&mut self, t: i64) {
        let Some(start) = self.fixation_start_ns else {
            return;
        };
        let window_ns = FixationParams::ms_to_ns(self.params.window_ms);
        // Index of the first sample of the last `window_ms`.
        let short = self
            .window
            .iter()
            .position(|&(w, _)| t - w <= window_ns)
            .unwrap_or(0);
        if t - start < FixationParams::ms_to_ns(self.params.min_fixation_ms)
            || self.window.len() - short < MIN_SAMPLES
        {
            return;
        }
        let depth_m = self.median_depth_m(short);
        self.output = Some((depth_m, t));
        let settle_ns = FixationParams::ms_to_ns(self.params.settle_ms);
        let settled = |since: Option<i64>| since.is_none_or(|s| t - s >= settle_ns);
        if !settled(self.gap_end_ns) {
            return;
        }
        // The window first, then each longer trailing stretch (module docs): the first whose
        // median changes the decision.
        let Some((candidate, image)) = (0..=short).rev().find_map(|from| {
            let mut candidate = self.selector;
            let image = candidate.update(Some(self.median_depth_m(from)));
            (image != self.selector.current()).then_some((candidate, image))
        }) else {
            return;
        };
        let switch = self.shown != GazeImage::Unknown && image != self.shown;
        if switch && !settled(self.last_switch_ns) {
            return;
        }
        if switch || self.shown == GazeImage::Unknown {
            self.last_switch_ns = Some(t);
        }
        self.selector = candidate;
        self.shown = image;
    }

    /// The median vergence of the fixation's samples from index `from` on, as a depth in
    /// metres.
    fn median_depth_m(&self, from: usize) -> f32 {
        let mut dioptres: Vec<f32> = self.window.iter().skip(from).map(|w| w.1).collect();
        dioptres.sort_by(f32::total_cmp);
        let n = dioptres.len();
        let median = if n % 2 == 1 {
            dioptres[n / 2]
        } else {
            (dioptres[n / 2 - 1] + dioptres[n / 2]) / 2.0
        };
        1.0 / median.max(1e-6)
    }

    /// Forgets the tracking state after the tracker was lost for longer than the hold time:
    /// the image is unknown until a fixation decides again; the last image shown and the time
    /// of the last switch are kept.
    pub fn reset(&mut self) {
        self.classifier.reset();
        self.selector.reset();
        self.window.clear();
        self.pending = None;
        self.fixation_start_ns = None;
        self.last_sample_ns = None;
        self.output = None;
    }
}

#[cfg(test)]
mod tests;
