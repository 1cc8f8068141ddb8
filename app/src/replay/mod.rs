//! `vitreous replay`: a recorded (or synthesised) trace through the real frame loop on a real
//! Vulkan device, writing per-eye images, see-through previews, the per-frame defocus log
//! `frames.csv` and `summary.json`.
//!
//! Over 600 lines: the replay's checks of its options and inputs, its sink (saving, the
//! sphere check beside the frames, the recording's edits and events) and its summary around the
//! one loop; the saving, the physical reference and the summary's types are apart already.

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use vitreous_optics::refraction::Refraction;
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{ContextOptions, GpuContext, Look, Reflection, Renderer, ScenePose};
use vitreous_trace::format::{EditRecord, Recording, TraceSample};
use vitreous_trace::{FrameInput, SessionEvent};
use vitreous_xr::null::{NullBackend, NullConfig};

use physical::Physical;
use summary::UnfinishedSummary;
pub use summary::{ReplaySummary, RunStatus};
use vitreous_frames::frame_log::FrameLog;
use vitreous_frames::frame_loop::{self, FramePlan, FrameSink};
use vitreous_frames::input_files::InputFiles;
use vitreous_frames::look::GazeSettings;
use vitreous_frames::look::LookPlanner;
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::output::{self, write_atomic};
use vitreous_frames::render_desc;
use vitreous_frames::setup::{check_size, load_recording};
use vitreous_frames::sphere_check_view::side_by_side;
use vitreous_frames::spread::Spread;
use vitreous_frames::validation::ValidationSummary;
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{Scene, load_scene};

mod cli;
mod fields;
mod physical;
mod summary;

use fields::recorded_field;
pub use fields::{Fields, square_pixels};

pub use cli::{ReplayArgs, replay_command};

/// Options of a replay.
#[derive(Clone, Debug)]
pub struct ReplayOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// The trace to replay; `None` synthesises one for the scene.
    pub trace: Option<PathBuf>,
    /// Output folder.
    pub out: PathBuf,
    /// Stop after this many frames.
    pub frames: Option<u64>,
    /// Save every K-th frame (0 saves none); the first frame is always saved when K > 0.
    pub save_every: u64,
    /// Eye image size overriding the scene's, pixels.
    pub size: Option<(u32, u32)>,
    /// Turn on the Vulkan validation layers; any message fails the replay.
    pub validate: bool,
    /// Effects overriding the scene's.
    pub effects: Option<EffectSet>,
    /// Pick the Vulkan device whose name contains this.
    pub device: Option<String>,
    /// Display frame rate of the replay, hertz.
    pub frame_rate_hz: f64,
    /// One frame per trace sample at its time (as `vitreous run` rendered a recording),
    /// instead of `frame_rate_hz`.
    pub at_samples: bool,
    /// Show a progress bar.
    pub progress: bool,
    /// How the reflected image is drawn when per-eye refraction is on.
    pub reflection: Reflection,
    /// Also write each saved eye image beside the sphere check of its refraction layer.
    pub sphere_check: bool,
    /// Also render the physical reference of every saved frame (`vitreous reference`) and
    /// measure what the eye sees against it.
    pub compare_reference: bool,
    /// With `compare_reference`: also measure with the display's light and panel misregistered
    /// by each of these angles (degrees), right, left, down and up.
    pub compare_shifts_deg: Vec<f32>,
    /// Depth filter and gaze-image override of the gaze pipeline (used with defocus).
    pub gaze: GazeSettings,
    /// The field of view each eye is drawn with: the scene's, or the headset's from the
    /// recording's views lines.
    pub fields: Fields,
}

