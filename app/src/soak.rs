//! `vitreous soak`: replay a trace again and again in one process, as one long session on one
//! Vulkan device and renderer (or, with `recreate`, a new device and renderer each pass), and
//! watch resident memory, the C heap and the validation layers. On a CPU device (lavapipe) GPU
//! memory is process memory, so a leaked buffer or image shows here as growth from pass to
//! pass; a pass that leaves the device dirty shows as validation messages.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde::Serialize;
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{ContextOptions, GpuContext, Reflection, Renderer, ScenePose};
use vitreous_xr::FrameInput;
use vitreous_xr::null::{NullBackend, NullConfig};

use crate::effects::EffectSet;
use crate::frame_loop::{self, FramePlan, FrameSink};
use crate::look::LookPlanner;
use crate::look::{GazeSettings, planner_for};
use crate::motion_clock::MotionClock;
use crate::render_desc;
use crate::resident::resident_kib;
use crate::scene::load_scene;
use crate::setup::{check_size, load_trace};

/// Passes left out of the memory comparison: the first passes grow the allocator's pools and
/// the driver's shader caches.
pub const WARM_UP_PASSES: usize = 2;

/// Largest growth of resident memory after warm-up that still counts as flat, percent.
pub const MAX_GROWTH_PERCENT: f64 = 1.0;

/// Options of a soak run.
#[derive(Clone, Debug)]
pub struct SoakOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Effects (default: every effect the scene's assets allow).
    pub effects: Option<EffectSet>,
    /// How long to keep replaying.
    pub duration: Duration,
    /// Eye image size, pixels.
    pub size: (u32, u32),
    /// Frames per pass, at most the scene's synthetic trace (721 frames at 60 Hz), replayed
    /// from its start each pass.
    pub frames_per_pass: u64,
    /// Read back every K-th frame (exercises the readback path).
    pub read_back_every: u64,
    /// Vulkan validation layers on (the soak's purpose; off only to tell a layer's own memory
    /// from the driver's).
    pub validation: bool,
    /// A new Vulkan device and renderer for every pass (tests teardown) instead of one for the
    /// whole run (a long session).
    pub recreate: bool,
}

/// One pass: the trace replayed once from its start.
#[derive(Clone, Debug, Serialize)]
pub struct SoakPass {
    /// Pass number, from 0.
    pub pass: usize,
    /// Frames rendered.
    pub frames: u64,
    /// Resident memory after the pass's teardown (and after the C heap gave its free pages
    /// back to the system), kibibytes.
    pub rss_kib: u64,
    /// Bytes allocated and not freed on the C heap (Rust's, the Vulkan driver's and the
    /// layers' allocations), kibibytes: growth here is a leak, not fragmentation.
    pub heap_in_use_kib: u64,
    /// Validation errors and warnings of the pass.
    pub validation_messages: u32,
    /// Frames where the scene's `[motion]` moved the object or the light (each recomputes the
    /// inducer's fields, and a live scene's caustics).
    pub moved_frames: u64,
}

impl std::fmt::Display for SoakPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "pass {} ({} frames, {} moved): resident {} KiB, heap in use {} KiB, {} validation \
             messages",
            self.pass,
            self.frames,
            self.moved_frames,
            self.rss_kib,
            self.heap_in_use_kib,
            self.validation_messages
        )
    }
}

/// The result of a soak run.
#[derive(Clone, Debug, Serialize)]
pub struct SoakReport {
    /// The scene file.
    pub scene: String,
    /// Effects rendered.
    pub effects: String,
    /// Vulkan device.
    pub device: String,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Frames over all passes.
    pub frames: u64,
    /// Every pass.
    pub passes: Vec<SoakPass>,
    /// Resident memory after the first pass past warm-up, kibibytes.
    pub rss_after_warm_up_kib: u64,
    /// Largest resident memory after a later pass, kibibytes.
    pub rss_max_kib: u64,
    /// Growth of the largest over the warm-up figure, percent.
    pub growth_percent: f64,
    /// Validation messages over all passes.
    pub validation_messages: u32,
    /// The first validation messages' texts.
    pub first_messages: Vec<String>,
}

