//! `vitreous study run`: one participant's session of a protocol, following a plan, on the
//! OpenXR runtime (the `vitreous run` path) or, with `--dry-run`, headless on the null backend
//! replaying a trace (a synthetic one for the scene when none is given).
//!
//! Trials are run in plan order; consecutive trials in one scene form a block, and each block
//! is its own session (the scene is loaded once per block). Answers already in the responses
//! file are skipped, after checking they match the plan: a restart after a crash resumes at the
//! first unanswered trial.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{ContextOptions, GpuContext, Reflection};
use vitreous_trace::{Command, FrameInput};
use vitreous_xr::{NullBackend, NullConfig};

use crate::run::RunOptions;
use vitreous_frames::conditions::LiveConditions;
use vitreous_frames::director::Director;
use vitreous_frames::frame_loop::{self, FramePlan, FrameSink};
use vitreous_frames::look::{GazeSettings, planners_for};
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::render_desc;
use vitreous_gaze::GazeOverride;
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{Scene, load_scene};
use vitreous_study::answers::{Keyboard, SimulatedObserver};
use vitreous_study::plan::{PlannedTrial, read_plan};
use vitreous_study::protocol::{Protocol, Show};
use vitreous_study::session::{
    AnswerSources, ResponsesFile, StudyDirector, TimingLog, remaining_trials,
};

/// The shortest and longest time scale `--time-scale` accepts.
pub const TIME_SCALE_RANGE: (f64, f64) = (0.001, 10.0);

/// Options of `vitreous study run`.
#[derive(Clone, Debug)]
pub struct StudyRunOptions {
    /// The protocol file.
    pub protocol: PathBuf,
    /// The plan file.
    pub plan: PathBuf,
    /// Whose trials to run.
    pub participant: String,
    /// The responses file (appended to).
    pub responses: PathBuf,
    /// Headless on the null backend instead of the OpenXR runtime.
    pub dry_run: bool,
    /// In a desktop window of this size instead of the OpenXR runtime (`vitreous view`).
    pub view: Option<(u32, u32)>,
    /// The trace a dry run replays (default: a synthetic one for each scene).
    pub trace: Option<PathBuf>,
    /// Display rate of a dry run, hertz.
    pub frame_rate_hz: f64,
    /// Eye image size of a dry run (default: the scene's).
    pub size: Option<(u32, u32)>,
    /// Every protocol duration multiplied by this (rehearsals and tests).
    pub time_scale: f64,
    /// Stop after this many answers.
    pub max_answers: Option<usize>,
    /// A simulated participant's scale values (`NAME=VALUE,...`) instead of real answers.
    pub simulate: Option<String>,
    /// Seed of the simulated participant.
    pub seed: u64,
    /// Read typed answers from standard input.
    pub keyboard: bool,
    /// Vulkan (and OpenXR core) validation; any message fails the run.
    pub validate: bool,
    /// On the headset: where each block's session writes its summary.json, frames.csv and
    /// recording, in a folder named after the block's stimulus.
    pub out: Option<PathBuf>,
    /// The OpenXR run's own options (blend, gaze source, size, out); scene and frames are set
    /// per block.
    pub run: RunOptions,
}

/// What a session did.
#[derive(Debug, Clone, Default)]
pub struct StudyRunSummary {
    /// Trials of the participant in the plan.
    pub planned: usize,
    /// Trials answered before this session.
    pub answered_before: usize,
    /// Answers recorded in this session.
    pub answered_now: usize,
    /// Trials still unanswered.
    pub remaining: usize,
}

/// A study's trials as a session's [`Director`]: the condition and gaze image of each frame,
/// from a [`StudyDirector`].
pub struct StudyStage {
    /// The trials and answers.
    pub director: StudyDirector,
    /// The effect sets the looks are built for, in order.
    pub sets: Vec<EffectSet>,
    /// For each protocol condition, its index in `sets`; `None` for one that shows nothing.
    looks_index: Vec<Option<usize>>,
    /// Set once the director is done (or failed), to end the session.
    end: Arc<AtomicBool>,
    /// The first error, returned when the next frame finishes.
    error: Option<anyhow::Error>,
}

