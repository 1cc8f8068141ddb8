//! `vitreous run`: the frame loop on a live OpenXR runtime (a headset, or Monado in CI).
//!
//! Set-up order is dictated by XR_KHR_vulkan_enable2: the OpenXR runtime first, then the
//! renderer's Vulkan instance and device created *through* it
//! ([`XrDeviceCreator`](vitreous_xr::openxr::XrDeviceCreator)), then the
//! session on that device, whose swapchain images the renderer draws into. Teardown is the
//! reverse: the renderer lets go of the swapchain images, the session goes, then the device,
//! then the OpenXR instance; [`XrSession`] owns the four and keeps that order itself.
//!
//! The loop is the shared one ([`vitreous_frames::frame_loop`]) plus one hook: each frame is drawn where
//! [`Backend::frame_target`](vitreous_xr::Backend::frame_target) says (the renderer's own
//! images or swapchain image `i`, and depth swapchain image `j` when depth is submitted).
//!
//! Live actions (controller buttons, see `vitreous_trace::command` and
//! `vitreous_xr::openxr::actions`) re-register the scene in the session itself; the commands
//! that change the look reach the sink through
//! [`Session::take_commands`](vitreous_xr::openxr::Session::take_commands) and are applied
//! by [`LiveConditions`]: the next effect condition among those this build implements, and the
//! forced gaze image (surface, refracted, auto).
//!
//! Parts: `cli.rs` (the command line), `controls.rs` (keyboard edits), `device.rs` (Vulkan
//! through the runtime), `xr_session.rs` (runtime, renderer and session owned together),
//! `sink.rs` (what is done with each frame; the readback check is
//! `vitreous_frames::readback_check`), `recording.rs` (the recorded trace and its replay
//! check), `summary.rs` (what the run reports), `interruptions.rs` (what a misbehaving headset
//! did: each session event logged, recorded, counted), `reconnect.rs` (asking the runtime again
//! after a loss); the conditions and live commands are
//! `vitreous_frames::conditions`. This file sets the session up, runs it and writes the summary.
//!
//! Over 600 lines: the run's set-up, its loop over sessions (a new one after a lost session or
//! runtime, the sink going on) and its summary share the scene, the runtime's info, the sink and
//! the merged report; what they need besides is in the parts above.

mod cli;
mod controls;
mod interruptions;
mod reconnect;
mod recording;
mod room_light;
mod sink;
mod summary;
mod views;
mod xr_session;

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use vitreous_render::{ContextOptions, Reflection, Renderer};
use vitreous_trace::Blend;
use vitreous_trace::format::{TraceVersion, TraceWriter};
use vitreous_trace::session_event::Loss;
use vitreous_xr::openxr::ash::vk;
use vitreous_xr::openxr::{
    Continued, DepthOptions, GazeChoice, OpenXrOptions, Runtime, SessionOptions, SessionReport,
    State,
};

pub use cli::{RunArgs, run_command};
pub use interruptions::{InterruptionSummary, NotRenderedFrames, Reconnect};
pub use reconnect::{RECONNECT_S_DEFAULT, RECONNECT_S_MAX};
pub use recording::ReplayCheck;
pub use summary::{GazeSamples, RunSummary};
#[cfg(test)]
pub(crate) use vitreous_frames::test_frame::test_frame;

use recording::replay_check;
use sink::RunSink;
use vitreous_frames::blur_stack::DefocusSetup;
use vitreous_frames::conditions::{LiveConditions, live_conditions};
use vitreous_frames::director::Director;
use vitreous_frames::focus::FocusFollower;
use vitreous_frames::frame_log::FrameLog;
use vitreous_frames::frame_loop;
use vitreous_frames::input_files::InputFiles;
use vitreous_frames::look::{GazeSettings, base_look, planners_for};
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::output::write_atomic;
use vitreous_frames::render_desc;
use vitreous_frames::resident::ResidentSampler;
use vitreous_frames::spread::Spread;
use vitreous_frames::validation::ValidationSummary;
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{CausticsMode, load_scene};
pub use xr_session::{Closed, XrSession};

/// Frames before the first sample of resident memory (summary.json `resident_memory`): the
/// first frames compile the driver's shader variants on first use and fill the allocators'
/// pools.
pub const RESIDENT_WARM_UP_FRAMES: u64 = 10;

