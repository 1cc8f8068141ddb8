//! Trace analysis (`vitreous trace analyze` and `trace plot`): how fast and how steadily each
//! depth filter's gaze-image decision follows the gaze on a trace.
//!
//! # Figures
//! The trace is replayed through a [`GazePipeline`] per filter, one update per trace sample
//! (at the sample's `time_ns`). From the decisions:
//! - a **switch** is a change of the gaze image between surface and refracted (a stretch of
//!   `unknown` in between is bridged: surface, unknown, surface is no switch; the first
//!   decision of the trace is no switch);
//! - a **gaze change** is a moment the wearer's gaze moved to the other image. On a synthetic
//!   trace these are the ground-truth phase starts (a [`TruthTimeline`] the caller makes of
//!   them). A real trace has no truth, so changes are derived from the RAW (unfiltered) depth
//!   ([`timeline_from_raw_depth`]):
//!   each tracker sample's depth is classed by the threshold between the images (the
//!   geometric mean, no hysteresis); a change is a run of samples all on the other side
//!   lasting at least `persist_ns` (first to last sample, default 200 ms), dated at the run's
//!   first sample. Samples without a depth neither extend nor break a run;
//! - the **switch latency** of a gaze change is the time from it to the first switch to its
//!   image before the next gaze change. A change with no such switch is **missed**; a change
//!   whose image was already shown (after an early false switch) has no latency and is not
//!   missed; a last change less than [`UNRESOLVED_NS`] before the end of the trace with no
//!   switch after it is left out (the trace ended first);
//! - every switch not matched to a gaze change is a **false switch**;
//! - **agree** is the fraction of samples (after the truth is first known) whose decision is
//!   the true image; unknown decisions count as disagreeing;
//! - an **episode** is a stretch of one decision: from the first decision or a switch to the
//!   next switch (unknown stretches bridged, as for switches). The last episode, cut short by
//!   the end of the trace, is not counted;
//! - a **gap** is a blink or a dropout: a run of tracker samples without a depth, or more than
//!   [`DROPOUT_NS`] between two consecutive tracker samples. It ends at the next sample with a
//!   depth. A switch during a gap or less than [`SETTLE_NS`] after it ends is counted in
//!   `switches_within_150ms_after_gap`.
//!
//! `vitreous trace analyze --json` writes the same figures as JSON ([`AnalyzeReport::to_json`]).

use glam::Vec3;
use serde::Serialize;
use vitreous_trace::TraceSample;

use crate::evidence::DEFAULT_PRIOR_NOISE_DEG;
use crate::fixation::{
    DEFAULT_VELOCITY_DEG_S, DROPOUT_NS, Step, VelocityClassifier, combined_direction,
};
use crate::vergence::{Measurement, VergenceConfig, VergenceEstimator};
use crate::{
    FilterKind, GazeConfig, GazeImage, GazePipeline, GazeState, ImageDistances, ObjectInView,
    Separability, SeparabilityMonitor,
};

mod report;

pub use report::{AnalyzeJson, AnalyzeReport, FilterJson, FilterReport};

/// Default persistence of a raw-depth crossing that counts as a gaze change, nanoseconds.
pub const DEFAULT_PERSIST_NS: i64 = 200_000_000;

/// A last gaze change this close to the end of the trace with no switch after it is left
/// out (neither missed nor timed): the trace ended before any filter could follow, nanoseconds.
pub const UNRESOLVED_NS: i64 = 1_000_000_000;

/// Episodes shorter than this, and switches this soon after a gap, are counted apart
/// (`episodes_under_150ms`, `switches_within_150ms_after_gap`), nanoseconds.
pub const SETTLE_NS: i64 = 150_000_000;

/// What to analyse with.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalyzeConfig {
    /// Distances of the two images from the head, metres.
    pub distances: ImageDistances,
    /// Vergence settings (depth cap, blink hold).
    pub vergence: VergenceConfig,
    /// Hysteresis band of the gaze-image decision (see `gaze::image`).
    pub band: f32,
    /// The filters compared, eq. 15 (the paper's, the reference) first by convention.
    pub filters: Vec<FilterKind>,
    /// How long a raw-depth crossing must persist to count as a gaze change when there is
    /// no ground truth, nanoseconds.
    pub persist_ns: i64,
    /// The glass object's bounding sphere in the world frame (centre, radius; metres), so the
    /// `evidence` decision knows, from each sample's head pose, whether the gaze meets it.
    /// `None`: every gaze direction counts.
    pub object: Option<(Vec3, f32)>,
}