impl StudyStage {
    /// The stage for `director`'s trials of `protocol`.
    pub fn new(protocol: &Protocol, director: StudyDirector) -> StudyStage {
        let mut sets: Vec<EffectSet> = Vec::new();
        let looks_index = protocol
            .conditions
            .iter()
            .map(|c| match c.show {
                Show::Nothing => None,
                Show::Effects(set) => {
                    Some(sets.iter().position(|s| *s == set).unwrap_or_else(|| {
                        sets.push(set);
                        sets.len() - 1
                    }))
                }
            })
            .collect();
        if sets.is_empty() {
            sets.push(EffectSet::NONE);
        }
        StudyStage {
            director,
            sets,
            looks_index,
            end: Arc::new(AtomicBool::new(false)),
            error: None,
        }
    }
}

impl Director for StudyStage {
    fn sets(&self) -> &[EffectSet] {
        &self.sets
    }

    fn next_shown(&mut self, input: &FrameInput) -> (Option<EffectSet>, Option<GazeOverride>) {
        let shown = match self
            .director
            .frame(input.index, input.time_ns as f64 * 1e-9)
        {
            Ok(shown) => Some(shown),
            Err(e) => {
                self.error.get_or_insert(e);
                None
            }
        };
        if self.director.done() || self.error.is_some() {
            self.end.store(true, Ordering::SeqCst);
        }
        let set = shown
            .and_then(|s| s.condition.and_then(|c| self.looks_index[c]))
            .map(|i| self.sets[i]);
        (set, shown.map(|s| s.gaze))
    }

    fn command(&mut self, command: Command) {
        self.director.command(command);
    }

    fn session_events(&mut self, events: &[vitreous_trace::SessionEvent]) {
        self.director.session_events(events);
    }

    fn end_flag(&self) -> Arc<AtomicBool> {
        self.end.clone()
    }

    fn take_error(&mut self) -> Option<anyhow::Error> {
        self.error.take()
    }
}

