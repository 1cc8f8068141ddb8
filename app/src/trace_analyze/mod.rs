//! `vitreous trace analyze` and `vitreous trace plot`: how fast and how steadily each depth
//! filter's gaze-image decision follows the gaze on a trace. This file holds the analysis;
//! `plot.rs` draws it.
//!
//! # Figures
//! The trace is replayed through a [`GazePipeline`] per filter, one update per trace sample
//! (at the sample's `time_ns`). From the decisions:
//! - a **switch** is a change of the gaze image between surface and refracted (a stretch of
//!   `unknown` in between is bridged: surface, unknown, surface is no switch; the first
//!   decision of the trace is no switch);
//! - a **gaze change** is a moment the wearer's gaze moved to the other image. On a synthetic
//!   trace these are the ground-truth phase starts ([`Truth::Phases`]). A real trace has no
//!   truth, so changes are derived from the RAW (unfiltered) depth ([`Truth::FromRawDepth`]):
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
//!   the true image; unknown decisions count as disagreeing.

use std::fmt;
use std::path::Path;

use anyhow::{Context, Result};
use vitreous_xr::TraceSample;
use vitreous_xr::synth::GazePhase;

use crate::gaze::vergence::{FixationDepth, VergenceConfig, VergenceEstimator};
use crate::gaze::{FilterKind, GazeConfig, GazeImage, GazePipeline, GazeState, ImageDistances};
use crate::scene::{gaze_image_of_target, load_scene};

mod plot;

pub use plot::{plot, plot_trace_file};

/// Default persistence of a raw-depth crossing that counts as a gaze change, nanoseconds.
pub const DEFAULT_PERSIST_NS: i64 = 200_000_000;

/// A last gaze change this close to the end of the trace with no switch after it is left
/// out (neither missed nor timed): the trace ended before any filter could follow, nanoseconds.
pub const UNRESOLVED_NS: i64 = 1_000_000_000;

/// What to analyse with.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalyzeConfig {
    /// Distances of the two images from the head, metres.
    pub distances: ImageDistances,
    /// Vergence settings (depth cap, blink hold).
    pub vergence: VergenceConfig,
    /// Hysteresis band of the gaze-image decision (see `gaze::image`).
    pub band: f32,
    /// The filters compared, the default (eq. 15) first by convention.
    pub filters: Vec<FilterKind>,
    /// How long a raw-depth crossing must persist to count as a gaze change when there is
    /// no ground truth, nanoseconds.
    pub persist_ns: i64,
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

/// Where the gaze changes come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Truth<'a> {
    /// Ground-truth phases of a synthetic trace.
    Phases(&'a [GazePhase]),
    /// Derived from the raw depth crossing the threshold persistently (module docs).
    FromRawDepth,
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

/// Replays a trace through a pipeline, one update per sample.
pub fn replay(samples: &[TraceSample], config: GazeConfig) -> Vec<ReplayedFrame> {
    let mut pipeline = GazePipeline::new(config);
    samples
        .iter()
        .map(|s| (s.time_ns, pipeline.update(Some(&s.gaze), s.time_ns)))
        .collect()
}

/// The raw depth of each tracker sample (each sample once, held depths skipped), with the
/// sample time.
pub fn raw_depths(samples: &[TraceSample], vergence: VergenceConfig) -> Vec<(i64, Option<f32>)> {
    let mut estimator = VergenceEstimator::new(vergence);
    let mut last: Option<i64> = None;
    let mut out = Vec::new();
    for s in samples {
        let t = s.gaze.sample_time_ns;
        let depth = estimator.update(Some(&s.gaze), s.time_ns);
        if last.is_some_and(|l| t <= l) {
            continue;
        }
        last = Some(t);
        let fresh = match depth {
            FixationDepth::Known {
                depth_m,
                sample_time_ns,
            } if sample_time_ns == t => Some(depth_m),
            _ => None,
        };
        out.push((t, fresh));
    }
    out
}

/// The truth timeline of ground-truth phases of a trace whose targets are laid out as
/// [`crate::scene::synth_params_for`] does (surface, then refracted).
pub fn timeline_from_phases(phases: &[GazePhase]) -> TruthTimeline {
    let image = |p: &GazePhase| gaze_image_of_target(p.target);
    let mut changes = Vec::new();
    for w in phases.windows(2) {
        if image(&w[0]) != image(&w[1]) {
            changes.push(GazeChange {
                time_ns: w[1].start_ns,
                to: image(&w[1]),
            });
        }
    }
    TruthTimeline {
        initial: phases.first().map(|p| (p.start_ns, image(p))),
        changes,
    }
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

/// The figures of one filter on one trace.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterReport {
    /// The filter.
    pub filter: FilterKind,
    /// Switches between surface and refracted.
    pub switches: usize,
    /// Switches not matched to a gaze change.
    pub false_switches: usize,
    /// Gaze changes never followed by a switch to their image.
    pub missed: usize,
    /// Switch latency of each matched gaze change, nanoseconds.
    pub latencies_ns: Vec<i64>,
    /// Fraction of samples whose decision is the true image (0..1), when the truth is known
    /// for some sample.
    pub agreement: Option<f64>,
}

impl FilterReport {
    /// Mean switch latency, milliseconds.
    pub fn mean_latency_ms(&self) -> Option<f64> {
        (!self.latencies_ns.is_empty()).then(|| {
            self.latencies_ns.iter().map(|&l| l as f64).sum::<f64>()
                / self.latencies_ns.len() as f64
                / 1e6
        })
    }

    /// Median switch latency (lower middle for an even count), milliseconds.
    pub fn median_latency_ms(&self) -> Option<f64> {
        let mut l = self.latencies_ns.clone();
        l.sort_unstable();
        l.get(l.len().saturating_sub(1) / 2)
            .map(|&v| v as f64 / 1e6)
    }

    /// Largest switch latency, milliseconds.
    pub fn max_latency_ms(&self) -> Option<f64> {
        self.latencies_ns.iter().max().map(|&v| v as f64 / 1e6)
    }
}

/// What `vitreous trace analyze` reports.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalyzeReport {
    /// Trace samples (lines).
    pub samples: usize,
    /// Distinct tracker samples.
    pub tracker_samples: usize,
    /// Tracker samples with no depth (blinks, lost eyes).
    pub tracker_samples_without_depth: usize,
    /// First to last sample, seconds.
    pub duration_s: f64,
    /// The image distances used, metres.
    pub distances: ImageDistances,
    /// Depths at which the decision leaves the surface / the refracted image, metres.
    pub switch_depths_m: (f32, f32),
    /// Whether the gaze changes are ground truth (else derived from the raw depth).
    pub ground_truth: bool,
    /// Persistence used for derived changes, nanoseconds.
    pub persist_ns: i64,
    /// The true timeline.
    pub truth: TruthTimeline,
    /// One report per filter, in the configured order.
    pub filters: Vec<FilterReport>,
}