impl AnalyzeConfig {
    /// The default pipeline settings and every offered filter, for given image distances.
    pub fn new(distances: ImageDistances) -> Self {
        let g = GazeConfig::new(distances);
        AnalyzeConfig {
            distances,
            vergence: g.vergence,
            band: g.band,
            filters: FilterKind::all_default(),
            persist_ns: DEFAULT_PERSIST_NS,
            object: None,
        }
    }

    /// The pipeline settings for one filter.
    pub fn gaze_config(&self, filter: FilterKind) -> GazeConfig {
        GazeConfig {
            vergence: self.vergence,
            filter,
            band: self.band,
            ..GazeConfig::new(self.distances)
        }
    }
}

/// A moment the gaze moved to an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GazeChange {
    /// When, nanoseconds on the trace clock.
    pub time_ns: i64,
    /// The image the gaze moved to.
    pub to: GazeImage,
}

/// The true gaze image over a trace: where it starts and when it changes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TruthTimeline {
    /// The first true image and from when it is known, nanoseconds.
    pub initial: Option<(i64, GazeImage)>,
    /// The gaze changes, in time order.
    pub changes: Vec<GazeChange>,
}

impl TruthTimeline {
    /// The true image at a time, if known.
    pub fn at(&self, time_ns: i64) -> Option<GazeImage> {
        let (start_ns, first) = self.initial?;
        if time_ns < start_ns {
            return None;
        }
        Some(
            self.changes
                .iter()
                .take_while(|c| c.time_ns <= time_ns)
                .last()
                .map_or(first, |c| c.to),
        )
    }
}

/// One frame of a replay: the trace time and the pipeline's state.
pub type ReplayedFrame = (i64, GazeState);

/// Replays a trace through a pipeline, one update per sample; with `object` (the glass
/// object's centre and radius, world frame) the pipeline knows where it is from each sample's
/// head pose.
pub fn replay(
    samples: &[TraceSample],
    config: GazeConfig,
    object: Option<(Vec3, f32)>,
) -> Vec<ReplayedFrame> {
    let mut pipeline = GazePipeline::new(config);
    samples
        .iter()
        .map(|s| {
            pipeline.set_object(object.and_then(|(center_m, radius_m)| {
                ObjectInView::from_head(s.head.position, s.head.orientation, center_m, radius_m)
            }));
            (s.time_ns, pipeline.update(Some(&s.gaze), s.time_ns))
        })
        .collect()
}

/// The separability of the images at `distances` for the tracker of a trace: the vergence
/// noise estimated over all its fixations, at the median eye baseline of its samples.
pub fn separability_of(
    samples: &[TraceSample],
    vergence: VergenceConfig,
    distances: &ImageDistances,
) -> Option<Separability> {
    let mut monitor = SeparabilityMonitor::new(DEFAULT_VELOCITY_DEG_S, DEFAULT_PRIOR_NOISE_DEG);
    let mut baselines = Vec::new();
    for (s, measured) in tracker_samples(samples, vergence) {
        let depth = measured.map(|m| m.depth_m);
        if let Some(r) = monitor.push(&s.gaze, depth, distances).reading {
            baselines.push(r.baseline_m);
        }
    }
    let sep = monitor.separability()?;
    baselines.sort_by(f32::total_cmp);
    let baseline_m = baselines[baselines.len() / 2];
    Some(Separability::new(
        distances,
        baseline_m,
        sep.noise_deg,
        sep.estimated,
    ))
}

/// Each tracker sample of a trace once (a sample that several trace lines repeat, or a depth
/// held through a blink, is skipped), with what it measured itself (`None`: no depth).
fn tracker_samples(
    samples: &[TraceSample],
    vergence: VergenceConfig,
) -> impl Iterator<Item = (&TraceSample, Option<Measurement>)> {
    let mut estimator = VergenceEstimator::new(vergence);
    let mut last: Option<i64> = None;
    samples.iter().filter_map(move |s| {
        let t = s.gaze.sample_time_ns;
        estimator.update(Some(&s.gaze), s.time_ns);
        if last.is_some_and(|l| t <= l) {
            return None;
        }
        last = Some(t);
        Some((s, estimator.measurement().filter(|m| m.sample_time_ns == t)))
    })
}

