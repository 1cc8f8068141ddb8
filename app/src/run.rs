//! `vitreous run`: the frame loop on a live OpenXR runtime (a headset, or Monado in CI).
//!
//! Set-up order is dictated by XR_KHR_vulkan_enable2: the OpenXR runtime first, then the
//! renderer's Vulkan instance and device created *through* it ([`XrDeviceCreator`]), then the
//! session on that device, whose swapchain images the renderer draws into. Teardown is the
//! reverse: the renderer lets go of the swapchain images, the session goes, then the device,
//! then the OpenXR instance.
//!
//! The loop is the shared one ([`crate::frame_loop`]) plus one hook: each frame is drawn where
//! [`Backend::frame_target`] says (the renderer's own images or swapchain image `i`, and depth
//! swapchain image `j` when depth is submitted).
//!
//! Live actions (controller buttons, see `vitreous_xr::openxr::actions`) re-register the scene
//! in the session itself; the commands that change the look reach the sink through
//! [`Session::take_commands`](vitreous_xr::openxr::Session::take_commands) and are applied
//! by [`LiveLooks`]: the next effect condition among those this build implements, and the
//! forced gaze image (surface, refracted, auto).

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use vitreous_render::context::API_VERSION;
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{
    ContextOptions, DeviceCreator, GpuContext, Reflection, RenderError, Renderer,
};
use vitreous_xr::null::{NullBackend, NullConfig};
use vitreous_xr::openxr::ash::{self, vk};
use vitreous_xr::openxr::{
    Blend, Command, DepthOptions, OpenXrOptions, Runtime, SessionOptions, SessionReport, State,
    VulkanHandles,
};
use vitreous_xr::trace::{TraceSample, TraceWriter, read_trace};
use vitreous_xr::{Backend, FrameInput, GazeRay, GazeSample, Pose};

use crate::defocus::LookPlanner;
use crate::effects::EffectSet;
use crate::frame_loop::{self, FramePlan, FrameSink};
use crate::gaze::GazeOverride;
use crate::output::write_atomic;
use crate::replay::{GazeSettings, planners_for};
use crate::replay::{Spread, ValidationSummary};
use crate::scene::{Scene, load_scene};
use crate::views;

/// Options of `vitreous run`.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// End the session after this many frames (None: until the runtime or Ctrl-C ends it).
    pub frames: Option<u64>,
    /// Gaze replayed from this trace when the headset has no eye tracker.
    pub gaze_trace: Option<PathBuf>,
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
    /// Where summary.json goes (None: not written).
    pub out: Option<PathBuf>,
}

/// What the readback of a submitted swapchain image showed.
#[derive(Clone, Debug, Serialize)]
pub struct ReadbackCheck {
    /// Index of the frame read back.
    pub frame: u64,
    /// Pixels (both eyes) inside the object's projected disc.
    pub region_px: u64,
    /// Of those, pixels where the submitted image differs from the real world alone (or from
    /// black, on a see-through display) by more than [`LIT_THRESHOLD`] in some channel.
    pub object_px: u64,
    /// `object_px / region_px`.
    pub object_fraction: f64,
    /// Mean sRGB value (0-255) of the submitted image inside the region.
    pub mean_value: f64,
    /// Whether the check passed (`object_fraction >= MIN_OBJECT_FRACTION`).
    pub passed: bool,
}

/// How different (sRGB steps) a pixel must be to count as the object's.
pub const LIT_THRESHOLD: u8 = 8;
/// Share of the object's region that must show it.
pub const MIN_OBJECT_FRACTION: f64 = 0.2;

/// How well a replay of the recording reproduces the session's views.
#[derive(Clone, Debug, Serialize)]
pub struct ReplayCheck {
    /// Samples in the recording.
    pub samples: u64,
    /// Replay frames compared.
    pub frames: u64,
    /// Largest head position difference, metres.
    pub max_head_position_m: f32,
    /// Largest head orientation difference, degrees.
    pub max_head_angle_deg: f32,
    /// Largest eye position difference, metres (the replay puts eyes at the recorded gaze
    /// origins, the runtime at its own eye positions: both should agree with the IPD).
    pub max_eye_position_m: f32,
}