impl SoakReport {
    /// Whether memory stayed flat and validation was silent.
    pub fn passed(&self) -> bool {
        self.passes.len() > WARM_UP_PASSES
            && self.growth_percent <= MAX_GROWTH_PERCENT
            && self.validation_messages == 0
    }

    /// The result in one line.
    pub fn summary_line(&self) -> String {
        format!(
            "soak of {} ({}) on {}: {} passes, {} frames in {:.0} s; resident memory {} KiB \
             after warm-up, at most {} KiB later ({:+.2} %, limit {} %); {} validation messages",
            self.scene,
            self.effects,
            self.device,
            self.passes.len(),
            self.frames,
            self.wall_s,
            self.rss_after_warm_up_kib,
            self.rss_max_kib,
            self.growth_percent,
            MAX_GROWTH_PERCENT,
            self.validation_messages
        )
    }

    /// An error saying why the soak failed, unless it [`passed`](Self::passed).
    pub fn verdict(&self) -> Result<()> {
        if self.passed() {
            return Ok(());
        }
        bail!(
            "soak failed: {} passes (more than {} needed), memory growth {:.2} %, {} validation \
             messages{}",
            self.passes.len(),
            WARM_UP_PASSES,
            self.growth_percent,
            self.validation_messages,
            self.first_messages
                .first()
                .map(|m| format!(", first: {m}"))
                .unwrap_or_default()
        )
    }
}

/// Renders every frame at the scene's pose for its time, reads back some, keeps nothing.
struct Discard {
    planner: LookPlanner,
    read_back_every: u64,
    motion: MotionClock,
}

impl FrameSink for Discard {
    fn pose(&mut self, input: &FrameInput) -> Option<ScenePose> {
        self.motion.pose(input.time_ns, &mut self.planner)
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let read = input.index.is_multiple_of(self.read_back_every);
        FramePlan {
            look: self.planner.plan(input).0,
            want: Want {
                eyes: read,
                world: read,
            },
        }
    }

    fn finished(&mut self, _input: &FrameInput, _result: &FrameResult) -> Result<()> {
        Ok(())
    }

    fn stop_requested(&self) -> bool {
        crate::interrupt::requested()
    }
}

/// The C heap's statistics (glibc `struct mallinfo2`).
#[repr(C)]
#[derive(Default)]
struct MallInfo2 {
    arena: usize,
    ordblks: usize,
    smblks: usize,
    hblks: usize,
    hblkhd: usize,
    usmblks: usize,
    fsmblks: usize,
    uordblks: usize,
    fordblks: usize,
    keepcost: usize,
}

unsafe extern "C" {
    /// glibc: statistics of the main and thread heaps.
    fn mallinfo2() -> MallInfo2;
    /// glibc: gives free heap pages back to the system; returns 1 if any were.
    fn malloc_trim(pad: usize) -> i32;
}

/// Gives free C-heap pages back to the system, then returns the bytes still allocated
/// (ordinary and mmap'd blocks), kibibytes.
pub fn trim_heap_and_measure_kib() -> u64 {
    // SAFETY: both are plain glibc calls without preconditions; `mallinfo2` returns its
    // struct by value, laid out as `MallInfo2` (glibc >= 2.33; Debian 12 has 2.36).
    let info = unsafe {
        malloc_trim(0);
        mallinfo2()
    };
    ((info.uordblks + info.hblkhd) / 1024) as u64
}

