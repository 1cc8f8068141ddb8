//! `vitreous trace analyze` and `vitreous trace plot`: how fast and how steadily each depth
//! filter's gaze-image decision follows the gaze on a trace (issue 4, items 5 and 6).
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
use std::sync::Once;

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use vitreous_xr::TraceSample;
use vitreous_xr::synth::GazePhase;

use crate::gaze::vergence::{FixationDepth, VergenceConfig, VergenceEstimator};
use crate::gaze::{FilterKind, GazeConfig, GazeImage, GazePipeline, GazeState, ImageDistances};
use crate::scene::{gaze_image_of_target, load_scene};

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
/// ([`Scene::image_distances`](crate::scene::Scene::image_distances)); gaze changes are derived from the raw depth (a trace
/// file carries no ground truth). `filters` empty means the default and every alternative.
pub fn analyze_trace_file(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<AnalyzeReport> {
    let (samples, config) = load_inputs(trace, scene, filters)?;
    Ok(analyze(&samples, Truth::FromRawDepth, &config))
}

/// `vitreous trace plot TRACE --scene SCENE -o OUT`: see [`plot`].
pub fn plot_trace_file(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
    out_png: &Path,
) -> Result<()> {
    let (samples, config) = load_inputs(trace, scene, filters)?;
    plot(&samples, Truth::FromRawDepth, &config, out_png)
}

fn load_inputs(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<(Vec<TraceSample>, AnalyzeConfig)> {
    let scene = load_scene(scene).with_context(|| format!("loading scene {}", scene.display()))?;
    let samples = vitreous_xr::read_trace(trace)
        .with_context(|| format!("reading trace {}", trace.display()))?;
    let mut config = AnalyzeConfig::new(scene.image_distances());
    if !filters.is_empty() {
        config.filters = filters.to_vec();
    }
    Ok((samples, config))
}

/// Plot size, pixels.
const PLOT_SIZE_PX: (u32, u32) = (1400, 800);
/// The embedded font (DejaVu Sans, licence in `app/assets/fonts/LICENSE-DejaVu.txt`), so the
/// plot needs no system fonts.
static FONT_TTF: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

fn register_font() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_TTF)
            .map_err(|_| anyhow!("the embedded DejaVu Sans font could not be parsed"));
    });
    result
}

/// Colour of a gaze image in plots.
fn image_colour(image: GazeImage) -> RGBColor {
    match image {
        GazeImage::Surface => RGBColor(31, 119, 180),
        GazeImage::Refracted => RGBColor(230, 120, 20),
        GazeImage::Unknown => RGBColor(200, 200, 200),
    }
}

