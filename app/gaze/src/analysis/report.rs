//! What `vitreous trace analyze` reports: the figures per filter and per trace
//! ([`FilterReport`], [`AnalyzeReport`]), as the text table and as `--json`
//! ([`FilterJson`], [`AnalyzeJson`]). The definitions are in the parent module's docs.

use std::fmt;

use serde::Serialize;

use super::{Gap, SETTLE_NS, TruthTimeline};
use crate::separability::SEPARABLE;
use crate::{FilterKind, ImageDistances, Separability};

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
    /// Length of each complete decision episode (module docs), nanoseconds.
    pub episodes_ns: Vec<i64>,
    /// Switches during a gap or less than [`SETTLE_NS`] after it ended.
    pub switches_after_gap: usize,
    /// Switch latency of each matched gaze change with no gap in the [`SETTLE_NS`] after it,
    /// nanoseconds (a change hidden by a blink cannot be seen before the blink ends).
    pub clear_latencies_ns: Vec<i64>,
    /// For each matched gaze change that a gap hides (a gap in the [`SETTLE_NS`] after it),
    /// the time from the end of that gap to the switch, nanoseconds.
    pub hidden_latencies_from_gap_end_ns: Vec<i64>,
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

    /// Shortest complete decision episode, milliseconds.
    pub fn min_episode_ms(&self) -> Option<f64> {
        self.episodes_ns.iter().min().map(|&v| v as f64 / 1e6)
    }

    /// Complete decision episodes shorter than [`SETTLE_NS`].
    pub fn episodes_under_settle(&self) -> usize {
        self.episodes_ns.iter().filter(|&&e| e < SETTLE_NS).count()
    }

    /// The figures as `trace analyze --json` writes them.
    pub fn to_json(&self) -> FilterJson {
        let ms = |v: &[i64]| -> (Option<f64>, Option<f64>) {
            let mean = (!v.is_empty())
                .then(|| v.iter().map(|&l| l as f64).sum::<f64>() / v.len() as f64 / 1e6);
            (mean, v.iter().max().map(|&m| m as f64 / 1e6))
        };
        let (mean_ms, max_ms) = ms(&self.latencies_ns);
        let (clear_mean_ms, clear_max_ms) = ms(&self.clear_latencies_ns);
        let (hidden_mean_ms_from_gap_end, hidden_max_ms_from_gap_end) =
            ms(&self.hidden_latencies_from_gap_end_ns);
        FilterJson {
            filter: self.filter.to_string(),
            default: self.filter == FilterKind::default(),
            switches: self.switches,
            false_switches: self.false_switches,
            missed: self.missed,
            mean_ms,
            median_ms: self.median_latency_ms(),
            max_ms,
            clear_mean_ms,
            clear_max_ms,
            hidden_mean_ms_from_gap_end,
            hidden_max_ms_from_gap_end,
            agree: self.agreement,
            episodes: self.episodes_ns.len(),
            min_episode_ms: self.min_episode_ms(),
            episodes_under_150ms: self.episodes_under_settle(),
            switches_within_150ms_after_gap: self.switches_after_gap,
        }
    }
}

/// One filter's figures in `trace analyze --json` (see the module docs for the definitions).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FilterJson {
    /// The filter's name.
    pub filter: String,
    /// Whether it is the default decision (a scene without `[gaze] filter`).
    pub default: bool,
    /// Switches between surface and refracted.
    pub switches: usize,
    /// Switches matched to no gaze change.
    #[serde(rename = "false")]
    pub false_switches: usize,
    /// Gaze changes never followed.
    pub missed: usize,
    /// Mean switch latency, milliseconds (`null`: no matched change).
    pub mean_ms: Option<f64>,
    /// Median switch latency, milliseconds.
    pub median_ms: Option<f64>,
    /// Largest switch latency, milliseconds.
    pub max_ms: Option<f64>,
    /// Mean latency over the changes with no gap in the 150 ms after them, milliseconds.
    pub clear_mean_ms: Option<f64>,
    /// Largest latency over the changes with no gap in the 150 ms after them, milliseconds.
    pub clear_max_ms: Option<f64>,
    /// Mean time from the end of the gap that hides a change to the switch, milliseconds.
    pub hidden_mean_ms_from_gap_end: Option<f64>,
    /// Largest time from the end of the gap that hides a change to the switch, milliseconds.
    pub hidden_max_ms_from_gap_end: Option<f64>,
    /// Fraction of samples whose decision is the true image, 0..1.
    pub agree: Option<f64>,
    /// Complete decision episodes.
    pub episodes: usize,
    /// Shortest complete decision episode, milliseconds.
    pub min_episode_ms: Option<f64>,
    /// Complete decision episodes shorter than 150 ms.
    pub episodes_under_150ms: usize,
    /// Switches during a gap or less than 150 ms after it ended.
    pub switches_within_150ms_after_gap: usize,
}