/// One tracker sample as the analysis sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawSample {
    /// Tracker time, nanoseconds.
    pub time_ns: i64,
    /// The depth this sample measured (`None`: blink, lost eye), metres.
    pub depth_m: Option<f32>,
    /// Whether its rays diverged (the depth is then the far cap).
    pub divergent: bool,
    /// How the I-VT classifier of the `fixation` filter saw it.
    pub step: Step,
}

/// Each tracker sample once (held depths skipped), with its depth, divergence and I-VT step
/// (classified with `velocity_deg_s`).
pub fn raw_samples(
    samples: &[TraceSample],
    vergence: VergenceConfig,
    velocity_deg_s: f32,
) -> Vec<RawSample> {
    let mut classifier = VelocityClassifier::new(velocity_deg_s);
    tracker_samples(samples, vergence)
        .map(|(s, fresh)| {
            let t = s.gaze.sample_time_ns;
            let direction = fresh.and_then(|_| combined_direction(&s.gaze));
            RawSample {
                time_ns: t,
                depth_m: fresh.map(|m| m.depth_m),
                divergent: fresh.is_some_and(|m| m.divergent),
                step: classifier.step(t, direction),
            }
        })
        .collect()
}

/// The raw depth of each tracker sample (each sample once, held depths skipped), with the
/// sample time.
pub fn raw_depths(samples: &[TraceSample], vergence: VergenceConfig) -> Vec<(i64, Option<f32>)> {
    raw_samples(samples, vergence, DEFAULT_VELOCITY_DEG_S)
        .into_iter()
        .map(|r| (r.time_ns, r.depth_m))
        .collect()
}

/// The truth timeline derived from raw depths crossing the threshold for at least
/// `persist_ns` (module docs).
pub fn timeline_from_raw_depth(
    raw: &[(i64, Option<f32>)],
    distances: &ImageDistances,
    persist_ns: i64,
) -> TruthTimeline {
    let mut timeline = TruthTimeline {
        initial: None,
        changes: Vec::new(),
    };
    let mut current: Option<GazeImage> = None;
    // The run of samples on a side other than `current`: side, first and last time.
    let mut run: Option<(GazeImage, i64, i64)> = None;
    for &(t, depth) in raw {
        let Some(depth_m) = depth else { continue };
        let side = distances.nearest(depth_m);
        if Some(side) == current {
            run = None;
            continue;
        }
        let (run_side, start, _) = match run {
            Some((s, start, _)) if s == side => (s, start, t),
            _ => (side, t, t),
        };
        run = Some((run_side, start, t));
        if t - start >= persist_ns {
            match current {
                None => timeline.initial = Some((start, side)),
                Some(_) => timeline.changes.push(GazeChange {
                    time_ns: start,
                    to: side,
                }),
            }
            current = Some(side);
            run = None;
        }
    }
    timeline
}

/// A blink or dropout: from its first sample without depth (or the last sample before a
/// dropout) to the first sample with a depth after it, nanoseconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Gap {
    /// Start, nanoseconds on the trace clock.
    pub start_ns: i64,
    /// End: the first sample with a depth after the gap, nanoseconds.
    pub end_ns: i64,
}

/// The gaps (module docs) of raw depths; a gap still open at the end of the trace is left out.
pub fn gaps(raw: &[(i64, Option<f32>)]) -> Vec<Gap> {
    let mut gaps = Vec::new();
    let mut open: Option<i64> = None;
    let mut previous: Option<i64> = None;
    for &(t, depth) in raw {
        if depth.is_none() {
            open.get_or_insert(t);
        } else {
            let dropout = previous.is_some_and(|p| t - p > DROPOUT_NS);
            match (open.take(), previous) {
                (Some(start), _) => gaps.push(Gap {
                    start_ns: start,
                    end_ns: t,
                }),
                (None, Some(p)) if dropout => gaps.push(Gap {
                    start_ns: p,
                    end_ns: t,
                }),
                _ => {}
            }
        }
        previous = Some(t);
    }
    gaps
}