/// What `vitreous run` reports (and writes to summary.json).
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    /// vitreous version.
    pub vitreous_version: String,
    /// The scene file.
    pub scene: String,
    /// OpenXR runtime name and version.
    pub runtime: String,
    /// The headset's name.
    pub system: String,
    /// Enabled OpenXR extensions.
    pub extensions: Vec<String>,
    /// Blend modes offered.
    pub blend_modes_offered: Vec<String>,
    /// The blend mode used.
    pub blend: String,
    /// Whether the real world was drawn behind the glass (opaque displays).
    pub world_behind: bool,
    /// The reference space.
    pub space: String,
    /// The gaze source.
    pub gaze_source: String,
    /// Swapchain format and whether it encodes sRGB.
    pub swapchain_format: String,
    /// Session states reached, in order.
    pub states: Vec<String>,
    /// Whether FOCUSED was reached.
    pub reached_focused: bool,
    /// Why the session ended.
    pub end_reason: String,
    /// Frames submitted with a projection layer.
    pub frames_submitted: u64,
    /// Frames the runtime said not to render.
    pub frames_skipped: u64,
    /// Frames whose head pose was not fully tracked.
    pub frames_untracked: u64,
    /// Vulkan device and driver.
    pub device: String,
    /// Eye image size, pixels.
    pub width_px: u32,
    /// Eye image size, pixels.
    pub height_px: u32,
    /// Vulkan validation results.
    pub validation: ValidationSummary,
    /// Wall-clock time of the session's frame loop, seconds.
    pub wall_s: f64,
    /// Frames per second.
    pub frames_per_second: f64,
    /// CPU milliseconds per frame.
    pub cpu_ms: Option<Spread>,
    /// GPU milliseconds per frame.
    pub gpu_ms: Option<Spread>,
    /// The readback check, when asked for.
    pub readback: Option<ReadbackCheck>,
    /// The recording, when asked for.
    pub recorded: Option<String>,
    /// Samples recorded.
    pub recorded_samples: u64,
    /// Replay of the recording against the session's views, when recorded.
    pub replay_check: Option<ReplayCheck>,
    /// The controller action set was created and attached.
    pub actions_attached: bool,
    /// Interaction profiles whose bindings the runtime accepted.
    pub action_profiles: Vec<String>,
    /// xrSyncActions calls (one per FOCUSED frame).
    pub action_syncs: u64,
    /// Commands the live actions gave.
    pub commands: u64,
    /// The effect conditions the live actions cycle through, the first one the start.
    pub conditions: Vec<String>,
    /// The effect condition at the end.
    pub final_condition: String,
    /// The forced gaze image at the end (`auto`: the tracker decides).
    pub final_gaze_image: String,
    /// Whether depth was submitted (XR_KHR_composition_layer_depth).
    pub depth_submitted: bool,
    /// The depth swapchain's format, when depth was submitted.
    pub depth_format: Option<String>,
    /// Frames submitted with depth.
    pub frames_with_depth: u64,
}

/// The paper's study conditions, in the order the live action cycles through them (after the
/// run's own effect set): O2 (none), O3 (defocus), O4 (disparity), O5 (disparity + defocus),
/// b (caustics), c (inducer + caustics).
pub const STUDY_CONDITIONS: [&str; 6] = ["O2", "O3", "O4", "O5", "b", "c"];

/// The effect conditions `vitreous run` cycles through: `start` first, then the study
/// conditions, each once, keeping only those this build implements and (for caustics) those
/// whose bake is loaded.
pub fn live_conditions(start: EffectSet, caustics_loaded: bool) -> Vec<EffectSet> {
    let mut out = vec![start];
    for name in STUDY_CONDITIONS {
        let set = EffectSet::parse(name).expect("study condition names parse");
        if !out.contains(&set)
            && set.ensure_implemented().is_ok()
            && (!set.caustics || caustics_loaded)
        {
            out.push(set);
        }
    }
    out
}

/// The looks the live actions switch between: a look planner per effect condition (all fed
/// every frame, so switching keeps the gaze filters warm) and the forced gaze image.
pub struct LiveLooks {
    /// Each condition and its planner.
    conditions: Vec<(EffectSet, LookPlanner)>,
    /// Index of the condition shown.
    current: usize,
    /// The forced gaze image.
    gaze: GazeOverride,
}