/// Runs the soak; `progress` is called after every pass.
pub fn soak(options: &SoakOptions, mut progress: impl FnMut(&SoakPass)) -> Result<SoakReport> {
    let mut scene = load_scene(&options.scene)?;
    let effects = options.effects.unwrap_or(scene.effects);
    effects.ensure_implemented()?;
    if effects.caustics {
        scene.load_caustics()?;
    }
    check_size(options.size.0, options.size.1)?;
    if options.frames_per_pass == 0 || options.read_back_every == 0 {
        bail!("frames per pass and the readback interval must be at least 1");
    }
    let (samples, _) = load_trace(&scene, None)?;
    let signals = crate::interrupt::watch();

    let started = Instant::now();
    let mut passes = Vec::new();
    let mut device = String::new();
    let mut first_messages = Vec::new();
    let mut current: Option<(Renderer, LookPlanner)> = None;
    let mut messages_before = 0;
    while passes.is_empty() || started.elapsed() < options.duration {
        if signals && crate::interrupt::requested() {
            break;
        }
        if options.recreate {
            current = None; // the old renderer and device go before the new ones are made
        }
        let (renderer, planner) = match &mut current {
            Some(made) => made,
            None => {
                let ctx = GpuContext::headless(&ContextOptions {
                    validation: options.validation,
                    device_name: None,
                })
                .context("setting up the Vulkan device")?;
                device.clone_from(&ctx.device_name);
                let (planner, defocus) = planner_for(
                    &scene,
                    &effects,
                    Reflection::Phong,
                    &GazeSettings::default(),
                )?;
                let mut renderer = Renderer::new(
                    ctx,
                    &render_desc::scene_desc(&scene, defocus.as_ref()),
                    options.size.0,
                    options.size.1,
                )
                .context("preparing the renderer")?;
                render_desc::enable_live_caustics(&mut renderer, &scene, effects.caustics)
                    .context("preparing live caustics")?;
                messages_before = 0;
                current.insert((renderer, planner))
            }
        };
        let mut backend = NullBackend::new(
            samples.clone(),
            NullConfig {
                frame_rate_hz: 60.0,
                max_frames: Some(options.frames_per_pass),
                fov: scene.output.fov,
                ipd_m: scene.viewer.ipd_m,
                at_samples: false,
            },
        )?;
        let mut sink = Discard {
            planner: planner.restarted(),
            read_back_every: options.read_back_every,
            motion: MotionClock::new(&scene),
        };
        let records = frame_loop::run(&mut backend, renderer, &mut sink)?;
        let log = renderer.context().validation();
        let messages_now = log.errors() + log.warnings();
        let messages = messages_now - messages_before;
        messages_before = messages_now;
        if messages > 0 && first_messages.len() < 5 {
            first_messages.extend(log.messages().into_iter().take(5 - first_messages.len()));
        }
        if options.recreate {
            current = None;
        }
        let heap_in_use_kib = trim_heap_and_measure_kib();
        let pass = SoakPass {
            pass: passes.len(),
            frames: records.len() as u64,
            heap_in_use_kib,
            rss_kib: resident_kib()?,
            validation_messages: messages,
            moved_frames: sink.motion.moved_frames,
        };
        progress(&pass);
        passes.push(pass);
    }
    drop(current);

    let settled: Vec<u64> = passes
        .iter()
        .skip(WARM_UP_PASSES)
        .map(|p| p.rss_kib)
        .collect();
    let rss_after_warm_up_kib = settled.first().copied().unwrap_or(0);
    let rss_max_kib = settled.iter().copied().max().unwrap_or(0);
    let growth_percent = if rss_after_warm_up_kib > 0 {
        (rss_max_kib as f64 / rss_after_warm_up_kib as f64 - 1.0) * 100.0
    } else {
        0.0
    };
    Ok(SoakReport {
        scene: options.scene.display().to_string(),
        effects: effects.to_string(),
        device,
        wall_s: started.elapsed().as_secs_f64(),
        frames: passes.iter().map(|p| p.frames).sum(),
        validation_messages: passes.iter().map(|p| p.validation_messages).sum(),
        passes,
        rss_after_warm_up_kib,
        rss_max_kib,
        growth_percent,
        first_messages,
    })
}
