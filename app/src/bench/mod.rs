//! `vitreous bench`: the baseline and each requested effect set, alternated frame by frame in
//! one process on one device, so their ratio is meaningful on a shared, noisy machine; and each
//! variant's counted work (`counts.rs`), which is the same run after run.

mod table;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use vitreous_optics::refraction::Refraction;
use vitreous_render::floor::FieldPassesMs;
use vitreous_render::renderer::Want;
use vitreous_render::work::counts::{WorkCounts, mean_counts};
use vitreous_render::{ContextOptions, FrameWork, GpuContext, Look, Reflection, Renderer};
use vitreous_trace::FrameInput;
use vitreous_xr::Backend;
use vitreous_xr::null::{NullBackend, NullConfig};

use vitreous_frames::blur_stack::DefocusSetup;
use vitreous_frames::look::{DefocusModel, LookPlanner};
use vitreous_frames::render_desc;
use vitreous_frames::setup::check_size;
use vitreous_frames::spread::Spread;
use vitreous_gaze::GazeConfig;
use vitreous_gaze::blur::check_pupil_diameter_m;
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{CausticsMode, load_scene, synth_params_for};

/// Frames of each variant rendered before timing starts (shaders compile on first use on
/// some drivers, lavapipe among them).
pub const WARM_UP_FRAMES: usize = 5;

/// Options of a benchmark.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Effect sets compared with the baseline.
    pub effects: Vec<EffectSet>,
    /// Eye image size, pixels.
    pub size: (u32, u32),
    /// Timed frames per variant.
    pub frames: usize,
    /// Frames of each variant rendered before timing and counting start
    /// ([`WARM_UP_FRAMES`] for timings; counts need none).
    pub warm_up: usize,
    /// Reflected image with per-eye refraction.
    pub reflection: Reflection,
    /// Turn on validation (slows everything down; for checking, not timing).
    pub validate: bool,
    /// Pick the Vulkan device whose name contains this.
    pub device: Option<String>,
    /// Pupil diameters to sweep for effect sets with defocus, millimetres (empty: the
    /// scene's).
    pub pupils_mm: Vec<f32>,
    /// Also time each variant with the light moving every frame (alternated with the same
    /// variant standing still).
    pub moving: bool,
    /// Also time each variant with caustics computed per pose on the GPU (a second renderer,
    /// alternated with the scene's baked caustics).
    pub live_caustics: bool,
    /// Also time each variant with two-surface refraction (a second renderer, alternated
    /// with the same variant under the paper's refraction).
    pub two_surface: bool,
    /// Also time each variant with the glass's whole image drawn with the environment's
    /// lookup (the frame's proof of coverage off), alternated with the same variant drawn as
    /// the proof allows.
    pub unproved: bool,
}

/// Degrees the light turns about the vertical axis through the object on each moving frame.
pub const MOVING_LIGHT_STEP_DEG: f32 = 1.0;

/// One variant's figures.
#[derive(Clone, Debug, Serialize)]
pub struct VariantResult {
    /// Effect set name (and pupil diameter, for defocus).
    pub effects: String,
    /// Texture fetches per covered pixel of the glass, by the shader's structure.
    pub fetches_per_pixel: u32,
    /// Whether the light moved on every frame of this variant.
    pub moving: bool,
    /// GPU milliseconds per stereo frame (the eye passes).
    pub gpu_ms: Option<Spread>,
    /// GPU milliseconds per frame of the floor fields' work before the eye passes (the
    /// shadow inducer's recomputation after a move, with the live caustic map's).
    pub prepare_gpu_ms: Option<Spread>,
    /// Median GPU milliseconds per frame of each stage of that work.
    pub field_passes_gpu_ms: Option<FieldPassesMedians>,
    /// CPU milliseconds per stereo frame (recording and submission).
    pub cpu_ms: Option<Spread>,
    /// Wall-clock milliseconds per stereo frame, submission to completion.
    pub wall_ms: Option<Spread>,
    /// Median GPU time over the baseline's.
    pub gpu_ratio: Option<f64>,
    /// Median CPU time over the baseline's.
    pub cpu_ratio: Option<f64>,
    /// Median wall time over the baseline's.
    pub wall_ratio: Option<f64>,
    /// Moving variants: median GPU time (fields and eye passes) over the same variant's
    /// standing still.
    pub gpu_over_static: Option<f64>,
    /// Moving variants: median wall time over the same variant's standing still.
    pub wall_over_static: Option<f64>,
    /// Two-surface variants: median GPU time over the same variant's under the paper's
    /// refraction.
    pub gpu_over_paper: Option<f64>,
    /// With `--unproved`, each variant drawn as the proof allows: median GPU time over the
    /// same variant's with the proof off.
    pub gpu_over_unproved: Option<f64>,
    /// Counted work, mean per timed frame ([`WorkCounts`]).
    pub work: WorkCounts,
}

