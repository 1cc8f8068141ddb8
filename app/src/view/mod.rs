//! `vitreous view`: the see-through display simulated in a desktop window.
//!
//! The same frame loop as `run` and `replay` ([`vitreous_frames::frame_loop`]) drives the real renderer
//! through a third backend, [`desktop::DesktopBackend`], whose head pose comes from the mouse
//! and keys and whose gaze is synthesised from the cursor. Each finished frame's eye images
//! are read back and put in the window (left, right or both; the display's light or the
//! see-through preview) by the renderer's [`vitreous_render::Presenter`], on a Vulkan device of
//! its own.
//!
//! What needs a new renderer (a new eye image size after a resize or a change of the eyes
//! shown, a reloaded scene) ends the frame loop with the frames in flight finished, makes the
//! renderer, and runs the loop again with the same backend and sink.
//!
//! Parts: `desktop.rs` (the backend), `window.rs` (winit), `surface.rs` (the window's Vulkan
//! surface and its presenter), `input.rs` (events and keys), `script.rs` (`--script`),
//! `conditions.rs` (the keys' effect conditions), `picture.rs` (the window's picture and
//! overlay), `reload.rs` (hot reload), `playback.rs` (`--trace`), `session.rs` (the sink and
//! what the overlay shows), `cli.rs` (the options).

mod cli;
mod conditions;
mod desktop;
mod edits;
mod input;
mod picture;
mod playback;
mod reload;
mod script;
mod session;
mod surface;
mod window;

use std::cell::RefCell;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use vitreous_render::{ContextOptions, GpuContext, PlainVulkan, Reflection};

pub use cli::{ViewArgs, run};
pub use desktop::{FixationTarget, fixation_point};
pub use input::{Action, EyesShown, InputEvent, KEYS};
pub use script::{Script, ScriptError, Step};

use desktop::{DesktopBackend, Shared};
use reload::Loaded;
use session::{Request, ViewSink};
use vitreous_frames::director::Director;
use vitreous_frames::frame_loop::{self, FrameRecord};
use vitreous_frames::input_files::InputFiles;
use vitreous_frames::output::{encode_png, write_atomic};
use vitreous_frames::spread::Spread;
use vitreous_frames::validation::ValidationSummary;
use vitreous_gaze::{FilterKind, GazeOverride};
use vitreous_scene::effects::EffectSet;

/// Options of `vitreous view`.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Window size, pixels.
    pub window: (u32, u32),
    /// Eye images rendered at this fraction of their part of the window (0.25-1), scaled up.
    pub render_scale: f32,
    /// End after this many frames (None: when the window is closed or Esc pressed).
    pub frames: Option<u64>,
    /// Write the last picture shown here as PNG when the session ends.
    pub screenshot: Option<PathBuf>,
    /// Scripted input.
    pub script: Option<PathBuf>,
    /// Effects to start with, overriding the scene's.
    pub effects: Option<EffectSet>,
    /// Which eyes the window shows at the start.
    pub eyes: EyesShown,
    /// Start with the see-through preview instead of the display's light.
    pub preview: bool,
    /// Show the overlay at the start.
    pub overlay: bool,
    /// How the reflected image is drawn at the start.
    pub reflection: Reflection,
    /// Gaze filter overriding the scene's.
    pub filter: Option<FilterKind>,
    /// Turn on the Vulkan validation layers; any message fails the session.
    pub validate: bool,
    /// Pick the Vulkan device whose name contains this.
    pub device: Option<String>,
    /// Folder for summary.json.
    pub out: Option<PathBuf>,
    /// Play this trace instead of taking head and gaze from the user.
    pub trace: Option<PathBuf>,
    /// Record each frame's head pose and gaze as a trace (v1) here.
    pub record: Option<PathBuf>,
}