impl LiveLooks {
    /// Starts at the first condition with gaze image `gaze`, applied to every planner.
    pub fn new(conditions: Vec<(EffectSet, LookPlanner)>, gaze: GazeOverride) -> LiveLooks {
        assert!(!conditions.is_empty(), "at least one condition");
        let mut looks = LiveLooks {
            conditions,
            current: 0,
            gaze,
        };
        looks.set_gaze(gaze);
        looks
    }

    /// The condition shown.
    pub fn condition(&self) -> EffectSet {
        self.conditions[self.current].0
    }

    /// The forced gaze image.
    pub fn gaze(&self) -> GazeOverride {
        self.gaze
    }

    fn set_gaze(&mut self, gaze: GazeOverride) {
        self.gaze = gaze;
        for (_, planner) in &mut self.conditions {
            planner.set_gaze_override(gaze);
        }
    }

    /// Applies a live command; says what changed (None for commands the session handles:
    /// Nudge and Rotate).
    pub fn apply(&mut self, command: Command) -> Option<String> {
        match command {
            Command::NextCondition => {
                self.current = (self.current + 1) % self.conditions.len();
                Some(format!(
                    "effect condition now {} ({} of {})",
                    self.condition(),
                    self.current + 1,
                    self.conditions.len()
                ))
            }
            Command::NextGazeImage => {
                let next = match self.gaze {
                    GazeOverride::Auto => GazeOverride::Surface,
                    GazeOverride::Surface => GazeOverride::Refracted,
                    GazeOverride::Refracted => GazeOverride::Auto,
                };
                self.set_gaze(next);
                Some(format!(
                    "gaze image now {next}{}",
                    if self.condition().defocus {
                        ""
                    } else {
                        " (shown once a condition with defocus is on)"
                    }
                ))
            }
            Command::Nudge(_) | Command::Rotate(_) => None,
        }
    }

    /// This frame's look: every planner sees the frame, the current one's look is used.
    pub fn plan(&mut self, input: &FrameInput) -> vitreous_render::Look {
        let mut look = None;
        for (i, (_, planner)) in self.conditions.iter_mut().enumerate() {
            let l = planner.plan(input).0;
            if i == self.current {
                look = Some(l);
            }
        }
        look.expect("current condition exists")
    }
}

/// Creates the renderer's Vulkan instance and device through the OpenXR runtime.
pub struct XrDeviceCreator<'a> {
    /// The runtime.
    pub runtime: &'a mut Runtime,
}

fn creation(e: impl std::fmt::Display) -> RenderError {
    RenderError::Creation(e.to_string())
}

impl DeviceCreator for XrDeviceCreator<'_> {
    unsafe fn create_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance, RenderError> {
        self.runtime
            .check_vulkan_version(API_VERSION)
            .map_err(creation)?;
        unsafe { self.runtime.create_vulkan_instance(entry, info) }.map_err(creation)
    }

    fn pick_physical_device(
        &mut self,
        instance: &ash::Instance,
        _options: &ContextOptions,
    ) -> Result<vk::PhysicalDevice, RenderError> {
        // The headset decides: it is driven by one GPU.
        self.runtime
            .vulkan_physical_device(instance)
            .map_err(creation)
    }

    unsafe fn create_device(
        &mut self,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device, RenderError> {
        let entry = unsafe { ash::Entry::load() }?;
        unsafe {
            self.runtime
                .create_vulkan_device(&entry, instance, physical, info)
        }
        .map_err(creation)
    }
}

/// Records frames and checks a readback.
struct RunSink {
    /// Decides each frame's look (effect condition, gaze-dependent defocus).
    looks: LiveLooks,
    /// Live commands from the session.
    commands: Option<std::sync::mpsc::Receiver<Command>>,
    /// Frame to read back, if any.
    readback_frame: Option<u64>,
    /// The scene's object, for the region check.
    object_center_m: glam::Vec3,
    /// The object's radius.
    object_radius_m: f32,
    /// Whether the world is drawn behind.
    world_behind: bool,
    /// The readback result.
    readback: Option<ReadbackCheck>,
    /// Where head pose and gaze are recorded, if asked.
    writer: Option<TraceWriter<vitreous_xr::trace::AtomicFile>>,
    /// Every frame's input, for the replay check.
    recorded: Vec<FrameInput>,
}