/// Median GPU milliseconds per frame of each stage of the floor fields' work (0 where it
/// did not run on most frames).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FieldPassesMedians {
    /// The shadow mask.
    pub mask_ms: f64,
    /// The nearest shadow texel of every texel (distance transform).
    pub nearest_ms: f64,
    /// The inducer's gain (ramp), with the distance to the shadow edge.
    pub ramp_ms: f64,
    /// The live caustic map's photons (clearing, tracing, splatting).
    pub caustic_photons_ms: f64,
    /// The live caustic map's smoothing and copy.
    pub caustic_smoothing_ms: f64,
}

impl FieldPassesMedians {
    /// The medians of `frames`' stages, or `None` without frames.
    fn of(frames: &[FieldPassesMs]) -> Option<FieldPassesMedians> {
        let median = |stage: fn(&FieldPassesMs) -> f64| {
            Spread::of(frames.iter().map(stage)).map_or(0.0, |s| s.median_ms)
        };
        (!frames.is_empty()).then(|| FieldPassesMedians {
            mask_ms: median(|f| f.mask_ms),
            nearest_ms: median(|f| f.nearest_ms),
            ramp_ms: median(|f| f.ramp_ms),
            caustic_photons_ms: median(|f| f.caustic_photons_ms),
            caustic_smoothing_ms: median(|f| f.caustic_smoothing_ms),
        })
    }
}

/// A benchmark's result.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// The scene file.
    pub scene: String,
    /// Vulkan device.
    pub device: String,
    /// Vulkan driver.
    pub driver: String,
    /// Eye image width, pixels.
    pub width_px: u32,
    /// Eye image height, pixels.
    pub height_px: u32,
    /// Timed frames per variant.
    pub frames: usize,
    /// Whether each variant also ran with the light moving (`--moving`).
    pub moving: bool,
    /// Whether each variant also ran with two-surface refraction (`--two-surface`).
    pub two_surface: bool,
    /// Whether each variant also ran with the proof of coverage off (`--unproved`).
    pub unproved: bool,
    /// Whether the device counted shader invocations (pipeline-statistics queries).
    pub invocations_counted: bool,
    /// The baseline first, then each requested set.
    pub variants: Vec<VariantResult>,
}

/// Texture fetches per covered pixel of the glass pass for a look (see shaders/glass.wgsl):
/// blur-stack reads are one trilinear fetch whatever the blur.
pub fn fetches_per_pixel(look: &Look) -> u32 {
    let background = look.disparity || look.defocus.is_some();
    match (background, look.reflection) {
        (false, _) => 3,
        (true, Reflection::Phong) => 2,
        (true, Reflection::EnvironmentFresnel) => 3,
    }
}

/// The fetches per covered pixel that eq. 6 over the glass adds in `scene` as the bench draws
/// it (additive, or for the scene's segmented dimmer): one where the glass's shader takes the
/// background away, none where the dimmer's resolve does or the scene keeps the paper's light.
pub fn compensation_fetches(scene: &vitreous_scene::Scene) -> u32 {
    u32::from(
        scene.compensation == vitreous_optics::display::Compensation::Background
            && scene.dimmer.is_none(),
    )
}