/// Frames between two samples of resident memory after the warm-up.
pub const RESIDENT_EVERY_FRAMES: u64 = 10;

/// Options of `vitreous run`.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// End the session after this many frames (None: until the runtime or Ctrl-C ends it).
    pub frames: Option<u64>,
    /// Gaze replayed from this trace when the headset has no per-eye eye tracker (with the
    /// combined XR_EXT_eye_gaze_interaction ray alone, it decides the gaze image).
    pub gaze_trace: Option<PathBuf>,
    /// Which gaze source to use (`--gaze`): the best offered, or a forced one.
    pub gaze: GazeChoice,
    /// Record head pose and gaze of every frame into this trace file.
    pub record: Option<PathBuf>,
    /// Turn on the Vulkan validation layers and the OpenXR core validation layer; any Vulkan
    /// message fails the run.
    pub validate: bool,
    /// Read back a submitted swapchain image and check the object is in it.
    pub readback_check: bool,
    /// Blend mode instead of the automatic choice.
    pub blend: Option<Blend>,
    /// Eye image size instead of the runtime's recommended one.
    pub size: Option<(u32, u32)>,
    /// Effects overriding the scene's.
    pub effects: Option<EffectSet>,
    /// How the reflected image is drawn.
    pub reflection: Reflection,
    /// Fixation-depth filter overriding the scene's `[gaze] filter`.
    pub filter: Option<vitreous_gaze::FilterKind>,
    /// Where A_p comes from, overriding the scene's `[gaze] pupil`.
    pub pupil_source: Option<vitreous_gaze::PupilSource>,
    /// Where summary.json goes (None: not written).
    pub out: Option<PathBuf>,
    /// Read the keyboard's live controls from standard input even when it is not a terminal
    /// (a pipe or fifo); in a terminal they are always read (not in a study, whose answers
    /// come from there).
    pub stdin_controls: bool,
    /// How long to wait for the runtime to come back after a lost session or runtime before
    /// giving up, seconds (0: end the run at the loss; `None`: [`RECONNECT_S_DEFAULT`]).
    pub reconnect_s: Option<f64>,
}

/// Runs the scene on the OpenXR runtime. Fails with a clear message when there is no runtime,
/// no Vulkan support, a validation message, or a failed readback check.
pub fn run(options: &RunOptions) -> Result<RunSummary> {
    run_with(options, None)
}

/// Runs a session on the OpenXR runtime whose conditions and gaze images `director` decides
/// (a block of a study's trials): the controller's buttons go to it instead of the live
/// controls, and the session ends once it says so.
pub fn run_directed(options: &RunOptions, director: &mut dyn Director) -> Result<()> {
    run_with(options, Some(director)).map(|_| ())
}

/// Refuses `--record` and `--out` when they would write over a file the session reads (the
/// scene, its assets, the gaze trace), before the runtime starts.
fn check_outputs(options: &RunOptions, scene: &vitreous_scene::Scene) -> Result<()> {
    let mut inputs = InputFiles::new();
    inputs.add_scene(scene, "SCENE");
    if let Some(trace) = &options.gaze_trace {
        inputs.add(trace, "--gaze-trace");
    }
    if let Some(record) = &options.record {
        inputs.check_file("--record", record)?;
    }
    if let Some(out) = &options.out {
        inputs.check_folder("--out", out, &[], &|p| {
            p == Path::new("summary.json") || p == Path::new("frames.csv")
        })?;
    }
    Ok(())
}