/// `trace analyze --json`: the trace's figures and one entry per filter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnalyzeJson {
    /// Trace samples (lines).
    pub samples: usize,
    /// Distinct tracker samples.
    pub tracker_samples: usize,
    /// Tracker samples with no depth.
    pub tracker_samples_without_depth: usize,
    /// First to last sample, seconds.
    pub duration_s: f64,
    /// Surface image distance, metres.
    pub surface_m: f32,
    /// Refracted image distance, metres.
    pub refracted_m: f32,
    /// Decision threshold (geometric mean of the distances), metres.
    pub threshold_m: f32,
    /// Whether the gaze changes are ground truth (else derived from the raw depth).
    pub ground_truth: bool,
    /// Gaze changes.
    pub gaze_changes: usize,
    /// Blinks and dropouts.
    pub gaps: usize,
    /// How far apart the two images are in the tracker's vergence noise (`d'`; `null`
    /// without a sample with a depth).
    pub separability: Option<f32>,
    /// The tracker's vergence noise (standard deviation), degrees.
    pub vergence_noise_deg: Option<f32>,
    /// Whether the noise was estimated from the trace's fixations (false: the 1 degree prior,
    /// too few fixation samples).
    pub vergence_noise_estimated: Option<bool>,
    /// Vergence of the surface image minus that of the refracted image, degrees.
    pub vergence_gap_deg: Option<f32>,
    /// One entry per filter, in the configured order.
    pub filters: Vec<FilterJson>,
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
    /// Blinks and dropouts of the trace.
    pub gaps: Vec<Gap>,
    /// The separability of the images for this trace's tracker.
    pub separability: Option<Separability>,
    /// One report per filter, in the configured order.
    pub filters: Vec<FilterReport>,
}

impl AnalyzeReport {
    /// The tracker's mean sample rate, hertz.
    pub fn tracker_rate_hz(&self) -> Option<f64> {
        (self.duration_s > 0.0 && self.tracker_samples > 1)
            .then(|| (self.tracker_samples - 1) as f64 / self.duration_s)
    }

    /// The figures as `trace analyze --json` writes them.
    pub fn to_json(&self) -> AnalyzeJson {
        AnalyzeJson {
            samples: self.samples,
            tracker_samples: self.tracker_samples,
            tracker_samples_without_depth: self.tracker_samples_without_depth,
            duration_s: self.duration_s,
            surface_m: self.distances.surface_m,
            refracted_m: self.distances.refracted_m,
            threshold_m: self.distances.threshold_m(),
            ground_truth: self.ground_truth,
            gaze_changes: self.truth.changes.len(),
            gaps: self.gaps.len(),
            separability: self.separability.map(|s| s.d_prime()),
            vergence_noise_deg: self.separability.map(|s| s.noise_deg),
            vergence_noise_estimated: self.separability.map(|s| s.estimated),
            vergence_gap_deg: self.separability.map(|s| s.gap_deg),
            filters: self.filters.iter().map(FilterReport::to_json).collect(),
        }
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
        if let Some(sep) = &self.separability {
            writeln!(
                f,
                "separability d' = {:.2}: the images are {:.2} degree apart in vergence, the \
                 tracker's vergence noise is {:.2} degree ({})",
                sep.d_prime(),
                sep.gap_deg.abs(),
                sep.noise_deg,
                if sep.estimated {
                    "estimated from the trace's fixations"
                } else {
                    "assumed: too few fixation samples to estimate it"
                }
            )?;
            if sep.d_prime() < SEPARABLE {
                writeln!(
                    f,
                    "warning: d' below {SEPARABLE}: the eye tracker cannot tell the surface from \
                     the refracted image apart in this scene"
                )?;
            }
        }
        let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.0}"));
        let name = |k: &FilterKind| {
            if *k == FilterKind::default() {
                format!("{k} (default)")
            } else {
                k.to_string()
            }
        };
        writeln!(
            f,
            "{:<44} {:>8} {:>6} {:>6} {:>9} {:>9} {:>8} {:>6}",
            "filter", "switches", "false", "missed", "mean ms", "median ms", "max ms", "agree"
        )?;
        for r in &self.filters {
            writeln!(
                f,
                "{:<44} {:>8} {:>6} {:>6} {:>9} {:>9} {:>8} {:>6}",
                name(&r.filter),
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
        writeln!(
            f,
            "decision episodes; {} blinks or dropouts (gaps):",
            self.gaps.len()
        )?;
        writeln!(
            f,
            "{:<44} {:>8} {:>14} {:>15} {:>26}",
            "filter", "episodes", "min episode ms", "under 150 ms", "switches <150 ms after gap"
        )?;
        for r in &self.filters {
            writeln!(
                f,
                "{:<44} {:>8} {:>14} {:>15} {:>26}",
                name(&r.filter),
                r.episodes_ns.len(),
                ms(r.min_episode_ms()),
                r.episodes_under_settle(),
                r.switches_after_gap,
            )?;
        }
        Ok(())
    }
}