/// Runs the benchmark.
pub fn bench(options: &BenchOptions) -> Result<BenchReport> {
    let mut scene = load_scene(&options.scene)?;
    if options.two_surface && options.live_caustics {
        bail!("give --two-surface or --live-caustics, not both");
    }
    if options.two_surface {
        // The first renderer refracts as the paper does, the second through both surfaces.
        scene.object.refraction = Refraction::Paper;
    }
    for set in &options.effects {
        set.ensure_implemented()?;
    }
    if options.effects.iter().any(|set| set.caustics) {
        scene.load_caustics()?;
    }
    vitreous_frames::setup::load_bake_for_glass(&mut scene);
    check_size(options.size.0, options.size.1)?;
    if options.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let mut sets = vec![EffectSet::NONE];
    sets.extend(
        options
            .effects
            .iter()
            .copied()
            .filter(|e| *e != EffectSet::NONE),
    );
    let any_defocus = sets.iter().any(|e| e.defocus);
    let setup = any_defocus.then(|| DefocusSetup::new(&scene, scene.viewer.pupil_diameter_m));
    let pupils_m: Vec<f32> = if options.pupils_mm.is_empty() {
        vec![scene.viewer.pupil_diameter_m]
    } else {
        options
            .pupils_mm
            .iter()
            .map(|mm| check_pupil_diameter_m(mm / 1000.0))
            .collect::<Result<_, _>>()?
    };
    // One variant per set, and per pupil diameter for sets with defocus; each with its own
    // gaze pipeline over the same views.
    let mut variants = Vec::new();
    for set in &sets {
        let base = vitreous_frames::look::base_look(set, options.reflection);
        let variant = |label: String, planner: LookPlanner| Variant {
            label,
            planner,
            caustics: set.caustics,
            live: false,
            two_surface: false,
            unproved: false,
            moving: false,
        };
        match (&setup, set.defocus) {
            (Some(setup), true) => {
                for &pupil_m in &pupils_m {
                    // Each variant times its own fixed A_p, whatever the scene's source.
                    let model = DefocusModel {
                        pupil_m,
                        pupil_source: vitreous_gaze::PupilSource::Paper,
                        ..setup.model.clone()
                    };
                    variants.push(variant(
                        format!("{set} A_p={:.0}mm", pupil_m * 1000.0),
                        LookPlanner::new(base, Some((GazeConfig::new(model.distances), model))),
                    ));
                }
            }
            _ => variants.push(variant(set.to_string(), LookPlanner::new(base, None))),
        }
    }
    // With --live-caustics every variant with caustics also runs on a second renderer that
    // computes them per pose (`<set> live`), right after the same variant with the bake.
    if options.live_caustics {
        variants = with_twins(variants, |v| v.caustics, "live", |v| v.live = true);
    }
    // With --two-surface every variant also runs on a second renderer that refracts through
    // both surfaces (`<set> two-surface`), right after the same variant under the paper's.
    if options.two_surface {
        variants = with_twins(variants, |_| true, "two-surface", |v| v.two_surface = true);
    }
    // With --unproved every variant also runs with the proof of coverage off (`<set>
    // unproved`), right before the same variant drawn as the proof allows.
    if options.unproved {
        variants = with_twins(variants, |_| true, "unproved", |v| v.unproved = true);
    }

    // The same views for every variant: a synthetic trace looking at the object.
    let samples = vitreous_trace::synth::synthesize_with_truth(&synth_params_for(&scene))
        .context("synthesising the benchmark's views")?
        .samples;
    let total = options.warm_up + options.frames;
    let mut backend = NullBackend::new(
        samples,
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: None,
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )?;
    let mut inputs: Vec<FrameInput> = Vec::with_capacity(total);
    while let Some(frame) = backend.wait_frame()? {
        backend.end_frame(&frame)?;
        inputs.push(frame);
    }
    let inputs: Vec<FrameInput> = inputs.into_iter().cycle().take(total).collect();

    let ctx = GpuContext::headless(&ContextOptions {
        validation: options.validate,
        device_name: options.device.clone(),
    })
    .context("setting up the Vulkan device")?;
    let (device, driver) = (ctx.device_name.clone(), ctx.driver.clone());
    let (w, h) = options.size;
    let any_caustics = options.effects.iter().any(|set| set.caustics);
    let mut renderer = Renderer::new(ctx, &render_desc::scene_desc(&scene, setup.as_ref()), w, h)
        .context("preparing the renderer")?;
    render_desc::enable_live_caustics(&mut renderer, &scene, any_caustics)
        .context("preparing live caustics")?;
    // The same scene with caustics computed per pose, on the scene's live map
    // (`[caustics] resolution_px`, `smoothing_px`, `photons_per_side`).
    let mut live_renderer = match (options.live_caustics, &scene.caustics.gain) {
        (true, Some(bake)) if scene.caustics.mode == CausticsMode::Baked => {
            let mut live = scene.clone();
            live.caustics.mode = CausticsMode::Live;
            live.load_caustics()?;
            let ctx = GpuContext::headless(&ContextOptions {
                validation: options.validate,
                device_name: options.device.clone(),
            })
            .context("setting up the second Vulkan device")?;
            let mut r = Renderer::new(ctx, &render_desc::scene_desc(&live, setup.as_ref()), w, h)
                .context("preparing the live-caustics renderer")?;
            render_desc::enable_live_caustics(&mut r, &live, true)
                .context("preparing live caustics")?;
            Some(r)
        }
        (true, _) => bail!(
            "--live-caustics compares with the scene's bake: give a scene with a bake \
             ([caustics] mode = \"baked\") and an effect set with caustics"
        ),
        _ => None,
    };
    let mut two_renderer = if options.two_surface {
        let mut two = scene.clone();
        two.object.refraction = Refraction::TwoSurface;
        let ctx = GpuContext::headless(&ContextOptions {
            validation: options.validate,
            device_name: options.device.clone(),
        })
        .context("setting up the second Vulkan device")?;
        let mut r = Renderer::new(ctx, &render_desc::scene_desc(&two, setup.as_ref()), w, h)
            .context("preparing the two-surface renderer")?;
        render_desc::enable_live_caustics(&mut r, &two, any_caustics)
            .context("preparing live caustics")?;
        Some(r)
    } else {
        None
    };
    drop(setup);
    let mut invocations_counted = true;
    for r in std::iter::once(&mut renderer)
        .chain(live_renderer.as_mut())
        .chain(two_renderer.as_mut())
    {
        invocations_counted &= r.count_invocations()?;
    }

    // With --moving every variant runs twice in a row per frame: the light moved, then the
    // same pose again (nothing moved since the frame before).
    if options.moving {
        variants = with_twins(variants, |_| true, "moving", |v| v.moving = true);
    }
    let center = scene.object.center_m;
    let rest = scene.rest_placement();
    let mut turns = 0u32;
    let n = variants.len();
    let mut prepare = vec![Vec::new(); n];
    let mut field_passes = vec![Vec::new(); n];
    let mut gpu = vec![Vec::new(); n];
    let mut cpu = vec![Vec::new(); n];
    let mut wall = vec![Vec::new(); n];
    let mut work: Vec<Vec<FrameWork>> = vec![Vec::new(); n];
    let mut looks = vec![Look::default(); n];
    for (k, input) in inputs.iter().enumerate() {
        for (v, variant) in variants.iter_mut().enumerate() {
            let renderer = match (&mut live_renderer, &mut two_renderer) {
                (Some(live), _) if variant.live => live,
                (_, Some(two)) if variant.two_surface => two,
                _ => &mut renderer,
            };
            let started = Instant::now();
            let (look, _) = variant.planner.plan(input);
            looks[v] = look;
            if variant.moving {
                turns += 1;
                let turn = glam::Quat::from_rotation_y(
                    (turns as f32 * MOVING_LIGHT_STEP_DEG).to_radians(),
                );
                let placement = vitreous_scene::Placement {
                    light_position_m: center + turn * (rest.light_position_m - center),
                    ..rest
                };
                renderer.set_pose(render_desc::scene_pose(&scene, &placement));
            }
            renderer.set_coverage_proof(!variant.unproved);
            let params = render_desc::frame_params(input, look);
            renderer.submit(&params, Want::default())?;
            let result = renderer.flush()?.pop().expect("one frame in flight");
            let wall_ms = started.elapsed().as_secs_f64() * 1e3;
            if k >= options.warm_up {
                work[v].push(result.work);
                if let Some(g) = result.timing.gpu_ms {
                    gpu[v].push(g);
                }
                if let Some(p) = result.timing.prepare_gpu_ms {
                    prepare[v].push(p);
                }
                if let Some(f) = result.timing.field_passes {
                    field_passes[v].push(f);
                }
                cpu[v].push(result.timing.cpu_submit_ms);
                wall[v].push(wall_ms);
            }
        }
    }
    for r in std::iter::once(&renderer)
        .chain(live_renderer.as_ref())
        .chain(two_renderer.as_ref())
    {
        vitreous_frames::frame_loop::ensure_validation_clean(r)?;
    }
    let spreads: Vec<_> = (0..n)
        .map(|i| {
            (
                Spread::of(gpu[i].iter().copied()),
                Spread::of(cpu[i].iter().copied()),
                Spread::of(wall[i].iter().copied()),
            )
        })
        .collect();
    // GPU time of a whole frame: the fields' work and the eye passes.
    let total_gpu: Vec<Option<Spread>> = (0..n)
        .map(|i| {
            Spread::of(
                gpu[i]
                    .iter()
                    .zip(prepare[i].iter().chain(std::iter::repeat(&0.0)))
                    .map(|(g, p)| g + p),
            )
        })
        .collect();
    let ratio = |a: Option<Spread>, b: Option<Spread>| match (a, b) {
        (Some(a), Some(b)) if b.median_ms > 0.0 => Some(a.median_ms / b.median_ms),
        _ => None,
    };
    // The baseline standing still under the paper's refraction, with the proof (after its
    // moving, unproved and two-surface twins).
    let twins = [options.moving, options.unproved, options.two_surface];
    let base = spreads[twins.iter().map(|&t| usize::from(t) + 1).product::<usize>() - 1];
    let compensated = compensation_fetches(&scene);
    let results = (0..n)
        .map(|i| {
            let (g, c, wl) = spreads[i];
            // A moving variant's static twin comes right after it.
            let variant = &variants[i];
            let twin = (variant.moving && i + 1 < n).then_some(i + 1);
            // A two-surface variant's paper twin: the same label without the suffix.
            let paper = variant.label.replace(" two-surface", "");
            let paper_twin = variant
                .two_surface
                .then(|| variants.iter().position(|v| v.label == paper))
                .flatten();
            // A proved variant's unproved twin: the same flags, proof off.
            let unproved_twin = (options.unproved && !variant.unproved)
                .then(|| {
                    variants.iter().position(|v| {
                        v.unproved && v.label.replace(" unproved", "") == variant.label
                    })
                })
                .flatten();
            let fetches =
                fetches_per_pixel(&looks[i]) + u32::from(variant.two_surface) + compensated;
            VariantResult {
                effects: variant.label.clone(),
                fetches_per_pixel: fetches,
                work: mean_counts(&work[i]),
                moving: variant.moving,
                gpu_ms: g,
                prepare_gpu_ms: Spread::of(prepare[i].iter().copied()),
                field_passes_gpu_ms: FieldPassesMedians::of(&field_passes[i]),
                cpu_ms: c,
                wall_ms: wl,
                gpu_ratio: ratio(g, base.0),
                cpu_ratio: ratio(c, base.1),
                wall_ratio: ratio(wl, base.2),
                gpu_over_static: twin.and_then(|t| ratio(total_gpu[i], total_gpu[t])),
                wall_over_static: twin.and_then(|t| ratio(wl, spreads[t].2)),
                gpu_over_paper: paper_twin.and_then(|t| ratio(g, spreads[t].0)),
                gpu_over_unproved: unproved_twin.and_then(|t| ratio(g, spreads[t].0)),
            }
        })
        .collect();
    Ok(BenchReport {
        scene: options.scene.display().to_string(),
        device,
        driver,
        width_px: w,
        height_px: h,
        frames: options.frames,
        moving: options.moving,
        two_surface: options.two_surface,
        unproved: options.unproved,
        invocations_counted,
        variants: results,
    })
}