impl FrameSink for RunSink {
    fn started(&mut self, input: &FrameInput) -> Result<()> {
        if let Some(w) = &mut self.writer {
            w.write(&trace_sample(input))
                .context("recording the trace")?;
        }
        self.recorded.push(input.clone());
        Ok(())
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let read = self.readback_frame == Some(input.index);
        if let Some(rx) = &self.commands {
            for command in rx.try_iter() {
                if let Some(change) = self.looks.apply(command) {
                    tracing::info!("frame {}: {change}", input.index);
                }
            }
        }
        FramePlan {
            look: self.looks.plan(input),
            want: Want {
                eyes: read,
                world: read,
            },
        }
    }

    fn finished(&mut self, input: &FrameInput, result: &FrameResult) -> Result<()> {
        if let Some(rb) = &result.readback {
            self.readback = Some(check_readback(
                input,
                rb,
                self.object_center_m,
                self.object_radius_m,
                self.world_behind,
            ));
        }
        Ok(())
    }
}

/// Counts the object's pixels in a readback of both eyes (see [`ReadbackCheck`]).
fn check_readback(
    input: &FrameInput,
    rb: &vitreous_render::Readback,
    center_m: glam::Vec3,
    radius_m: f32,
    world_behind: bool,
) -> ReadbackCheck {
    let (w, h) = (rb.width as usize, rb.height as usize);
    let (mut region, mut object, mut sum) = (0u64, 0u64, 0f64);
    for eye in 0..2 {
        let view = &input.views[eye];
        // The object's centre in the eye frame, projected with the eye's (asymmetric) fov.
        let p = view.pose.orientation.conjugate() * (center_m - view.pose.position);
        if p.z >= -1e-4 {
            continue;
        }
        let (l, r) = (
            view.fov.angle_left_rad.tan(),
            view.fov.angle_right_rad.tan(),
        );
        let (d, u) = (view.fov.angle_down_rad.tan(), view.fov.angle_up_rad.tan());
        let (x, y) = (p.x / -p.z, p.y / -p.z);
        let px = (x - l) / (r - l) * w as f32;
        let py = (u - y) / (u - d) * h as f32;
        let rad = (radius_m / p.length()).min(1.0).asin().tan();
        let (rx, ry) = (rad / (r - l) * w as f32, rad / (u - d) * h as f32);
        let image = &rb.eyes[eye];
        let world = rb.world.as_ref().map(|wv| &wv[eye]);
        for row in 0..h {
            for col in 0..w {
                let dx = (col as f32 + 0.5 - px) / rx;
                let dy = (row as f32 + 0.5 - py) / ry;
                if dx * dx + dy * dy > 1.0 {
                    continue;
                }
                region += 1;
                let i = (row * w + col) * 4;
                let got = &image[i..i + 3];
                sum += got.iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0;
                let lit = match (world_behind, world) {
                    (true, Some(wv)) => got
                        .iter()
                        .zip(&wv[i..i + 3])
                        .any(|(&a, &b)| a.abs_diff(b) > LIT_THRESHOLD),
                    _ => got.iter().any(|&a| a > LIT_THRESHOLD),
                };
                if lit {
                    object += 1;
                }
            }
        }
    }
    let fraction = if region == 0 {
        0.0
    } else {
        object as f64 / region as f64
    };
    ReadbackCheck {
        frame: input.index,
        region_px: region,
        object_px: object,
        object_fraction: fraction,
        mean_value: if region == 0 {
            0.0
        } else {
            sum / region as f64
        },
        passed: region > 0 && fraction >= MIN_OBJECT_FRACTION,
    }
}

/// A trace sample for a frame: its head pose and gaze (an invalid gaze at the frame time when
/// there is none).
fn trace_sample(input: &FrameInput) -> TraceSample {
    TraceSample {
        time_ns: input.time_ns,
        head: input.head,
        gaze: input.gaze.unwrap_or(GazeSample {
            sample_time_ns: input.time_ns,
            left: GazeRay::INVALID,
            right: GazeRay::INVALID,
            combined: None,
            fixation: None,
        }),
    }
}