/// [`run`], with a director deciding the looks when given.
fn run_with(options: &RunOptions, director: Option<&mut dyn Director>) -> Result<RunSummary> {
    let mut scene = load_scene(&options.scene)?;
    check_outputs(options, &scene)?;
    let effects = options.effects.unwrap_or(scene.effects);
    effects.ensure_implemented()?;
    if effects.caustics {
        scene.load_caustics()?;
    }
    // The caustic conditions are offered live only with the bake loaded or live caustics.
    let caustics_loaded = effects.caustics
        || ((scene.caustics.bake.is_some() || scene.caustics.mode == CausticsMode::Live)
            && EffectSet::IMPLEMENTED.caustics
            && scene
                .load_caustics()
                .map_err(|e| tracing::warn!("caustic conditions not offered live: {e}"))
                .is_ok());
    let conditions = match &director {
        Some(director) => {
            if director.sets().iter().any(|s| s.caustics) && !caustics_loaded {
                scene.load_caustics().with_context(|| {
                    format!(
                        "a directed condition (a study's) shows caustics in {}",
                        options.scene.display()
                    )
                })?;
            }
            director.sets().to_vec()
        }
        None => live_conditions(effects, caustics_loaded),
    };
    tracing::info!(
        "effect conditions (menu on the right controller): {}",
        conditions
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(" > ")
    );
    vitreous_frames::setup::load_bake_for_glass(&mut scene);
    let xr_options = OpenXrOptions {
        blend: options.blend,
        dimmer: scene.dimmer.is_some(),
        validation: options.validate,
        size: options.size,
    };
    let runtime = Runtime::new(&xr_options).context("starting OpenXR")?;
    let info = runtime.info().clone();
    let (width, height) = info.size;
    if let Some((w, h)) = options.size.filter(|&wanted| wanted != info.size) {
        tracing::warn!(
            "--size {w}x{h} is beyond what the runtime offers: eye images {width}x{height}"
        );
    }
    tracing::info!(
        "eye images {width}x{height} (recommended {}x{}, max {}x{})",
        info.recommended_size.0,
        info.recommended_size.1,
        info.max_size.0,
        info.max_size.1
    );
    let gaze_settings = GazeSettings {
        filter: options.filter,
        pupil_source: options.pupil_source,
        ..GazeSettings::default()
    };
    let (planners, defocus) =
        planners_for(&scene, &conditions, options.reflection, &gaze_settings)?;
    let context_options = ContextOptions {
        validation: options.validate,
        device_name: None,
    };
    // Every look the session may draw: each condition's, with its defocus when it has one.
    let looks: Vec<vitreous_render::Look> = conditions
        .iter()
        .flat_map(|c| {
            let look = base_look(c, options.reflection);
            let blurred = c.defocus.then_some(vitreous_render::Look {
                defocus: Some(vitreous_render::Defocus {
                    refracted_k_g_px: 1.0,
                    surface_k_g_px: 1.0,
                }),
                ..look
            });
            std::iter::once(look).chain(blurred)
        })
        .collect();
    let make_renderer = |ctx, defocus: Option<&DefocusSetup>| {
        let mut renderer = render_desc::renderer_for(ctx, &scene, defocus, width, height)?;
        render_desc::enable_live_caustics(&mut renderer, &scene, caustics_loaded)
            .context("preparing live caustics")?;
        render_desc::warm_up(
            &mut renderer,
            &scene,
            &looks,
            frame_loop::composition_for(info.blend),
        )
        .context("drawing the looks once before the session")?;
        Ok(renderer)
    };
    let end_flag = director.as_ref().map(|d| d.end_flag());
    let session_options = |continued: Option<Continued>, submitted: u64| SessionOptions {
        max_frames: options.frames.map(|n| n.saturating_sub(submitted)),
        gaze_trace: options.gaze_trace.clone(),
        gaze: options.gaze,
        scene_origin: None,
        viewer_position_m: scene.viewer.head_position_m,
        handle_ctrl_c: true,
        end: end_flag.clone(),
        depth: Some(DepthOptions {
            format: Renderer::DEPTH_FORMAT,
            near_m: vitreous_optics::camera::NEAR_M,
            far_m: vitreous_optics::camera::FAR_M,
        }),
        continued,
    };
    let mut xr = XrSession::start(
        runtime,
        &context_options,
        |ctx| make_renderer(ctx, defocus.as_ref()),
        &session_options(None, 0),
    )?;
    // The blur stacks are on the GPU now (a new session after a loss makes them again).
    drop(defocus);
    let device = {
        let ctx = xr.parts().1.context();
        format!("{} ({})", ctx.device_name, ctx.driver)
    };

    // Version 1.5 from the first line: every frame may carry the tracker's report, and the
    // session's events (a headset taken off, frames not rendered) and the eyes the headset
    // drew from go between the samples.
    let writer = match &options.record {
        Some(path) => Some(
            TraceWriter::create_version(path, TraceVersion::V1_5)
                .with_context(|| format!("creating {}", path.display()))?,
        ),
        None => None,
    };
    let log = match &options.out {
        Some(out) => {
            fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
            FrameLog::create(out)?
        }
        None => FrameLog::in_memory(),
    };
    let world_behind = info.blend.needs_world_behind();
    let edits = {
        use std::io::IsTerminal;
        (director.is_none() && (options.stdin_controls || std::io::stdin().is_terminal())).then(
            || {
                tracing::info!(
                    "keyboard controls on standard input, one a line: object x|y|z MM, turn DEG, \
                 place, light x|y|z MM, register x|y|z MM"
                );
                controls::stdin_edits()
            },
        )
    };
    let mut sink = RunSink {
        edits,
        planes_rx: None,
        planes: Vec::new(),
        light_rx: None,
        room_light: None,
        registrar: None,
        looks: LiveConditions::new(
            conditions.iter().copied().zip(planners).collect(),
            scene.gaze.image,
        ),
        commands: None,
        // Late enough for the pipelines to be warm and the head to have moved.
        readback_frame: options
            .readback_check
            .then(|| options.frames.map_or(10, |n| (n / 2).min(10)).max(1) - 1),
        object_center_m: scene.object.center_m,
        motion: MotionClock::new(&scene),
        object_radius_m: scene.object.radius_m,
        blend: info.blend,
        dimmer_shadow: scene.dimmer.map(|panel| {
            (
                panel,
                scene.placement_at(0.0).light_position_m,
                scene.floor.pose.position,
                scene.floor.normal(),
            )
        }),
        readback: None,
        writer,
        recorded: Vec::new(),
        log,
        log_error: None,
        director,
        focus: FocusFollower::new(&scene, options.filter),
        focus_m: None,
        global_dimmer: scene.global_dimmer,
        gaze_watch: Default::default(),
        events: Vec::new(),
        last_time_ns: None,
        resident: ResidentSampler::new(RESIDENT_WARM_UP_FRAMES, RESIDENT_EVERY_FRAMES),
        views: views::ViewWatch::default(),
        recorded_views: None,
        recorded_gaze_ns: None,
    };
    let reconnect_limit =
        std::time::Duration::from_secs_f64(options.reconnect_s.unwrap_or(RECONNECT_S_DEFAULT));
    let started = Instant::now();
    let mut report: Option<SessionReport> = None;
    let mut records = Vec::new();
    let mut reconnects = Vec::new();
    let mut validation: Option<ValidationSummary> = None;
    let mut inducer_computations = 0;
    let mut floor_centroids = None;
    let mut resident_memory;
    let format = xr.format();
    let mut gave_up: Option<anyhow::Error> = None;
    // One session, or one after another when a session or the runtime is lost: the sink (the
    // conditions, the gaze filters, the recording, a study's place) goes on across them.
    loop {
        sink.attach(xr.session());
        // The session's own count starts after the warm-up's.
        let warmed = xr.parts().1.inducer_computations();
        let (session, renderer) = xr.parts();
        let result = frame_loop::run(session, renderer, &mut sink);
        // Before the teardown: the session's memory as its last frame left it.
        resident_memory = sink.resident.finish();
        // The loop's error is the one reported; a clean-up failing after it (releasing the
        // images of a lost device) is logged.
        let final_light = sink
            .motion
            .final_placement()
            .map_or(scene.placement_at(0.0).light_position_m, |p| {
                glam::Vec3::from_array(p.light_position_m)
            });
        let (continued_from, next_index, first_display_ns, gaze_order, last_display) = {
            let s = xr.session();
            (
                s.world_from_space(),
                s.next_index(),
                s.first_display_ns(),
                s.gaze_order(),
                s.last_display(),
            )
        };
        let closed = xr.close(|renderer| {
            let centroids = options.readback_check.then(|| {
                vitreous_frames::readback_check::floor_centroids(
                    renderer,
                    scene.floor.world_from_plane(),
                    final_light,
                    sink.object_center_m,
                    sink.object_radius_m,
                )
            });
            (
                renderer.inducer_computations(),
                centroids,
                ValidationSummary::of(renderer.context()),
            )
        });
        let (computations, centroids, checked) = closed.after;
        inducer_computations += computations - warmed;
        match centroids {
            Some(Ok(c)) => floor_centroids = Some(c),
            Some(Err(e)) => tracing::warn!("reading back the floor's fields at the end: {e:#}"),
            None => {}
        }
        validation = Some(match validation.take() {
            Some(mut v) => {
                v.then(&checked);
                v
            }
            None => checked,
        });
        let lost = closed.report.interruptions.lost;
        match &mut report {
            Some(r) => r.then(&closed.report),
            None => report = Some(closed.report),
        }
        records.extend(first_error(result, closed.detached)?);
        let Some(loss) = lost.filter(|_| !reconnect_limit.is_zero()) else {
            break;
        };
        let end = end_flag.as_deref();
        let (runtime, waited) = match reconnect::runtime_again(&xr_options, reconnect_limit, end) {
            Ok(Some(again)) => again,
            Ok(None) => break,
            Err(e) => {
                tracing::error!("{e:#}");
                gave_up = Some(e);
                break;
            }
        };
        let again = runtime.info();
        if again.blend != info.blend || again.size != info.size {
            bail!(
                "the OpenXR runtime came back with another display ({} at {}x{}; the session \
                 was {} at {width}x{height}): start the run again",
                again.blend,
                again.size.0,
                again.size.1,
                info.blend
            );
        }
        reconnects.push(Reconnect {
            lost: match loss {
                Loss::Session => "session",
                Loss::Instance => "instance",
            }
            .to_owned(),
            waited_s: waited.as_secs_f64(),
        });
        let (_, defocus) = planners_for(&scene, &conditions, options.reflection, &gaze_settings)?;
        let submitted = report.as_ref().map_or(0, |r| r.frames_submitted);
        xr = XrSession::start(
            runtime,
            &context_options,
            |ctx| make_renderer(ctx, defocus.as_ref()),
            &session_options(
                Some(Continued {
                    next_index,
                    first_display_ns,
                    world_from_space: continued_from,
                    waited_ms: waited.as_millis() as u64,
                    gaze_order,
                    last_display,
                }),
                submitted,
            ),
        )
        .context("starting a new OpenXR session after the loss")?;
    }
    let wall_s = started.elapsed().as_secs_f64();
    let report = report.unwrap_or_default();
    let validation = validation.unwrap_or_default();
    let recording_closed = match sink.writer.take() {
        Some(w) => w.finish().map(drop).context("closing the recording"),
        None => Ok(()),
    };
    recording_closed?;
    sink.log.finish()?;

    let replay_check = match &options.record {
        Some(path) => Some(replay_check(
            path,
            &sink.recorded,
            scene.output.fov,
            scene.viewer.ipd_m,
        )?),
        None => None,
    };
    let headset_views = sink.views.summary(
        &scene.output.fov,
        replay_check
            .as_ref()
            .map(|r| (r.max_eye_position_m, r.max_eye_angle_deg)),
    );
    if let Some(views) = &headset_views {
        if let Some(path) = &options.record
            && let Some(warning) = views.replay_warning(&path.display().to_string())
        {
            tracing::warn!("{warning}");
        }
        if let Some(note) = views.field_note() {
            tracing::info!("{note}");
        }
    }
    let interruptions = InterruptionSummary::new(
        &report,
        reconnects,
        &sink.gaze_watch,
        &sink.events,
        options.record.is_some(),
    );
    if !interruptions.frames_add_up() {
        tracing::warn!(
            "the frames do not add up: {} handed out, {} shown, {:?} not rendered",
            interruptions.frames_waited,
            interruptions.frames_shown,
            interruptions.not_rendered
        );
    }
    let summary = RunSummary {
        vitreous_version: env!("CARGO_PKG_VERSION").into(),
        scene: options.scene.display().to_string(),
        runtime: info.runtime.clone(),
        system: info.system.clone(),
        extensions: info.extensions.clone(),
        blend_modes_offered: info
            .blend_modes_offered
            .iter()
            .map(ToString::to_string)
            .collect(),
        blend: info.blend.to_string(),
        world_behind,
        space: report.space.map(|s| format!("{s:?}")).unwrap_or_default(),
        gaze_source: report
            .gaze_source
            .map(|g| g.to_string())
            .unwrap_or_default(),
        gaze_samples: GazeSamples {
            frames: report.gaze_samples.frames,
            received: report.gaze_samples.received,
            fresh_frames: report.gaze_samples.fresh,
            out_of_order: report.gaze_samples.out_of_order,
            after_display: report.gaze_samples.after_display,
            max_ahead_ms: report.gaze_samples.max_ahead_ns as f64 / 1e6,
        },
        space_changes: report.space_changes,
        frames_abandoned: report.frames_abandoned,
        swapchain_format: format!("{format:?} (sRGB: true)"),
        states: report.states.iter().map(ToString::to_string).collect(),
        reached_focused: report.reached(State::Focused),
        end_reason: report
            .end_reason
            .map_or("unknown".into(), |r| r.to_string()),
        frames_submitted: report.frames_submitted,
        frames_skipped: report.frames_skipped,
        frames_untracked: report.frames_untracked,
        device,
        width_px: width,
        height_px: height,
        validation,
        wall_s,
        frames_per_second: records.len() as f64 / wall_s.max(1e-9),
        cpu_ms: Spread::of(records.iter().map(|r| r.cpu_ms)),
        gpu_ms: Spread::of(records.iter().filter_map(|r| r.gpu_ms)),
        readback: sink.readback.clone(),
        recorded: options.record.as_ref().map(|p| p.display().to_string()),
        recorded_samples: if options.record.is_some() {
            sink.recorded.len() as u64
        } else {
            0
        },
        replay_check,
        headset_views,
        actions_attached: report.actions_attached,
        action_profiles: report.action_profiles.clone(),
        action_syncs: report.action_syncs,
        commands: report.commands,
        conditions: conditions.iter().map(ToString::to_string).collect(),
        final_condition: sink.looks.condition().to_string(),
        final_gaze_image: sink.looks.gaze().to_string(),
        depth_submitted: report.depth_format.is_some(),
        depth_format: report
            .depth_format
            .map(|f| format!("{:?}", vk::Format::from_raw(f))),
        frames_with_depth: report.frames_with_depth,
        frames_with_focus_distance: report.frames_with_focus_distance,
        last_focus_distance_m: report.last_focus_distance_m,
        frames_with_global_dimmer: report.frames_with_global_dimmer,
        plane_detections: report.plane_detections,
        light_estimates: report.light_estimates,
        room_light: sink.room_light.clone(),
        floor_centroids,
        gaze_image_switches: sink.log.gaze_image_switches(),
        separability: sink.log.separability_summary(),
        pupil: sink.log.pupil_summary(sink.looks.pupil_source()),
        scene_edits: sink.motion.edit_count,
        moved_frames: sink.motion.moved_frames,
        inducer_computations,
        final_placement: sink.motion.final_placement(),
        interruptions,
        resident_memory,
    };
    if let Some(out) = &options.out {
        fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let json = serde_json::to_vec_pretty(&summary).context("encoding summary.json")?;
        write_atomic(&out.join("summary.json"), &json)?;
    }
    if let Some(e) = gave_up {
        return Err(e);
    }
    summary.validation.check(None)?;
    if options.readback_check {
        match &summary.readback {
            Some(c) => c.verdict(info.blend)?,
            None => bail!("readback check: no frame was read back (the session ended first)"),
        }
    }
    Ok(summary)
}

/// `result`, unless it succeeded and `cleanup` (done after it) failed: the first error is the
/// one returned; a clean-up error after a failure is logged.
fn first_error<T>(result: Result<T>, cleanup: Result<()>) -> Result<T> {
    match (result, cleanup) {
        (Ok(v), Ok(())) => Ok(v),
        (Ok(_), Err(e)) => Err(e),
        (Err(e), Ok(())) => Err(e),
        (Err(e), Err(later)) => {
            tracing::warn!("after the failure, also: {later:#}");
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_error_is_the_one_reported() {
        let lost = || -> Result<u32> { Err(anyhow::anyhow!("device lost")) };
        let cleanup = || -> Result<()> { Err(anyhow::anyhow!("releasing the swapchain images")) };
        let e = first_error(lost(), cleanup()).unwrap_err();
        assert_eq!(e.to_string(), "device lost");
        let e = first_error(Ok(3), cleanup()).unwrap_err();
        assert_eq!(e.to_string(), "releasing the swapchain images");
        assert_eq!(first_error(Ok(3), Ok(())).unwrap(), 3);
        let e = first_error(first_error(lost(), Ok(())), cleanup()).unwrap_err();
        assert_eq!(e.to_string(), "device lost");
    }
}