/// Saves chosen frames while the loop runs.
struct Saver<'a> {
    dir: PathBuf,
    /// How the scene's display shows the saved frames to the wearer (the previews).
    display: vitreous_frames::wearer::WearerView,
    /// Decides each frame's look (gaze-dependent defocus).
    planner: LookPlanner,
    /// The scene, when the sphere check is written beside each saved eye.
    sphere_check: Option<&'a Scene>,
    /// With the sphere check: the scene under the other refraction model, drawn again for each
    /// saved frame.
    other: Option<OtherRefraction>,
    save_every: u64,
    saved: Vec<String>,
    progress: ProgressBar,
    /// The per-frame log (`frames.csv`).
    log: FrameLog,
    /// The effect set's name, as the log gives it.
    condition: String,
    /// The first error writing the log, reported when the next frame finishes.
    log_error: Option<anyhow::Error>,
    /// How the scene moves, with the time of the first frame once it came.
    motion: MotionClock,
    /// The trace's scene edits not yet applied, in time order.
    edits: std::collections::VecDeque<EditRecord>,
    /// With `--compare-reference`: the physical reference of each saved frame.
    physical: Option<Physical>,
    /// The recording's session events met so far, by kind (trace v1.4's event lines).
    session_events: std::collections::BTreeMap<String, u64>,
}

/// A second renderer with the scene under the refraction model the scene does not use, for
/// `--sphere-check`'s paper / two-surface / ray-traced images.
struct OtherRefraction {
    /// The renderer.
    renderer: Renderer,
    /// The scene's own model.
    scene_model: Refraction,
    /// The object's latest pose, when it moves.
    pose: Option<ScenePose>,
    /// Saved frames in flight: index, look, and pose.
    pending: Vec<(u64, Look, Option<ScenePose>)>,
}

impl OtherRefraction {
    /// Draws frame `input` as planned under the other model and returns its eye images.
    fn draw(&mut self, input: &FrameInput) -> Result<Option<[Vec<u8>; 2]>> {
        let Some(k) = self.pending.iter().position(|p| p.0 == input.index) else {
            return Ok(None);
        };
        let (_, look, pose) = self.pending.swap_remove(k);
        if let Some(pose) = pose {
            self.renderer.set_pose(pose);
        }
        let want = Want {
            eyes: true,
            world: false,
        };
        self.renderer
            .submit(&render_desc::frame_params(input, look), want)
            .context("drawing the frame under the other refraction model")?;
        let results = self.renderer.flush()?;
        Ok(results
            .into_iter()
            .last()
            .and_then(|r| r.readback)
            .map(|r| r.eyes))
    }
}