/// Runs the participant's unanswered trials.
pub fn run_study(options: &StudyRunOptions) -> Result<StudyRunSummary> {
    let protocol = Protocol::read(&options.protocol)?;
    let (low, high) = TIME_SCALE_RANGE;
    if !(options.time_scale.is_finite() && (low..=high).contains(&options.time_scale)) {
        bail!(
            "--time-scale must be from {low} to {high}, got {}",
            options.time_scale
        );
    }
    if !(options.frame_rate_hz.is_finite() && (1.0..=1000.0).contains(&options.frame_rate_hz)) {
        bail!(
            "--rate must be from 1 to 1000 Hz, got {}",
            options.frame_rate_hz
        );
    }
    let plan = read_plan(&options.plan, &protocol)?;
    let planned: Vec<PlannedTrial> = plan
        .into_iter()
        .filter(|t| t.participant == options.participant)
        .collect();
    if planned.is_empty() {
        bail!(
            "{}: no trials for participant `{}`",
            options.plan.display(),
            options.participant
        );
    }
    let conditions: Vec<String> = protocol.conditions.iter().map(|c| c.name.clone()).collect();
    let mut simulated = match &options.simulate {
        Some(text) => Some(
            SimulatedObserver::parse(text, &conditions, options.seed)
                .map_err(|e| anyhow::anyhow!("--simulate: {e}"))?,
        ),
        None => None,
    };
    let (mut responses, answered) = ResponsesFile::open(&options.responses, &options.participant)?;
    let remaining = remaining_trials(&options.responses, &planned, &answered)?;
    let mut summary = StudyRunSummary {
        planned: planned.len(),
        answered_before: answered.len(),
        answered_now: 0,
        remaining: remaining.len(),
    };
    if remaining.is_empty() {
        tracing::info!(
            "participant {}: all {} trials are answered in {}",
            options.participant,
            planned.len(),
            options.responses.display()
        );
        return Ok(summary);
    }
    tracing::info!(
        "participant {}: {} of {} trials to run{}",
        options.participant,
        remaining.len(),
        planned.len(),
        if answered.is_empty() {
            String::new()
        } else {
            format!(" (resuming at trial {})", remaining[0].trial)
        }
    );
    let timing_path = timing_log_path(&options.responses);
    let mut keyboard = options.keyboard.then(Keyboard::stdin);
    for block in blocks(&remaining) {
        let left = options.max_answers.map(|m| m - summary.answered_now);
        if left == Some(0) {
            break;
        }
        let stimulus = &protocol.stimuli[protocol
            .stimulus_index(&block[0].stimulus)
            .expect("plan checked against the protocol")];
        tracing::info!(
            "block: {} ({} trials, scene {})",
            stimulus.name,
            block.len(),
            stimulus.scene.display()
        );
        let director = StudyDirector::new(
            &protocol,
            options.time_scale,
            block.to_vec(),
            left,
            AnswerSources {
                keyboard: keyboard.take(),
                simulated: simulated.take(),
                controller: !options.dry_run && options.view.is_none(),
            },
            responses,
            TimingLog::open(&timing_path)?,
        );
        let mut stage = StudyStage::new(&protocol, director);
        let stage = if options.dry_run {
            dry_run_block(options, &protocol, &stimulus.scene, block.len(), stage)?
        } else if let Some(window) = options.view {
            crate::view::view_directed(
                &crate::view::ViewOptions {
                    scene: stimulus.scene.clone(),
                    window,
                    render_scale: 1.0,
                    frames: None,
                    screenshot: None,
                    script: None,
                    effects: None,
                    eyes: Default::default(),
                    preview: false,
                    overlay: true,
                    reflection: Reflection::Phong,
                    filter: None,
                    validate: options.validate,
                    device: None,
                    out: None,
                    trace: options.trace.clone(),
                    record: None,
                },
                &mut stage,
            )?;
            stage
        } else {
            let mut run = options.run.clone();
            run.scene = stimulus.scene.clone();
            run.frames = None;
            run.validate = options.validate;
            run.out = options.out.as_ref().map(|d| d.join(&stimulus.name));
            run.record = run.out.as_ref().map(|d| d.join("recorded.trace"));
            if let Some(out) = &run.out {
                std::fs::create_dir_all(out)
                    .with_context(|| format!("creating {}", out.display()))?;
            }
            crate::run::run_directed(&run, &mut stage)?;
            stage
        };
        let done = stage.director.done();
        summary.answered_now += stage.director.answers();
        let sources;
        (responses, sources) = stage.director.into_parts();
        keyboard = sources.keyboard;
        simulated = sources.simulated;
        if !done {
            break;
        }
    }
    summary.remaining = summary.planned - summary.answered_before - summary.answered_now;
    Ok(summary)
}

/// `responses.csv` -> `responses-timing.csv`, beside it.
pub fn timing_log_path(responses: &std::path::Path) -> PathBuf {
    let stem = responses
        .file_stem()
        .map_or("responses".into(), |s| s.to_string_lossy().into_owned());
    responses.with_file_name(format!("{stem}-timing.csv"))
}

/// Consecutive trials in one scene.
fn blocks(trials: &[PlannedTrial]) -> Vec<&[PlannedTrial]> {
    trials.chunk_by(|a, b| a.stimulus == b.stimulus).collect()
}

/// Loads a block's scene with what its conditions need.
pub fn scene_for(path: &std::path::Path, sets: &[EffectSet]) -> Result<Scene> {
    let mut scene = load_scene(path)?;
    if sets.iter().any(|s| s.caustics) {
        scene
            .load_caustics()
            .with_context(|| format!("a condition shows caustics in {}", path.display()))?;
    }
    vitreous_frames::setup::load_bake_for_glass(&mut scene);
    Ok(scene)
}