/// Runs the scene on the OpenXR runtime. Fails with a clear message when there is no runtime,
/// no Vulkan support, a validation message, or a failed readback check.
pub fn run(options: &RunOptions) -> Result<RunSummary> {
    let mut scene = load_scene(&options.scene)?;
    let effects = options.effects.unwrap_or(scene.effects);
    effects.ensure_implemented()?;
    if effects.caustics {
        scene.load_caustics()?;
    }
    // The caustic conditions are offered live only with the scene's bake loaded.
    let caustics_loaded = effects.caustics
        || (scene.caustics.bake.is_some()
            && EffectSet::IMPLEMENTED.caustics
            && scene
                .load_caustics()
                .map_err(|e| tracing::warn!("caustic conditions not offered live: {e}"))
                .is_ok());
    let conditions = live_conditions(effects, caustics_loaded);
    tracing::info!(
        "effect conditions (menu on the right controller): {}",
        conditions
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(" > ")
    );
    let mut runtime = Runtime::new(&OpenXrOptions {
        blend: options.blend,
        validation: options.validate,
        size: options.size,
    })
    .context("starting OpenXR")?;
    let info = runtime.info().clone();
    let (width, height) = info.size;
    tracing::info!(
        "eye images {width}x{height} (recommended {}x{}, max {}x{})",
        info.recommended_size.0,
        info.recommended_size.1,
        info.max_size.0,
        info.max_size.1
    );
    let ctx = GpuContext::new(
        &ContextOptions {
            validation: options.validate,
            device_name: None,
        },
        &mut XrDeviceCreator {
            runtime: &mut runtime,
        },
        &[],
        &[],
    )
    .context("setting up the Vulkan device through the OpenXR runtime")?;
    let device = format!("{} ({})", ctx.device_name, ctx.driver);
    let handles = VulkanHandles {
        instance: ctx.instance.handle(),
        physical: ctx.physical,
        device: ctx.device.handle(),
        queue_family: ctx.queue_family,
        queue_index: 0,
    };
    let (planners, defocus) = planners_for(
        &scene,
        &conditions,
        options.reflection,
        &GazeSettings::default(),
    )?;
    let mut renderer = Renderer::new(
        ctx,
        &views::scene_desc(&scene, defocus.as_ref()),
        width,
        height,
    )
    .context("preparing the renderer")?;
    drop(defocus);
    let (mut session, images) = unsafe {
        runtime.start(
            handles,
            &SessionOptions {
                max_frames: options.frames,
                gaze_trace: options.gaze_trace.clone(),
                scene_origin: None,
                viewer_position_m: scene.viewer.head_position_m,
                handle_ctrl_c: true,
                depth: Some(DepthOptions {
                    format: Renderer::DEPTH_FORMAT,
                    near_m: vitreous_render::camera::NEAR_M,
                    far_m: vitreous_render::camera::FAR_M,
                }),
            },
        )
    }
    .context("starting the OpenXR session")?;
    if !images.srgb {
        bail!(
            "the runtime offers only UNORM swapchain formats; vitreous renders into sRGB images \
             only for now (VkFormat {:?})",
            images.format
        );
    }
    unsafe {
        renderer.attach_external_with_depth(&images.images, images.format, &images.depth_images)
    }
    .context("using the swapchain images")?;

    let writer = match &options.record {
        Some(path) => Some(
            TraceWriter::create(path).with_context(|| format!("creating {}", path.display()))?,
        ),
        None => None,
    };
    let world_behind = info.blend.needs_world_behind();
    let mut sink = RunSink {
        looks: LiveLooks::new(
            conditions.iter().copied().zip(planners).collect(),
            scene.gaze.image,
        ),
        commands: session.take_commands(),
        // Late enough for the pipelines to be warm and the head to have moved.
        readback_frame: options
            .readback_check
            .then(|| options.frames.map_or(10, |n| (n / 2).min(10)).max(1) - 1),
        object_center_m: scene.object.center_m,
        object_radius_m: scene.object.radius_m,
        world_behind,
        readback: None,
        writer,
        recorded: Vec::new(),
    };
    let started = Instant::now();
    let result = frame_loop::run(&mut session, &mut renderer, &mut sink);
    let wall_s = started.elapsed().as_secs_f64();
    // Teardown order: images out of the renderer, then the session, then (at the end) the
    // device with the renderer, then the OpenXR instance.
    renderer
        .detach_external()
        .context("releasing the swapchain images")?;
    let report: SessionReport = session.report().clone();
    drop(session);
    if let Some(w) = sink.writer.take() {
        w.finish().context("closing the recording")?;
    }
    let records = result?;

    let v = renderer.context().validation();
    let validation = ValidationSummary {
        enabled: renderer.context().validation_enabled(),
        warnings: v.warnings(),
        errors: v.errors(),
        messages: v.messages(),
    };
    drop(renderer);
    drop(runtime);

    let replay_check = match &options.record {
        Some(path) => Some(replay_check(path, &sink.recorded, &scene)?),
        None => None,
    };
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
        swapchain_format: format!("{:?} (sRGB: {})", images.format, images.srgb),
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
    };
    if let Some(out) = &options.out {
        fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let json = serde_json::to_vec_pretty(&summary).context("encoding summary.json")?;
        write_atomic(&out.join("summary.json"), &json)?;
    }
    if summary.validation.errors + summary.validation.warnings > 0 {
        bail!(
            "the Vulkan validation layers reported {} errors and {} warnings, first: {}",
            summary.validation.errors,
            summary.validation.warnings,
            summary
                .validation
                .messages
                .first()
                .map(String::as_str)
                .unwrap_or("")
        );
    }
    if options.readback_check {
        match &summary.readback {
            Some(c) if c.passed => {}
            Some(c) => bail!(
                "readback check failed: frame {} shows the object in {:.1} % of its region \
                 ({} of {} px); expected at least {:.0} %",
                c.frame,
                c.object_fraction * 100.0,
                c.object_px,
                c.region_px,
                MIN_OBJECT_FRACTION * 100.0
            ),
            None => bail!("readback check: no frame was read back (the session ended first)"),
        }
    }
    Ok(summary)
}