impl FrameSink for Saver<'_> {
    fn session_events(
        &mut self,
        frame: Option<&FrameInput>,
        events: &[SessionEvent],
    ) -> Result<()> {
        for e in events {
            tracing::info!(
                "{}: {e} (recorded)",
                frame.map_or("after the last frame".to_owned(), |f| format!(
                    "frame {}",
                    f.index
                ))
            );
            *self
                .session_events
                .entry(e.fields().0.to_owned())
                .or_default() += 1;
        }
        Ok(())
    }

    fn light_share(&mut self) -> Option<f32> {
        // A recorded `light-estimate` edit's share, else the scene's.
        Some(self.motion.light_share())
    }

    fn pose(&mut self, input: &FrameInput) -> Option<ScenePose> {
        // Each edit shows from the first frame at or after its time, as in the session.
        while let Some(edit) = self.edits.front()
            && edit.time_ns <= input.time_ns
        {
            self.motion.replay_edit(edit, input.index);
            self.edits.pop_front();
        }
        let pose = self.motion.pose(input.time_ns, &mut self.planner);
        if let (Some(other), Some(p)) = (&mut self.other, pose) {
            other.pose = Some(p);
        }
        pose
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let save = self.save_every > 0 && input.index.is_multiple_of(self.save_every);
        let mut look = self.planner.plan(input).0;
        look.caustics &= self.motion.caustics_valid();
        if save && let Some(other) = &mut self.other {
            other.pending.push((input.index, look, other.pose));
        }
        if save && let Some(physical) = &mut self.physical {
            let placement = self
                .motion
                .last_placement()
                .unwrap_or_else(|| physical.scene.rest_placement());
            physical.pending.push((input.index, placement));
        }
        if let Err(e) = self
            .log
            .record(input, &self.condition, self.planner.last_defocus())
        {
            self.log_error.get_or_insert(e);
        }
        FramePlan {
            look,
            want: Want {
                eyes: save,
                world: save,
            },
        }
    }

    fn stop_requested(&self) -> bool {
        vitreous_frames::interrupt::requested()
    }

    fn finished(&mut self, input: &FrameInput, result: &FrameResult) -> Result<()> {
        if let Some(e) = self.log_error.take() {
            return Err(e);
        }
        self.progress.inc(1);
        if let Some(readback) = &result.readback {
            let names = output::write_frame(&self.dir, input.index, readback, &self.display)?;
            self.saved
                .extend(names.into_iter().map(|n| format!("frames/{n}")));
            if let Some(physical) = &mut self.physical {
                let files = physical.measure(&self.dir, input, readback)?;
                self.saved.extend(files);
            }
            if let Some(scene) = self.sphere_check {
                let size = (readback.width, readback.height);
                let other = match &mut self.other {
                    Some(o) => o.draw(input)?.map(|eyes| (eyes, o.scene_model)),
                    None => None,
                };
                for (eye, name) in output::EYE_NAMES.iter().enumerate() {
                    let own = readback.eyes[eye].as_slice();
                    // Paper, two-surface, then the ray tracer's two-surface layer.
                    let gpu: Vec<&[u8]> = match &other {
                        Some((eyes, Refraction::Paper)) => vec![own, eyes[eye].as_slice()],
                        Some((eyes, Refraction::TwoSurface)) => vec![eyes[eye].as_slice(), own],
                        None => vec![own],
                    };
                    let traced = if other.is_some() {
                        Refraction::TwoSurface
                    } else {
                        scene.object.refraction
                    };
                    let image = side_by_side(scene, input, eye, &gpu, traced, size);
                    let png = output::encode_png(&image, size.0 * (gpu.len() as u32 + 1), size.1)?;
                    let file = format!("{:06}-{name}-sphere-check.png", input.index);
                    write_atomic(&self.dir.join(&file), &png)?;
                    self.saved.push(format!("frames/{file}"));
                }
            }
        }
        Ok(())
    }
}