/// Line colours of the filters, in order.
const FILTER_COLOURS: [RGBColor; 5] = [
    RGBColor(0, 0, 0),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Draws raw and filtered fixation depth over time with the gaze-image decisions (like the
/// paper's Fig. 11) as a PNG at `out_png`, written to `out_png.partial` then renamed.
///
/// Top: raw depth per tracker sample (grey dots), each filter's depth (lines), the two image
/// distances and the threshold. Bottom: one strip per filter (and the truth) coloured by the
/// gaze image over time (blue surface, orange refracted, grey unknown).
pub fn plot(
    samples: &[TraceSample],
    truth: Truth<'_>,
    config: &AnalyzeConfig,
    out_png: &Path,
) -> Result<()> {
    register_font()?;
    let raw = raw_depths(samples, config.vergence);
    let timeline = match truth {
        Truth::Phases(phases) => timeline_from_phases(phases),
        Truth::FromRawDepth => timeline_from_raw_depth(&raw, &config.distances, config.persist_ns),
    };
    let t0 = samples.first().map_or(0, |s| s.time_ns);
    let secs = |t: i64| (t - t0) as f64 * 1e-9;
    let t_max = samples.last().map_or(1.0, |s| secs(s.time_ns)).max(1e-3);
    let replays: Vec<(FilterKind, Vec<ReplayedFrame>)> = config
        .filters
        .iter()
        .map(|&f| (f, replay(samples, config.gaze_config(f))))
        .collect();
    let d = config.distances;
    let y_max = (d.surface_m.max(d.refracted_m) as f64 * 2.0)
        .min(f64::from(config.vergence.max_depth_m))
        .max(0.1);

    let (w, h) = PLOT_SIZE_PX;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let draw_err = |e: &dyn fmt::Display| anyhow!("drawing the plot: {e}");
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&e))?;
        let rows = replays.len() + 1;
        let strip_px = 28 * rows as u32 + 70;
        let (upper, lower) = root.split_vertically(h - strip_px);
        let truth_label = if matches!(truth, Truth::Phases(_)) {
            "ground truth"
        } else {
            "raw-depth changes"
        };
        let mut chart = ChartBuilder::on(&upper)
            .caption(
                format!(
                    "Fixation depth: raw and filtered (surface {:.2} m, refracted {:.2} m)",
                    d.surface_m, d.refracted_m
                ),
                ("sans-serif", 22),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_max, 0.0..y_max)
            .map_err(|e| draw_err(&e))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("depth (m)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw_err(&e))?;
        let clamp = |v: f32| f64::from(v).clamp(0.0, y_max);
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(raw.iter().filter_map(|&(t, d)| {
                d.map(|d| Circle::new((secs(t), clamp(d)), 2, grey.filled()))
            }))
            .map_err(|e| draw_err(&e))?
            .label("raw depth")
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
        for (image, dist) in [
            (GazeImage::Surface, d.surface_m),
            (GazeImage::Refracted, d.refracted_m),
        ] {
            let c = image_colour(image);
            chart
                .draw_series(LineSeries::new(
                    [(0.0, clamp(dist)), (t_max, clamp(dist))],
                    c.stroke_width(1),
                ))
                .map_err(|e| draw_err(&e))?
                .label(format!("{image} image"))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c));
        }
        let threshold = clamp(d.threshold_m());
        chart
            .draw_series(DashedLineSeries::new(
                [(0.0, threshold), (t_max, threshold)],
                6,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(|e| draw_err(&e))?
            .label("threshold")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
        for (i, (kind, frames)) in replays.iter().enumerate() {
            let c = FILTER_COLOURS[i % FILTER_COLOURS.len()];
            // One line per stretch with a known depth.
            let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for &(t, state) in frames {
                match state.filtered_depth.depth_m() {
                    Some(dm) => segments
                        .last_mut()
                        .into_iter()
                        .for_each(|s| s.push((secs(t), clamp(dm)))),
                    None if segments.last().is_some_and(|s| !s.is_empty()) => {
                        segments.push(Vec::new())
                    }
                    None => {}
                }
            }
            for (k, seg) in segments.into_iter().filter(|s| !s.is_empty()).enumerate() {
                let series = chart
                    .draw_series(LineSeries::new(seg, c.stroke_width(2)))
                    .map_err(|e| draw_err(&e))?;
                if k == 0 {
                    series.label(kind.to_string()).legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2))
                    });
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| draw_err(&e))?;

        // Decision strips: truth first, then one per filter.
        let mut strips = ChartBuilder::on(&lower)
            .margin_left(12)
            .margin_right(12)
            .margin_bottom(8)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_max, 0.0..rows as f64)
            .map_err(|e| draw_err(&e))?;
        strips
            .configure_mesh()
            .disable_mesh()
            .disable_y_axis()
            .x_desc("time (s)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw_err(&e))?;
        let row_top = |row: usize| (rows - row) as f64;
        let mut bars: Vec<Rectangle<(f64, f64)>> = Vec::new();
        let mut label_rows: Vec<(usize, String)> = vec![(0, truth_label.to_owned())];
        // Truth row.
        let mut truth_points: Vec<(f64, GazeImage)> = Vec::new();
        if let Some((start, first)) = timeline.initial {
            truth_points.push((secs(start).max(0.0), first));
        }
        truth_points.extend(timeline.changes.iter().map(|c| (secs(c.time_ns), c.to)));
        let mut push_row = |row: usize, points: &[(f64, GazeImage)]| {
            for (k, &(t, image)) in points.iter().enumerate() {
                let end = points.get(k + 1).map_or(t_max, |p| p.0);
                if end > t {
                    bars.push(Rectangle::new(
                        [(t, row_top(row) - 0.85), (end, row_top(row) - 0.15)],
                        image_colour(image).filled(),
                    ));
                }
            }
        };
        push_row(0, &truth_points);
        for (i, (kind, frames)) in replays.iter().enumerate() {
            let mut points: Vec<(f64, GazeImage)> = Vec::new();
            for &(t, state) in frames {
                if points.last().is_none_or(|p| p.1 != state.image) {
                    points.push((secs(t), state.image));
                }
            }
            push_row(i + 1, &points);
            label_rows.push((i + 1, kind.to_string()));
        }
        strips.draw_series(bars).map_err(|e| draw_err(&e))?;
        strips
            .draw_series(label_rows.into_iter().map(|(row, text)| {
                Text::new(
                    text,
                    (0.005 * t_max, row_top(row) - 0.4),
                    ("sans-serif", 13).into_font().color(&BLACK),
                )
            }))
            .map_err(|e| draw_err(&e))?;
        root.present().map_err(|e| draw_err(&e))?;
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let png = crate::output::encode_png(&rgba, w, h)?;
    crate::output::write_atomic(out_png, &png)
}