/// What `summary.json` of a view session holds.
#[derive(Clone, Debug, Serialize)]
pub struct ViewSummary {
    /// vitreous version.
    pub vitreous_version: String,
    /// The scene file.
    pub scene: String,
    /// Vulkan device rendering the scene.
    pub device: String,
    /// Validation results of every device used.
    pub validation: ValidationSummary,
    /// Window size at the end, pixels.
    pub window_px: (u32, u32),
    /// Frames rendered.
    pub frames: u64,
    /// Frames per second of wall-clock time.
    pub frames_per_second: f64,
    /// Wall-clock time of the session, seconds.
    pub wall_s: f64,
    /// CPU milliseconds per stereo frame.
    pub cpu_ms: Option<Spread>,
    /// GPU milliseconds per stereo frame.
    pub gpu_ms: Option<Spread>,
    /// Frames whose picture was not put on screen: the window did not ask for one (hidden or
    /// minimised), had no area, or its swapchain was out of date.
    pub frames_not_shown: u64,
    /// Times the renderer was made anew (resizes, eyes shown, reloads).
    pub renderers_made: u32,
    /// Scene reloads that took effect.
    pub reloads: u32,
    /// Scene reloads refused (the last good scene kept running), with their errors.
    pub reload_errors: Vec<String>,
    /// The effect condition shown at the end.
    pub final_condition: String,
    /// The gaze images the gaze pipeline decided (with defocus on), in order, each change
    /// once.
    pub gaze_images: Vec<String>,
    /// The screenshot written, if any.
    pub screenshot: Option<String>,
    /// The trace recorded, if any.
    pub recorded: Option<String>,
    /// Scene edits made with the keys (docs/view.md), re-registrations included.
    pub scene_edits: u64,
    /// Frames whose object or light pose differed from the previous frame's.
    pub moved_frames: u64,
    /// Where the object and light were in the last frame (`null` when nothing moved).
    pub final_placement: Option<vitreous_frames::motion_clock::FinalPlacement>,
}

impl ViewSummary {
    /// Frames, rate and timings in one line.
    pub fn summary_line(&self) -> String {
        let median =
            |s: Option<Spread>| s.map_or("n/a".to_string(), |s| format!("{:.2}", s.median_ms));
        format!(
            "viewed {} frames in a {}x{} window on {} in {:.1} s ({:.1} frames/s; median GPU {} \
             ms, CPU {} ms per stereo frame)",
            self.frames,
            self.window_px.0,
            self.window_px.1,
            self.device,
            self.wall_s,
            self.frames_per_second,
            median(self.gpu_ms),
            median(self.cpu_ms),
        )
    }
}

/// Runs a view session until the window closes, Esc, or `frames`.
pub fn view(options: &ViewOptions) -> Result<ViewSummary> {
    view_with(options, None)
}

/// Runs a view session whose conditions and gaze images `director` decides (a block of a
/// study's trials, `vitreous study run --view`); it ends once the director says so (or the
/// window closes).
pub fn view_directed(options: &ViewOptions, director: &mut dyn Director) -> Result<()> {
    view_with(options, Some(director)).map(|_| ())
}