/// Runs a replay. All input is checked before anything is written.
pub fn replay(options: &ReplayOptions) -> Result<ReplaySummary> {
    let mut scene = load_scene(&options.scene)?;
    let effects = options.effects.unwrap_or(scene.effects);
    effects.ensure_implemented()?;
    if effects.caustics {
        scene.load_caustics()?;
    }
    vitreous_frames::setup::load_bake_for_glass(&mut scene);
    let (width, height) = options
        .size
        .unwrap_or((scene.output.width_px, scene.output.height_px));
    check_size(width, height)?;
    if !(options.frame_rate_hz.is_finite() && (1.0..=1000.0).contains(&options.frame_rate_hz)) {
        bail!(
            "--rate must be between 1 and 1000 Hz, got {}",
            options.frame_rate_hz
        );
    }
    if options.save_every == 0 {
        for (asked, option) in [
            (options.compare_reference, "--compare-reference"),
            (options.sphere_check, "--sphere-check"),
        ] {
            if asked {
                bail!(
                    "{option} works on the saved frames, and --save-every 0 saves none: give \
                     --save-every K (1 or more)"
                );
            }
        }
    }
    let (recording, trace_name) = load_recording(&scene, options.trace.as_deref())?;
    let Recording {
        samples,
        edits,
        events,
        views,
    } = recording;
    let recorded = recorded_field(options.fields, &views, &trace_name, options.size)?;
    let (width, height) = match (options.size, recorded) {
        (Some(size), _) => size,
        (None, Some(fov)) => square_pixels(scene.output.width_px, fov),
        (None, None) => (width, height),
    };
    check_size(width, height)?;
    if let Some(fov) = recorded {
        scene.output.fov = fov;
    }
    let mut inputs = InputFiles::new();
    inputs.add_scene(&scene, "SCENE");
    if let Some(trace) = &options.trace {
        inputs.add(trace, "--trace");
    }
    inputs.check_folder("--out", &options.out, &["frames"], &replay_writes)?;
    let expected_frames = expected_frames(&samples, options.frame_rate_hz, options.frames);
    if options.frames.is_none() && expected_frames > MAX_FRAMES_WITHOUT_LIMIT {
        bail!(
            "{trace_name} spans {:.0} s: at {} Hz that is {expected_frames} frames, more than the \
             {MAX_FRAMES_WITHOUT_LIMIT} replayed without --frames; pass --frames N to replay part \
             of it",
            trace_span_s(&samples),
            options.frame_rate_hz
        );
    }
    let mut backend = NullBackend::new(
        samples,
        NullConfig {
            frame_rate_hz: options.frame_rate_hz,
            max_frames: options.frames,
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: options.at_samples,
        },
    )
    .with_context(|| format!("replaying {trace_name}"))?
    .with_events(events)
    .with_views(views);
    if recorded.is_some() {
        backend = backend.with_recorded_fields();
    }

    let ctx = GpuContext::headless(&ContextOptions {
        validation: options.validate,
        device_name: options.device.clone(),
    })
    .context("setting up the Vulkan device")?;
    let (device, driver) = (ctx.device_name.clone(), ctx.driver.clone());
    let (planner, defocus) =
        vitreous_frames::look::planner_for(&scene, &effects, options.reflection, &options.gaze)?;
    let mut renderer = render_desc::renderer_for(ctx, &scene, defocus.as_ref(), width, height)?;
    render_desc::enable_live_caustics(&mut renderer, &scene, effects.caustics)
        .context("preparing live caustics")?;
    let other = if options.sphere_check {
        let mut other_scene = scene.clone();
        other_scene.object.refraction = match scene.object.refraction {
            Refraction::Paper => Refraction::TwoSurface,
            Refraction::TwoSurface => Refraction::Paper,
        };
        let ctx = GpuContext::headless(&ContextOptions {
            validation: options.validate,
            device_name: options.device.clone(),
        })
        .context("setting up the second Vulkan device")?;
        let mut r = Renderer::new(
            ctx,
            &render_desc::scene_desc(&other_scene, defocus.as_ref()),
            width,
            height,
        )
        .context("preparing the renderer of the other refraction model")?;
        render_desc::enable_live_caustics(&mut r, &other_scene, effects.caustics)
            .context("preparing live caustics")?;
        Some(OtherRefraction {
            renderer: r,
            scene_model: scene.object.refraction,
            pose: None,
            pending: Vec::new(),
        })
    } else {
        None
    };
    drop(defocus);

    let frames_dir = options.out.join("frames");
    fs::create_dir_all(&frames_dir)
        .with_context(|| format!("creating output folder {}", frames_dir.display()))?;
    let scene_name = options.scene.display().to_string();
    let summary_path = options.out.join("summary.json");
    let unfinished = |status, error| UnfinishedSummary {
        vitreous_version: env!("CARGO_PKG_VERSION"),
        status,
        complete: false,
        scene: &scene_name,
        trace: &trace_name,
        error,
    };
    // First replace an earlier run's summary, then clear its frames: from here on the folder
    // says it is incomplete until the final summary is written last.
    let running = serde_json::to_vec_pretty(&unfinished(RunStatus::Running, None))?;
    write_atomic(&summary_path, &running)?;
    remove_earlier_frames(&frames_dir)?;
    let log = FrameLog::create(&options.out)?;
    let signals = vitreous_frames::interrupt::watch();
    let progress = if options.progress {
        let bar = ProgressBar::new(expected_frames);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} replay [{bar:30}] {pos}/{len} frames {per_sec} {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut saver = Saver {
        dir: frames_dir,
        display: vitreous_frames::wearer::WearerView::of_scene(&scene),
        sphere_check: options.sphere_check.then_some(&scene),
        other,
        save_every: options.save_every,
        planner,
        saved: Vec::new(),
        progress,
        log,
        condition: effects.to_string(),
        log_error: None,
        motion: MotionClock::new(&scene),
        edits: edits.into(),
        session_events: Default::default(),
        physical: options.compare_reference.then(|| {
            let mut scene = scene.clone();
            if scene.caustics.bake.is_some()
                && let Err(e) = scene.load_caustics()
            {
                tracing::warn!("the caustic is left out of the compared regions: {e}");
            }
            Physical {
                scene,
                shifts_deg: options.compare_shifts_deg.clone(),
                pending: Vec::new(),
                figures: Vec::new(),
                reports: Vec::new(),
                source: (options.scene.clone(), trace_name.clone()),
            }
        }),
    };
    let started = Instant::now();
    let records = match frame_loop::run(&mut backend, &mut renderer, &mut saver) {
        Ok(records) => records,
        Err(e) => {
            saver.progress.abandon();
            // Best effort: the `running` summary already marks the folder incomplete.
            let failed = unfinished(RunStatus::Failed, Some(format!("{e:#}")));
            if let Ok(json) = serde_json::to_vec_pretty(&failed) {
                let _ = write_atomic(&summary_path, &json);
            }
            return Err(e);
        }
    };
    let wall_s = started.elapsed().as_secs_f64();
    saver.progress.finish_and_clear();
    if let Some(other) = &saver.other {
        frame_loop::ensure_validation_clean(&other.renderer)?;
    }
    let interrupted = signals && vitreous_frames::interrupt::requested();
    // The log holds exactly the frames rendered, also when interrupted.
    saver.log.finish()?;
    if let Some(physical) = &mut saver.physical {
        let file = physical.write_report(&saver.dir, renderer.size())?;
        saver.saved.push(file);
    }

    let validation = ValidationSummary::of(renderer.context());
    let status = if interrupted {
        RunStatus::Interrupted
    } else {
        RunStatus::Complete
    };
    let summary = ReplaySummary {
        vitreous_version: env!("CARGO_PKG_VERSION").into(),
        status,
        complete: status == RunStatus::Complete,
        scene: scene_name.clone(),
        scene_hash: scene.hash.clone(),
        trace: trace_name,
        effects: effects.to_string(),
        device,
        driver,
        validation,
        width_px: width,
        height_px: height,
        fields: options.fields,
        fov_deg: [
            scene.output.fov.angle_left_rad,
            scene.output.fov.angle_right_rad,
            scene.output.fov.angle_up_rad,
            scene.output.fov.angle_down_rad,
        ]
        .map(f32::to_degrees),
        frame_rate_hz: options.frame_rate_hz,
        frames: records.len() as u64,
        frames_per_second: records.len() as f64 / wall_s.max(1e-9),
        wall_s,
        cpu_ms: Spread::of(records.iter().map(|r| r.cpu_ms)),
        gpu_ms: Spread::of(records.iter().filter_map(|r| r.gpu_ms)),
        saved: saver.saved,
        gaze_image_switches: saver.log.gaze_image_switches(),
        separability: saver.log.separability_summary(),
        pupil: saver.log.pupil_summary(saver.planner.pupil_source()),
        moved_frames: saver.motion.moved_frames,
        inducer_computations: renderer.inducer_computations(),
        scene_edits: saver.motion.edit_count,
        session_events: saver.session_events,
        final_placement: saver.motion.final_placement(),
        compare_reference: saver.physical.map(|p| p.figures),
        per_frame: records,
    };
    let json = serde_json::to_vec_pretty(&summary).context("encoding summary.json")?;
    write_atomic(&summary_path, &json)?;
    if interrupted {
        bail!(
            "interrupted after {} frames; {} marks the run incomplete",
            summary.frames,
            summary_path.display()
        );
    }
    summary
        .validation
        .check(Some(&options.out.join("summary.json")))?;
    Ok(summary)
}

/// Most frames a replay renders without an explicit `--frames` (about 4.6 hours at 60 Hz): a
/// trace that spans years, or whose clock jumps, is refused rather than replayed for ever.
pub const MAX_FRAMES_WITHOUT_LIMIT: u64 = 1_000_000;

/// Seconds from the first to the last sample (0 for fewer than two samples).
fn trace_span_s(samples: &[TraceSample]) -> f64 {
    match (samples.first(), samples.last()) {
        (Some(a), Some(b)) => span_s(a.time_ns, b.time_ns),
        _ => 0.0,
    }
}

/// Seconds between two trace times, in i128: the difference of two i64 times can overflow.
fn span_s(first_ns: i64, last_ns: i64) -> f64 {
    (i128::from(last_ns) - i128::from(first_ns)) as f64 * 1e-9
}

/// How many frames the null backend will give for `samples` at `rate_hz` (saturating).
fn expected_frames(samples: &[TraceSample], rate_hz: f64, limit: Option<u64>) -> u64 {
    frames_for_span(trace_span_s(samples), rate_hz, limit)
}

fn frames_for_span(span_s: f64, rate_hz: f64, limit: Option<u64>) -> u64 {
    let n = (span_s.max(0.0) * rate_hz).floor();
    let n = if n >= u64::MAX as f64 {
        u64::MAX
    } else {
        n as u64 + 1
    };
    limit.map_or(n, |l| n.min(l))
}

/// Removes the frame images an earlier replay left in `frames_dir` (only files named as a
/// replay names them, and temporary files of interrupted writes), so the folder never mixes
/// two runs.
fn remove_earlier_frames(frames_dir: &Path) -> Result<()> {
    let entries =
        fs::read_dir(frames_dir).with_context(|| format!("listing {}", frames_dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("listing {}", frames_dir.display()))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if output::is_frame_file_name(name) {
            fs::remove_file(entry.path())
                .with_context(|| format!("removing an earlier run's {}", entry.path().display()))?;
        }
    }
    Ok(())
}

/// Whether a replay writes (or, from an earlier run, removes) `relative` inside its output
/// folder: `summary.json`, `frames.csv` and the frame images under `frames/`.
fn replay_writes(relative: &Path) -> bool {
    let name = relative
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    match relative.parent().and_then(Path::to_str) {
        Some("") => name == "summary.json" || name == "frames.csv",
        Some("frames") => output::is_frame_file_name(name),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_replay_writes_its_summary_log_and_frame_images_only() {
        for written in ["summary.json", "frames.csv", "frames/000030-left.png"] {
            assert!(replay_writes(Path::new(written)), "{written}");
        }
        for kept in [
            "trace.csv",
            "frames/notes.txt",
            "000030-left.png",
            "x/summary.json",
        ] {
            assert!(!replay_writes(Path::new(kept)), "{kept}");
        }
    }

    #[test]
    fn frame_count_of_a_trace_spanning_all_of_i64_saturates() {
        let span = span_s(i64::MIN, i64::MAX);
        assert!((span - 1.8446744e10).abs() < 1e4, "{span}");
        let n = frames_for_span(span, 60.0, None);
        assert!(n > MAX_FRAMES_WITHOUT_LIMIT);
        assert_eq!(frames_for_span(span, 60.0, Some(5)), 5);
        assert_eq!(frames_for_span(f64::INFINITY, 60.0, None), u64::MAX);
        assert_eq!(frames_for_span(1.0, 60.0, None), 61);
    }
}