/// Runs a block headless on the null backend.
fn dry_run_block(
    options: &StudyRunOptions,
    protocol: &Protocol,
    scene_path: &std::path::Path,
    trials: usize,
    mut stage: StudyStage,
) -> Result<StudyStage> {
    let scene = scene_for(scene_path, &stage.sets)?;
    let (width, height) = options
        .size
        .unwrap_or((scene.output.width_px, scene.output.height_px));
    vitreous_frames::setup::check_size(width, height)?;
    let t = protocol.timing.scaled(options.time_scale);
    let needed_s = trials as f64 * (t.first_s + t.blank_s + t.second_s + t.interval_s) + 1.0;
    let samples = match &options.trace {
        Some(path) => {
            let (samples, _) = vitreous_frames::setup::load_trace(&scene, Some(path))?;
            samples
        }
        None => {
            let mut params = vitreous_scene::synth_params_for(&scene);
            params.duration_s = needed_s.min(4.0 * 3600.0) as f32;
            vitreous_trace::synth::synthesize_with_truth(&params)
                .context("synthesising a trace for the dry run")?
                .samples
        }
    };
    let mut backend = NullBackend::new(
        samples,
        NullConfig {
            frame_rate_hz: options.frame_rate_hz,
            max_frames: None,
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )
    .context("replaying the dry run's trace")?;
    let ctx = GpuContext::headless(&ContextOptions {
        validation: options.validate,
        device_name: None,
    })
    .context("setting up the Vulkan device")?;
    let (planners, defocus) = planners_for(
        &scene,
        &stage.sets,
        Reflection::default(),
        &GazeSettings::default(),
    )?;
    let mut renderer = render_desc::renderer_for(ctx, &scene, defocus.as_ref(), width, height)?;
    render_desc::enable_live_caustics(&mut renderer, &scene, stage.sets.iter().any(|s| s.caustics))
        .context("preparing live caustics")?;
    drop(defocus);
    let looks = LiveConditions::new(
        stage.sets.iter().copied().zip(planners).collect(),
        GazeOverride::Auto,
    );
    vitreous_frames::interrupt::watch();
    let mut sink = DryRunSink {
        stage: &mut stage,
        looks,
        motion: MotionClock::new(&scene),
    };
    frame_loop::run(&mut backend, &mut renderer, &mut sink)?;
    if let Some(e) = sink.stage.take_error() {
        return Err(e);
    }
    frame_loop::ensure_validation_clean(&renderer)?;
    if !stage.director.done() && !vitreous_frames::interrupt::requested() {
        tracing::warn!(
            "the dry run's trace ended before the block's last trial; run again to resume"
        );
    }
    Ok(stage)
}

/// The dry run's frames: the stage decides, nothing is read back.
struct DryRunSink<'a> {
    /// The study.
    stage: &'a mut StudyStage,
    /// A planner per effect set.
    looks: LiveConditions,
    /// The scene's motion (`[motion]`), from the first frame.
    motion: MotionClock,
}

impl FrameSink for DryRunSink<'_> {
    fn pose(&mut self, input: &FrameInput) -> Option<vitreous_render::ScenePose> {
        let placement = self.motion.placement(input.time_ns)?;
        let pose = self.motion.pose_of(&placement);
        self.looks
            .set_object_pose(placement.object_position_m, pose.world_from_model);
        Some(pose)
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        FramePlan {
            look: self.looks.plan_directed(self.stage, input),
            want: Want::default(),
        }
    }

    fn finished(&mut self, _input: &FrameInput, _result: &FrameResult) -> Result<()> {
        match self.stage.take_error() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn stop_requested(&self) -> bool {
        self.stage.ending() || vitreous_frames::interrupt::requested()
    }
}