/// [`view`], with a director deciding the looks when given.
fn view_with(options: &ViewOptions, director: Option<&mut dyn Director>) -> Result<ViewSummary> {
    let script = match &options.script {
        Some(path) => Some(Script::load(path)?),
        None => None,
    };
    let loaded = Loaded::load(&options.scene, options.effects)?;
    let mut inputs = InputFiles::new();
    inputs.add_scene(&loaded.scene, "SCENE");
    for (path, option) in [(&options.trace, "--trace"), (&options.script, "--script")] {
        if let Some(path) = path {
            inputs.add(path, option);
        }
    }
    for (path, option) in [
        (&options.screenshot, "--screenshot"),
        (&options.record, "--record"),
    ] {
        if let Some(path) = path {
            inputs.check_file(option, path)?;
        }
    }
    if let Some(out) = &options.out {
        inputs.check_folder("--out", out, &[], &|p| p == Path::new("summary.json"))?;
    }
    let (w, h) = options.window;
    if !(64..=8192).contains(&w) || !(64..=8192).contains(&h) {
        bail!("window size {w}x{h} is outside 64..=8192 pixels per side");
    }
    if !(0.25..=1.0).contains(&options.render_scale) {
        bail!(
            "--render-scale must be between 0.25 and 1, got {}",
            options.render_scale
        );
    }
    let title = format!("vitreous view: {}", options.scene.display());
    let desktop = window::DesktopWindow::open(&title, w, h)?;
    let win = desktop.window();
    let extensions = surface::surface_extensions(&win)?;
    let context_options = ContextOptions {
        validation: options.validate,
        device_name: options.device.clone(),
    };
    let present_ctx = GpuContext::new(
        &context_options,
        &mut PlainVulkan,
        &extensions,
        &[ash::khr::swapchain::NAME],
    )
    .context("setting up the Vulkan device for the window")?;
    let presenter = surface::presenter(present_ctx, win)?;

    let shared = Rc::new(RefCell::new(Shared {
        actions: VecDeque::new(),
        eyes: options.eyes,
        eye_aspect: 1.0,
        fixation: (FixationTarget::Surface, 0.0),
        resized_at: None,
        touched: Vec::new(),
        object_center_m: None,
        noise: false,
        trace: None,
        window_ready: true,
        presented: false,
    }));
    let mut backend = DesktopBackend::new(
        desktop,
        shared.clone(),
        script,
        options.frames,
        &loaded.scene,
    );
    let mut played_edits = Vec::new();
    if let Some(path) = &options.trace {
        let (samples, edits) = vitreous_trace::format::read_trace_with_edits(path)
            .with_context(|| format!("reading trace {}", path.display()))?;
        vitreous_frames::setup::ensure_samples(path, &samples, "play")?;
        backend.play(playback::Playback::new(samples));
        played_edits = edits;
    }
    let mut sink = ViewSink::new(
        options,
        loaded,
        presenter,
        shared,
        options.filter,
        GazeOverride::Auto,
    )?;
    if let Some(director) = director {
        sink.set_director(director);
    }
    sink.play_edits(played_edits);
    let mut renderer = sink.make_renderer(&context_options)?;

    let started = Instant::now();
    let mut records: Vec<FrameRecord> = Vec::new();
    loop {
        let part = frame_loop::run(&mut backend, &mut renderer, &mut sink);
        records.extend(part?);
        match sink.take_request() {
            None => break,
            Some(Request::Resize) => {
                sink.retire(&renderer);
                renderer = sink.make_renderer(&context_options)?;
            }
            Some(Request::Reload(loaded)) => match sink.adopt(*loaded, &context_options) {
                Ok(new) => {
                    sink.retire(&renderer);
                    renderer = new;
                    backend.set_scene(sink.scene());
                }
                Err(e) => sink.report_reload_error(format!("{e:#}")),
            },
        }
    }
    let wall_s = started.elapsed().as_secs_f64();
    sink.finish_recording()?;
    sink.retire(&renderer);
    let device = renderer.context().device_name.clone();
    drop(renderer);

    let screenshot = match &options.screenshot {
        Some(path) => {
            let (rgba, sw, sh) = sink
                .last_shown()
                .context("--screenshot: no picture was shown (the window never had an area)")?;
            let png = encode_png(rgba, sw, sh)?;
            write_atomic(path, &png)?;
            Some(path.display().to_string())
        }
        None => None,
    };
    let summary = ViewSummary {
        vitreous_version: env!("CARGO_PKG_VERSION").into(),
        scene: options.scene.display().to_string(),
        device,
        validation: sink.validation(),
        window_px: sink.window_size(),
        frames: records.len() as u64,
        frames_per_second: records.len() as f64 / wall_s.max(1e-9),
        wall_s,
        cpu_ms: Spread::of(records.iter().map(|r| r.cpu_ms)),
        gpu_ms: Spread::of(records.iter().filter_map(|r| r.gpu_ms)),
        frames_not_shown: sink.frames_not_shown(),
        renderers_made: sink.renderers_made(),
        reloads: sink.reloads(),
        reload_errors: sink.reload_errors().to_vec(),
        final_condition: sink.condition(),
        gaze_images: sink.gaze_images().to_vec(),
        screenshot,
        recorded: options.record.as_ref().map(|p| p.display().to_string()),
        scene_edits: sink.motion().edit_count,
        moved_frames: sink.motion().moved_frames,
        final_placement: sink.motion().final_placement(),
    };
    if let Some(out) = &options.out {
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let json = serde_json::to_vec_pretty(&summary).context("encoding summary.json")?;
        write_atomic(&out.join("summary.json"), &json)?;
    }
    summary.validation.check(None)?;
    Ok(summary)
}