/// Scores one replay against the truth and the trace's gaps.
pub fn score(
    frames: &[ReplayedFrame],
    truth: &TruthTimeline,
    gaps: &[Gap],
    filter: FilterKind,
) -> FilterReport {
    // Switch times and targets; the shown image (bridging unknown) before each frame.
    let mut switches: Vec<(i64, GazeImage)> = Vec::new();
    let mut shown: Option<GazeImage> = None;
    let (mut agree, mut judged) = (0usize, 0usize);
    for &(t, state) in frames {
        if state.image != GazeImage::Unknown {
            if shown.is_some_and(|s| s != state.image) {
                switches.push((t, state.image));
            }
            shown = Some(state.image);
        }
        if let Some(true_image) = truth.at(t) {
            judged += 1;
            agree += usize::from(state.image == true_image);
        }
    }
    let end_ns = frames.last().map_or(0, |f| f.0 + 1);
    let first_decision = frames
        .iter()
        .find(|f| f.1.image != GazeImage::Unknown)
        .map(|f| f.0);
    let episodes_ns: Vec<i64> = first_decision
        .into_iter()
        .chain(switches.iter().map(|s| s.0))
        .collect::<Vec<_>>()
        .windows(2)
        .map(|w| w[1] - w[0])
        .collect();
    let switches_after_gap = switches
        .iter()
        .filter(|&&(t, _)| {
            gaps.iter()
                .any(|g| g.start_ns <= t && t < g.end_ns + SETTLE_NS)
        })
        .count();
    let hidden = |t: i64| {
        gaps.iter()
            .any(|g| g.start_ns < t + SETTLE_NS && g.end_ns > t)
    };
    let hiding_gap = |t: i64| {
        gaps.iter()
            .find(|g| g.start_ns < t + SETTLE_NS && g.end_ns > t)
    };
    let mut hidden_latencies_from_gap_end_ns = Vec::new();
    let mut clear_latencies_ns = Vec::new();
    let mut matched = vec![false; switches.len()];
    let mut latencies_ns = Vec::new();
    let mut missed = 0;
    for (k, change) in truth.changes.iter().enumerate() {
        let until = truth.changes.get(k + 1).map_or(end_ns, |c| c.time_ns);
        let first = switches
            .iter()
            .position(|&(t, to)| t >= change.time_ns && t < until && to == change.to);
        match first {
            Some(i) => {
                matched[i] = true;
                latencies_ns.push(switches[i].0 - change.time_ns);
                if !hidden(change.time_ns) {
                    clear_latencies_ns.push(switches[i].0 - change.time_ns);
                }
                if let Some(g) = hiding_gap(change.time_ns) {
                    hidden_latencies_from_gap_end_ns.push(switches[i].0 - g.end_ns);
                }
            }
            // The trace ended before the decision could follow: not counted.
            None if k + 1 == truth.changes.len() && until - change.time_ns < UNRESOLVED_NS => {}
            None => {
                let before = switches
                    .iter()
                    .take_while(|s| s.0 < change.time_ns)
                    .last()
                    .map(|s| s.1);
                if before != Some(change.to) {
                    missed += 1;
                }
            }
        }
    }
    FilterReport {
        filter,
        switches: switches.len(),
        false_switches: matched.iter().filter(|m| !**m).count(),
        missed,
        latencies_ns,
        agreement: (judged > 0).then(|| agree as f64 / judged as f64),
        episodes_ns,
        switches_after_gap,
        clear_latencies_ns,
        hidden_latencies_from_gap_end_ns,
    }
}

/// Analyses a trace with every configured filter against `truth`, the true gaze image over
/// it: ground truth (`ground_truth`, a synthetic trace's phases) or derived from its raw depth
/// ([`timeline_from_raw_depth`]).
pub fn analyze(
    samples: &[TraceSample],
    truth: TruthTimeline,
    ground_truth: bool,
    config: &AnalyzeConfig,
) -> AnalyzeReport {
    let raw = raw_depths(samples, config.vergence);
    let gaps = gaps(&raw);
    let filters = config
        .filters
        .iter()
        .map(|&f| {
            let frames = replay(samples, config.gaze_config(f), config.object);
            score(&frames, &truth, &gaps, f)
        })
        .collect();
    let selector = crate::ImageSelector::new(config.distances, config.band);
    let duration_s = match (samples.first(), samples.last()) {
        (Some(a), Some(b)) => (b.time_ns - a.time_ns) as f64 * 1e-9,
        _ => 0.0,
    };
    AnalyzeReport {
        samples: samples.len(),
        tracker_samples: raw.len(),
        tracker_samples_without_depth: raw.iter().filter(|r| r.1.is_none()).count(),
        duration_s,
        distances: config.distances,
        switch_depths_m: selector.switch_depths_m(),
        ground_truth,
        persist_ns: config.persist_ns,
        truth,
        gaps,
        separability: separability_of(samples, config.vergence, &config.distances),
        filters,
    }
}