/// One timed variant: an effect set (with its pupil) and where and how it is drawn.
struct Variant {
    /// The label printed (`<set> [A_p=..] [live] [two-surface] [unproved] [moving]`).
    label: String,
    /// Its own gaze pipeline over the shared views.
    planner: LookPlanner,
    /// Whether the set draws caustics.
    caustics: bool,
    /// Drawn by the renderer that computes the caustics per pose.
    live: bool,
    /// Drawn by the renderer that refracts through both surfaces.
    two_surface: bool,
    /// Drawn with the proof of coverage off: the whole glass with the environment's lookup.
    unproved: bool,
    /// The light is turned before each of its frames.
    moving: bool,
}

/// `variants` with, right before each one that `wants` a twin, that twin: the label with
/// ` suffix`, its own restarted gaze pipeline, changed by `mark`.
fn with_twins(
    variants: Vec<Variant>,
    wants: impl Fn(&Variant) -> bool,
    suffix: &str,
    mark: impl Fn(&mut Variant),
) -> Vec<Variant> {
    let mut out = Vec::with_capacity(variants.len() * 2);
    for variant in variants {
        if wants(&variant) {
            let mut twin = Variant {
                label: format!("{} {suffix}", variant.label),
                planner: variant.planner.restarted(),
                ..variant
            };
            mark(&mut twin);
            out.push(twin);
        }
        out.push(variant);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_background_taken_away_in_the_glass_is_one_fetch_more() {
        let scene = |name: &str| {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../config/scenes")
                .join(name);
            load_scene(&path).unwrap()
        };
        // Compensated, additive: one more; the paper's scene: none; the dimmer's scene takes
        // the background away in its resolve, not in the glass.
        assert_eq!(compensation_fetches(&scene("glass-sphere-real.toml")), 1);
        assert_eq!(compensation_fetches(&scene("glass-sphere.toml")), 0);
        let ml2 = scene("glass-sphere-ml2.toml");
        assert_eq!(
            ml2.compensation,
            vitreous_optics::display::Compensation::Background
        );
        assert_eq!(compensation_fetches(&ml2), 0);
    }
}