/// Replays the recording with the null backend at the session's mean frame rate and compares
/// its views with the session's, interpolated at the replay's frame times.
fn replay_check(path: &Path, session: &[FrameInput], scene: &Scene) -> Result<ReplayCheck> {
    let samples = read_trace(path).with_context(|| format!("reading back {}", path.display()))?;
    if samples.len() < 2 || session.len() < 2 {
        bail!("the recording {} has fewer than 2 samples", path.display());
    }
    let span_ns = session[session.len() - 1].time_ns - session[0].time_ns;
    let rate_hz = (session.len() - 1) as f64 * 1e9 / span_ns as f64;
    let mut null = NullBackend::new(
        samples.clone(),
        NullConfig {
            frame_rate_hz: rate_hz,
            max_frames: None,
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
        },
    )?;
    let (mut frames, mut max_pos, mut max_ang, mut max_eye) = (0u64, 0f32, 0f32, 0f32);
    while let Some(frame) = null.wait_frame()? {
        null.end_frame(&frame)?;
        let t = frame.time_ns;
        let Some(b) = session.iter().position(|s| s.time_ns >= t) else {
            break;
        };
        let expected = if session[b].time_ns == t || b == 0 {
            session[b].clone()
        } else {
            let a = &session[b - 1];
            let f = (t - a.time_ns) as f32 / (session[b].time_ns - a.time_ns) as f32;
            let lerp = |p: &Pose, q: &Pose| Pose {
                position: p.position.lerp(q.position, f),
                orientation: p.orientation.slerp(q.orientation, f),
            };
            let mut e = a.clone();
            e.head = lerp(&a.head, &session[b].head);
            for eye in 0..2 {
                e.views[eye].pose = lerp(&a.views[eye].pose, &session[b].views[eye].pose);
            }
            e
        };
        frames += 1;
        max_pos = max_pos.max((frame.head.position - expected.head.position).length());
        max_ang = max_ang.max(
            frame
                .head
                .orientation
                .angle_between(expected.head.orientation)
                .to_degrees(),
        );
        for eye in 0..2 {
            max_eye = max_eye
                .max((frame.views[eye].pose.position - expected.views[eye].pose.position).length());
        }
    }
    Ok(ReplayCheck {
        samples: samples.len() as u64,
        frames,
        max_head_position_m: max_pos,
        max_head_angle_deg: max_ang,
        max_eye_position_m: max_eye,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_xr::{EyeView, Fov};

    fn frame() -> FrameInput {
        let view = EyeView {
            pose: Pose::IDENTITY,
            fov: Fov::symmetric(1.0, 1.0),
        };
        FrameInput {
            index: 0,
            time_ns: 5,
            head: Pose::IDENTITY,
            views: [view, view],
            gaze: None,
        }
    }

    #[test]
    fn a_frame_without_gaze_records_an_invalid_gaze_at_its_time() {
        let s = trace_sample(&frame());
        assert_eq!(s.gaze.sample_time_ns, 5);
        assert!(!s.gaze.left.valid && !s.gaze.right.valid);
    }

    #[test]
    fn readback_check_counts_lit_pixels_in_the_object_disc() {
        let (w, h) = (32u32, 32u32);
        let mut lit = vec![0u8; (w * h * 4) as usize];
        for px in lit.chunks_exact_mut(4) {
            px.copy_from_slice(&[200, 200, 200, 255]);
        }
        let dark = vec![0u8; (w * h * 4) as usize];
        let rb = |eyes: [Vec<u8>; 2]| vitreous_render::Readback {
            width: w,
            height: h,
            eyes,
            world: None,
        };
        let center = glam::Vec3::new(0.0, 0.0, -1.0);
        let c = check_readback(&frame(), &rb([lit.clone(), lit]), center, 0.1, false);
        assert!(
            c.passed && c.region_px > 0 && c.object_px == c.region_px,
            "{c:?}"
        );
        let c = check_readback(&frame(), &rb([dark.clone(), dark]), center, 0.1, false);
        assert!(!c.passed && c.object_px == 0);
        // Behind the viewer: no region, no pass.
        let c = check_readback(
            &frame(),
            &rb([vec![0; (w * h * 4) as usize], vec![0; (w * h * 4) as usize]]),
            glam::Vec3::new(0.0, 0.0, 1.0),
            0.1,
            false,
        );
        assert!(!c.passed && c.region_px == 0);
    }
    #[test]
    fn live_conditions_start_with_the_runs_own_and_skip_unloaded_caustics() {
        let defocus = EffectSet::parse("defocus").unwrap();
        let c = live_conditions(defocus, false);
        assert_eq!(c[0], defocus);
        assert_eq!(c.iter().filter(|&&e| e == defocus).count(), 1);
        assert!(
            c.iter()
                .all(|e| !e.caustics && e.ensure_implemented().is_ok())
        );
        assert!(c.contains(&EffectSet::NONE));
        assert!(c.contains(&EffectSet::parse("O5").unwrap()));
        let with = live_conditions(EffectSet::NONE, true);
        assert!(with.contains(&EffectSet::parse("c").unwrap()));
    }

    #[test]
    fn live_commands_cycle_the_condition_and_the_gaze_image() {
        let sets = [EffectSet::NONE, EffectSet::parse("disparity").unwrap()];
        let planners = sets
            .iter()
            .map(|e| LookPlanner::new(views::look(e, Reflection::default()), None))
            .collect::<Vec<_>>();
        let mut looks = LiveLooks::new(
            sets.iter().copied().zip(planners).collect(),
            GazeOverride::Auto,
        );
        assert!(!looks.plan(&frame()).disparity);
        assert!(looks.apply(Command::NextCondition).is_some());
        assert_eq!(looks.condition(), sets[1]);
        assert!(looks.plan(&frame()).disparity);
        looks.apply(Command::NextCondition);
        assert_eq!(looks.condition(), sets[0], "wraps round");
        let mut seen = Vec::new();
        for _ in 0..3 {
            looks.apply(Command::NextGazeImage);
            seen.push(looks.gaze());
        }
        assert_eq!(
            seen,
            [
                GazeOverride::Surface,
                GazeOverride::Refracted,
                GazeOverride::Auto
            ]
        );
        // Re-registration is the session's: nothing changes here.
        assert!(looks.apply(Command::Rotate(0.1)).is_none());
        assert_eq!(looks.condition(), sets[0]);
    }
}
