//! `vitreous trace analyze` and `vitreous trace plot`: how fast and how steadily each depth
//! filter's gaze-image decision follows the gaze on a trace. The analysis and its figures are
//! `vitreous-gaze`'s ([`vitreous_gaze::analysis`], whose docs define them); here the truth a
//! trace is judged against, the inputs read, and `plot.rs`, which draws it.

use std::path::Path;

use anyhow::{Context, Result};
use vitreous_trace::TraceSample;
use vitreous_trace::synth::GazePhase;

use vitreous_frames::input_files::InputFiles;
use vitreous_frames::setup::ensure_samples;
use vitreous_gaze::FilterKind;
use vitreous_gaze::analysis::{
    AnalyzeConfig, AnalyzeReport, GazeChange, TruthTimeline, raw_depths, timeline_from_raw_depth,
};
use vitreous_scene::{gaze_image_of_target, load_scene};

pub(crate) mod plot;

pub use plot::{FILTER_COLOURS, PlotLayout, plot, plot_trace_file};

/// Where the gaze changes come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Truth<'a> {
    /// Ground-truth phases of a synthetic trace.
    Phases(&'a [GazePhase]),
    /// Derived from the raw depth crossing the threshold persistently
    /// ([`timeline_from_raw_depth`]).
    FromRawDepth,
}

/// The analysis settings for a scene: its image distances (from its viewer's position) and
/// its object, whose projection the `evidence` decision checks the gaze against.
pub fn config_for_scene(scene: &vitreous_scene::Scene) -> AnalyzeConfig {
    let geometry = scene.viewing_geometry();
    AnalyzeConfig {
        object: Some((geometry.center_m, geometry.radius_m)),
        ..AnalyzeConfig::new(scene.image_distances())
    }
}

/// The truth timeline of ground-truth phases of a trace whose targets are laid out as
/// [`vitreous_scene::synth_params_for`] does (surface, then refracted).
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

/// Analyses a trace with every configured filter.
pub fn analyze(samples: &[TraceSample], truth: Truth<'_>, config: &AnalyzeConfig) -> AnalyzeReport {
    let timeline = match truth {
        Truth::Phases(phases) => timeline_from_phases(phases),
        Truth::FromRawDepth => timeline_from_raw_depth(
            &raw_depths(samples, config.vergence),
            &config.distances,
            config.persist_ns,
        ),
    };
    let ground_truth = matches!(truth, Truth::Phases(_));
    vitreous_gaze::analysis::analyze(samples, timeline, ground_truth, config)
}

/// `vitreous trace analyze TRACE --scene SCENE`: the image distances come from the scene
/// ([`Scene::image_distances`](vitreous_scene::Scene::image_distances)); gaze changes are
/// derived from the raw depth (a trace file carries no ground truth). `filters` empty means
/// every offered filter ([`FilterKind::all_default`]).
pub fn analyze_trace_file(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<AnalyzeReport> {
    let (samples, config, _) = load_inputs(trace, scene, filters)?;
    Ok(analyze(&samples, Truth::FromRawDepth, &config))
}

/// The trace's samples (refused when it has none) and the analysis settings for a scene (its
/// image distances) and `filters` (empty: every offered filter), with the files read.
pub(super) fn load_inputs(
    trace: &Path,
    scene: &Path,
    filters: &[FilterKind],
) -> Result<(Vec<TraceSample>, AnalyzeConfig, InputFiles)> {
    let scene = load_scene(scene).context("loading the scene")?;
    // The trace's errors name its file and line.
    let samples = vitreous_trace::read_trace(trace).context("reading the trace")?;
    ensure_samples(trace, &samples, "analyse")?;
    let mut config = config_for_scene(&scene);
    if !filters.is_empty() {
        config.filters = filters.to_vec();
    }
    let mut inputs = InputFiles::new();
    inputs.add(trace, "TRACE").add_scene(&scene, "--scene");
    Ok((samples, config, inputs))
}
