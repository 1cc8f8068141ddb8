//! The soak (`vitreous soak`): replay a trace again and again in one process, as one long
//! session on one Vulkan device and renderer (or, with `recreate`, a new device and renderer
//! each pass), and watch resident memory, the C heap and the validation layers. On a CPU device (lavapipe) GPU
//! memory is process memory, so a leaked buffer or image shows here as growth from pass to
//! pass; a pass that leaves the device dirty shows as validation messages.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde::Serialize;
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{ContextOptions, GpuContext, Reflection, Renderer, ScenePose};
use vitreous_trace::FrameInput;
use vitreous_xr::null::{NullBackend, NullConfig};

use vitreous_scene::effects::EffectSet;
use vitreous_scene::{CausticsMode, load_scene};

use crate::frame_loop::{self, FramePlan, FrameSink};
use crate::input_files::InputFiles;
use crate::look::LookPlanner;
use crate::look::{GazeSettings, planner_for};
use crate::motion_clock::MotionClock;
use crate::render_desc;
use crate::resident::resident_kib;
use crate::setup::{check_size, load_trace};

/// Passes left out of the memory comparison: the first passes grow the allocator's pools and
/// the driver's shader caches.
pub const WARM_UP_PASSES: usize = 2;

/// Passes after warm-up that a verdict needs: resident memory after the first is compared
/// with the later ones.
pub const COMPARED_PASSES: usize = 2;

/// Largest growth of resident memory after warm-up that still counts as flat by default,
/// percent.
pub const MAX_GROWTH_PERCENT: f64 = 1.0;

/// The effects a soak renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoakEffects {
    /// The scene's own (`[effects] set`).
    Scene,
    /// These.
    Set(EffectSet),
    /// Every effect the scene's assets allow: all of them, less the caustics where the scene
    /// has neither a bake nor live caustics.
    Available,
}

/// How long a soak replays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoakLength {
    /// Passes until this long has gone by since the start (at least one pass).
    Duration(Duration),
    /// This many passes.
    Passes(usize),
}

/// Options of a soak run.
#[derive(Clone, Debug)]
pub struct SoakOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Effects.
    pub effects: SoakEffects,
    /// How long to keep replaying.
    pub length: SoakLength,
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
    /// Where the caller writes the JSON report (`--json`), refused before the first pass when
    /// it names one of the scene's files.
    pub report: Option<PathBuf>,
    /// Largest growth of resident memory after warm-up that passes, percent.
    pub max_growth_percent: f64,
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
    /// Largest growth that passes, percent.
    pub max_growth_percent: f64,
    /// Validation messages over all passes.
    pub validation_messages: u32,
    /// The first validation messages' texts.
    pub first_messages: Vec<String>,
}

impl SoakReport {
    /// Whether memory stayed flat and validation was silent.
    pub fn passed(&self) -> bool {
        self.passes.len() >= WARM_UP_PASSES + COMPARED_PASSES
            && self.growth_percent <= self.max_growth_percent
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
            self.max_growth_percent,
            self.validation_messages
        )
    }

    /// An error saying why the soak failed, unless it [`passed`](Self::passed).
    pub fn verdict(&self) -> Result<()> {
        if self.passed() {
            return Ok(());
        }
        bail!(
            "soak of {} failed: {} passes ({} needed), memory growth {:+.2} % (limit {} %), {} \
             validation messages{}",
            self.scene,
            self.passes.len(),
            WARM_UP_PASSES + COMPARED_PASSES,
            self.growth_percent,
            self.max_growth_percent,
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
    if let Some(report) = &options.report {
        InputFiles::new()
            .add_scene(&scene, "SCENE")
            .check_file("--json", report)?;
    }
    let effects = match options.effects {
        SoakEffects::Scene => scene.effects,
        SoakEffects::Set(set) => set,
        SoakEffects::Available => EffectSet {
            caustics: scene.caustics.mode == CausticsMode::Live || scene.caustics.bake.is_some(),
            ..EffectSet::ALL
        },
    };
    effects.ensure_implemented()?;
    if effects.caustics {
        scene.load_caustics()?;
    }
    check_size(options.size.0, options.size.1)?;
    if options.frames_per_pass == 0 || options.read_back_every == 0 {
        bail!("frames per pass and the readback interval must be at least 1");
    }
    if !(options.max_growth_percent >= 0.0 && options.max_growth_percent.is_finite()) {
        bail!(
            "the largest growth must be a percentage of 0 or more, got {}",
            options.max_growth_percent
        );
    }
    let (samples, _) = load_trace(&scene, None)?;
    let signals = crate::interrupt::watch();

    let started = Instant::now();
    let mut passes = Vec::new();
    let mut device = String::new();
    let mut first_messages = Vec::new();
    let mut current: Option<(Renderer, LookPlanner)> = None;
    let mut messages_before = 0;
    let more = |done: usize| match options.length {
        SoakLength::Duration(duration) => done == 0 || started.elapsed() < duration,
        SoakLength::Passes(n) => done < n,
    };
    while more(passes.len()) {
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

    let (rss_after_warm_up_kib, rss_max_kib, growth_percent) = settled_growth(&passes);
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
        max_growth_percent: options.max_growth_percent,
        first_messages,
    })
}