impl AnalyzeReport {
    /// The tracker's mean sample rate, hertz.
    pub fn tracker_rate_hz(&self) -> Option<f64> {
        (self.duration_s > 0.0 && self.tracker_samples > 1)
            .then(|| (self.tracker_samples - 1) as f64 / self.duration_s)
    }
}

/// Scores one replay against the truth.
pub fn score(frames: &[ReplayedFrame], truth: &TruthTimeline, filter: FilterKind) -> FilterReport {
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
    }
}

/// Analyses a trace with every configured filter.
pub fn analyze(samples: &[TraceSample], truth: Truth<'_>, config: &AnalyzeConfig) -> AnalyzeReport {
    let raw = raw_depths(samples, config.vergence);
    let timeline = match truth {
        Truth::Phases(phases) => timeline_from_phases(phases),
        Truth::FromRawDepth => timeline_from_raw_depth(&raw, &config.distances, config.persist_ns),
    };
    let filters = config
        .filters
        .iter()
        .map(|&f| score(&replay(samples, config.gaze_config(f)), &timeline, f))
        .collect();
    let selector = crate::gaze::ImageSelector::new(config.distances, config.band);
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
        ground_truth: matches!(truth, Truth::Phases(_)),
        persist_ns: config.persist_ns,
        truth: timeline,
        filters,
    }
}

impl fmt::Display for AnalyzeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rate = self
            .tracker_rate_hz()
            .map_or("?".to_owned(), |r| format!("{r:.1}"));
        writeln!(
            f,
            "{} trace samples over {:.2} s; {} tracker samples (~{rate} Hz), {} without depth",
            self.samples, self.duration_s, self.tracker_samples, self.tracker_samples_without_depth
        )?;
        let d = &self.distances;
        writeln!(
            f,
            "images: surface {:.3} m, refracted {:.3} m; threshold {:.3} m (leave surface beyond \
             {:.3} m, leave refracted beyond {:.3} m)",
            d.surface_m,
            d.refracted_m,
            d.threshold_m(),
            self.switch_depths_m.0,
            self.switch_depths_m.1
        )?;
        if self.ground_truth {
            writeln!(
                f,
                "gaze changes: {} (ground truth)",
                self.truth.changes.len()
            )?;
        } else {
            writeln!(
                f,
                "gaze changes: {} (no ground truth: raw depth across the threshold for >= {} ms)",
                self.truth.changes.len(),
                self.persist_ns / 1_000_000
            )?;
        }
        let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.0}"));
        writeln!(
            f,
            "{:<44} {:>8} {:>6} {:>6} {:>9} {:>9} {:>8} {:>6}",
            "filter", "switches", "false", "missed", "mean ms", "median ms", "max ms", "agree"
        )?;
        for r in &self.filters {
            writeln!(
                f,
                "{:<44} {:>8} {:>6} {:>6} {:>9} {:>9} {:>8} {:>6}",
                r.filter.to_string(),
                r.switches,
                r.false_switches,
                r.missed,
                ms(r.mean_latency_ms()),
                ms(r.median_latency_ms()),
                ms(r.max_latency_ms()),
                r.agreement
                    .map_or("-".to_owned(), |a| format!("{:.1}%", a * 100.0)),
            )?;
        }
        Ok(())
    }
}

/// `vitreous trace analyze TRACE --scene SCENE`: the image distances come from the scene
/// ([`Scene::image_distances`](crate::scene::Scene::image_distances)); gaze changes are
/// derived from the raw depth (a trace file carries no ground truth). `filters` empty means
/// the default and every alternative.
pub fn analyze_trace_file(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<AnalyzeReport> {
    let (samples, config) = load_inputs(trace, scene, filters)?;
    Ok(analyze(&samples, Truth::FromRawDepth, &config))
}

/// The trace's samples and the analysis settings for a scene (its image distances) and
/// `filters` (empty: the default and every alternative).
pub(super) fn load_inputs(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<(Vec<TraceSample>, AnalyzeConfig)> {
    let scene = load_scene(scene).context("loading the scene")?;
    // The trace's errors name its file and line.
    let samples = vitreous_xr::read_trace(trace).context("reading the trace")?;
    let mut config = AnalyzeConfig::new(scene.image_distances());
    if !filters.is_empty() {
        config.filters = filters.to_vec();
    }
    Ok((samples, config))
}