/// Resident memory after the first pass past warm-up, the largest after a later pass (both
/// kibibytes, 0 without such passes), and the growth of the largest over the first, percent.
fn settled_growth(passes: &[SoakPass]) -> (u64, u64, f64) {
    let settled: Vec<u64> = passes
        .iter()
        .skip(WARM_UP_PASSES)
        .map(|p| p.rss_kib)
        .collect();
    let first = settled.first().copied().unwrap_or(0);
    let max = settled.iter().copied().max().unwrap_or(0);
    let growth_percent = if first > 0 {
        (max as f64 / first as f64 - 1.0) * 100.0
    } else {
        0.0
    };
    (first, max, growth_percent)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A report of passes with these resident sizes, kibibytes, judged against `limit`.
    fn report(rss_kib: &[u64], limit: f64) -> SoakReport {
        let passes: Vec<SoakPass> = rss_kib
            .iter()
            .enumerate()
            .map(|(pass, &rss_kib)| SoakPass {
                pass,
                frames: 3,
                rss_kib,
                heap_in_use_kib: 0,
                validation_messages: 0,
                moved_frames: 0,
            })
            .collect();
        let (rss_after_warm_up_kib, rss_max_kib, growth_percent) = settled_growth(&passes);
        SoakReport {
            scene: "scene.toml".into(),
            effects: "all".into(),
            device: "device".into(),
            wall_s: 1.0,
            frames: 3 * passes.len() as u64,
            passes,
            rss_after_warm_up_kib,
            rss_max_kib,
            growth_percent,
            max_growth_percent: limit,
            validation_messages: 0,
            first_messages: Vec::new(),
        }
    }

    #[test]
    fn growth_counts_from_the_first_pass_after_warm_up_to_the_largest_later() {
        // The warm-up passes' growth is left out; a later dip does not hide the peak.
        let leaking = report(&[100, 150, 1000, 1100, 1040], 5.0);
        assert_eq!(
            (leaking.rss_after_warm_up_kib, leaking.rss_max_kib),
            (1000, 1100)
        );
        assert!((leaking.growth_percent - 10.0).abs() < 1e-9);
        let err = leaking.verdict().unwrap_err().to_string();
        assert!(err.contains("+10.00 % (limit 5 %)"), "{err}");
        assert!(report(&[100, 150, 1000, 1100, 1040], 10.5).passed());
        assert!(report(&[100, 150, 1000, 1000, 1000], 0.0).passed());
    }

    #[test]
    fn a_soak_that_compares_fewer_than_two_passes_fails() {
        let short = report(&[100, 150, 1000], 5.0);
        assert!(!short.passed());
        let err = short.verdict().unwrap_err().to_string();
        assert!(err.contains("3 passes (4 needed)"), "{err}");
    }
}
