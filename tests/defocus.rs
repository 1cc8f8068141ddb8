//! Gaze-dependent defocus (eq. 9-14) on the machine's Vulkan device with validation on:
//! the GPU's blurred refracted image against a CPU reference that evaluates eq. 10-14
//! literally, and the blur following the gaze through the whole pipeline (vergence, the
//! 20-sample filter, the gaze image) on the shipped scene and a synthetic alternating trace.

use std::path::Path;

use glam::Vec2;
use vitreous_frames::blur_stack::DefocusSetup;
use vitreous_frames::frame_loop::{self, FramePlan, FrameSink};
use vitreous_frames::look::LookPlanner;
use vitreous_frames::render_desc;
use vitreous_gaze::blur::blur_reference;
use vitreous_gaze::{GazeConfig, GazeImage};
use vitreous_optics::sphere_check::{RefractionSample, refraction_sample};
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{Defocus, Look, Reflection, Renderer};
use vitreous_scene::synth_params_for;
use vitreous_scene::{Image, PixelData, Scene, gaze_image_of_target, load_scene};
use vitreous_tests::render_once;
use vitreous_trace::FrameInput;
use vitreous_trace::synth::synthesize_with_truth;
use vitreous_xr::null::{NullBackend, NullConfig};

const W: u32 = 320;
const H: u32 = 240;

fn scene() -> Scene {
    load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/visual-effects.toml"))
        .expect("shipped scene")
}

fn black(width: u32, height: u32, linear: bool) -> Image {
    let n = (width * height * 4) as usize;
    let data = if linear {
        PixelData::LinearF32((0..n).map(|i| if i % 4 == 3 { 1.0 } else { 0.0 }).collect())
    } else {
        PixelData::Srgb8((0..n).map(|i| if i % 4 == 3 { 255 } else { 0 }).collect())
    };
    Image::new(width, height, data).unwrap()
}

/// Renders one stereo frame of `scene` with `look`; returns the eye images.
fn render(scene: &Scene, setup: &DefocusSetup, input: &FrameInput, look: Look) -> [Vec<u8>; 2] {
    let ctx = vitreous_tests::validated_context();
    let mut renderer =
        Renderer::new(ctx, &render_desc::scene_desc(scene, Some(setup)), W, H).unwrap();
    let want = Want {
        eyes: true,
        world: false,
    };
    let readback = render_once(&mut renderer, &render_desc::frame_params(input, look), want);
    let v = renderer.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
    readback.eyes
}

/// The first frame of the scene's synthetic trace at the test's size.
fn first_frame(scene: &Scene) -> FrameInput {
    let samples = synthesize_with_truth(&synth_params_for(scene))
        .unwrap()
        .samples;
    let mut backend = NullBackend::new(
        samples,
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: Some(1),
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )
    .unwrap();
    use vitreous_xr::Backend;
    backend.wait_frame().unwrap().unwrap()
}

/// The refracted image blurred by the GPU matches eq. 10-14 evaluated literally on the CPU:
/// the background photo convolved by the naive 2-D loop of `blur_reference`, sampled where the
/// CPU ray tracer says each pixel's refracted ray lands, times the transmitted fraction.
#[test]
fn refracted_blur_matches_the_literal_convolution() {
    let mut scene = scene();
    // Only the refracted image: no surface texture, no environment light, no highlight.
    scene.object.surface_texture = None;
    scene.environment.latlong = black(8, 4, true);
    let setup = DefocusSetup::new(&scene, scene.viewer.pupil_diameter_m);
    let input = first_frame(&scene);
    let photo = &scene.background.photo;
    let (pw, ph) = (photo.width as usize, photo.height as usize);
    let grey: Vec<f32> = match &photo.data {
        PixelData::Srgb8(b) => b
            .chunks_exact(4)
            .map(|p| vitreous_optics::srgb::to_linear(p[0]))
            .collect(),
        PixelData::LinearF32(_) => unreachable!("photos are sRGB"),
    };
    // One K_g on a slice of the stack, one between slices (linear blending of neighbouring
    // slices matches the variance of eq. 11 exactly but not the Gaussian's shape).
    let step = setup.background.step_px;
    for (k_g, mean_tol) in [(12.0 * step, 0.006), (12.5 * step, 0.012)] {
        let look = Look {
            disparity: true,
            defocus: Some(Defocus {
                refracted_k_g_px: k_g,
                surface_k_g_px: 0.0,
            }),
            reflection: Reflection::EnvironmentFresnel,
            inducer: false,
            caustics: false,
            blank: false,
        };
        let gpu = render(&scene, &setup, &input, look);
        let blurred = blur_reference(&grey, pw, ph, k_g);
        let sharp_vs_blurred: f32 = grey
            .iter()
            .zip(&blurred)
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / grey.len() as f32;
        let sphere = vitreous_frames::sphere_check_view::sphere_of(&scene);
        let size = Vec2::new(W as f32, H as f32);
        let camera = render_desc::eye_params(&input.views[0]);
        let (mut err, mut n) = (0.0f64, 0usize);
        for y in 0..H {
            for x in 0..W {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let RefractionSample::Hit {
                    uv: Some(uv),
                    transmission,
                    ..
                } = refraction_sample(&camera, p, size, &sphere)
                else {
                    continue;
                };
                let expected = transmission * bilinear(&blurred, pw, ph, uv);
                let i = ((y * W + x) * 4) as usize;
                let got = vitreous_optics::srgb::to_linear(gpu[0][i]);
                err += f64::from((got - expected).abs());
                n += 1;
            }
        }
        let mean = (err / n as f64) as f32;
        assert!(n > 10_000, "too few refracted pixels ({n})");
        eprintln!("K_g {k_g}: mean error {mean}, blur changes the photo by {sharp_vs_blurred}");
        // Tolerances: 8-bit sRGB storage of the stack and of the eye image (about 0.002 in
        // linear light at these levels), bilinear vs trilinear sampling of a smooth image, and
        // between slices the shape (not the variance) of the blended kernel.
        assert!(
            mean < mean_tol,
            "K_g {k_g}: mean error {mean} (blur itself changes the photo by {sharp_vs_blurred})"
        );
        assert!(
            mean < 0.25 * sharp_vs_blurred,
            "K_g {k_g}: the GPU is not clearly closer to the blurred photo than the photo is"
        );
    }
}

/// Bilinear sample (texel centres at half-integers, clamp to edge) of a grey image.
fn bilinear(img: &[f32], w: usize, h: usize, uv: Vec2) -> f32 {
    let x = (uv.x * w as f32 - 0.5).clamp(0.0, (w - 1) as f32);
    let y = (uv.y * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let row = |yy: usize| img[yy * w + x0] * (1.0 - fx) + img[yy * w + x1] * fx;
    row(y0) * (1.0 - fy) + row(y1) * fy
}

/// Variance of the Laplacian of the left eye's luminance over the central half of the image.
fn laplacian_variance(rgba: &[u8]) -> f64 {
    let l =
        |x: u32, y: u32| vitreous_optics::srgb::to_linear(rgba[((y * W + x) * 4) as usize]) as f64;
    let mut values = Vec::new();
    for y in H / 4..3 * H / 4 {
        for x in W / 4..3 * W / 4 {
            values.push(l(x - 1, y) + l(x + 1, y) + l(x, y - 1) + l(x, y + 1) - 4.0 * l(x, y));
        }
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64
}

/// Keeps the left eye image of chosen frames with the gaze image of their look.
struct Keep {
    planner: LookPlanner,
    frames: Vec<u64>,
    kept: Vec<(u64, GazeImage, Vec<u8>)>,
    images: std::collections::HashMap<u64, GazeImage>,
}

impl FrameSink for Keep {
    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let (mut look, state) = self.planner.plan(input);
        self.images
            .insert(input.index, state.map_or(GazeImage::Unknown, |s| s.image));
        let keep = self.frames.contains(&input.index);
        // Every sample goes through the gaze pipeline; only the frames measured are drawn.
        look.blank = !keep;
        FramePlan {
            look,
            want: Want {
                eyes: keep,
                world: false,
            },
        }
    }

    fn finished(&mut self, input: &FrameInput, result: &FrameResult) -> anyhow::Result<()> {
        if let Some(rb) = &result.readback {
            self.kept
                .push((input.index, self.images[&input.index], rb.eyes[0].clone()));
        }
        Ok(())
    }
}

/// Replays the synthetic alternating trace with O5 through the real frame loop and gaze
/// pipeline; returns (gaze image, sharpness) of frames late in each gaze phase.
fn sharpness_by_gaze(scene: &Scene) -> Vec<(GazeImage, f64)> {
    let setup = DefocusSetup::new(scene, scene.viewer.pupil_diameter_m);
    let truth = synthesize_with_truth(&synth_params_for(scene)).unwrap();
    // Frames 2.5 s into each 3 s phase: the 20-sample mean has settled.
    let frames: Vec<u64> = truth
        .phases
        .iter()
        .map(|p| ((p.start_ns as f64 * 1e-9 + 2.5) * 60.0) as u64)
        .filter(|f| *f < 600)
        .collect();
    let images: Vec<GazeImage> = truth
        .phases
        .iter()
        .map(|p| gaze_image_of_target(p.target))
        .collect();
    assert!(images.contains(&GazeImage::Surface) && images.contains(&GazeImage::Refracted));
    let effects = vitreous_scene::effects::EffectSet::parse("O5").unwrap();
    let mut look = vitreous_frames::look::base_look(&effects, Reflection::EnvironmentFresnel);
    look.reflection = Reflection::EnvironmentFresnel;
    // The scene's filter (eq. 15, whose 20-sample mean the frames above wait for).
    let config = GazeConfig {
        filter: scene.gaze.filter,
        ..GazeConfig::new(setup.model.distances)
    };
    let mut sink = Keep {
        planner: LookPlanner::new(look, Some((config, setup.model.clone()))),
        frames: frames.clone(),
        kept: Vec::new(),
        images: Default::default(),
    };
    let mut backend = NullBackend::new(
        truth.samples,
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: Some(frames.iter().max().unwrap() + 1),
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )
    .unwrap();
    let ctx = vitreous_tests::validated_context();
    let mut renderer =
        Renderer::new(ctx, &render_desc::scene_desc(scene, Some(&setup)), W, H).unwrap();
    frame_loop::run(&mut backend, &mut renderer, &mut sink).unwrap();
    let v = renderer.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
    sink.kept
        .iter()
        .map(|(_, image, rgba)| (*image, laplacian_variance(rgba)))
        .collect()
}

fn mean_of(values: &[(GazeImage, f64)], image: GazeImage) -> f64 {
    let v: Vec<f64> = values
        .iter()
        .filter(|(i, _)| *i == image)
        .map(|(_, s)| *s)
        .collect();
    assert!(!v.is_empty(), "no frame with the gaze on {image:?}");
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn blur_follows_the_gaze_on_the_synthetic_trace() {
    // The refracted image alone: sharper while the gaze is on it.
    let mut refracted_only = scene();
    refracted_only.object.surface_texture = None;
    refracted_only.environment.latlong = black(8, 4, true);
    let s = sharpness_by_gaze(&refracted_only);
    let (on, off) = (
        mean_of(&s, GazeImage::Refracted),
        mean_of(&s, GazeImage::Surface),
    );
    assert!(
        on > 1.5 * off,
        "refracted image: sharpness {on} looked at vs {off} not"
    );

    // The surface image alone (black background and environment): sharper while looked at.
    let mut surface_only = scene();
    let (bw, bh) = (
        surface_only.background.photo.width,
        surface_only.background.photo.height,
    );
    surface_only.background.photo = black(bw, bh, false);
    surface_only.environment.latlong = black(8, 4, true);
    surface_only.object.surface_transmittance = 0.0;
    let s = sharpness_by_gaze(&surface_only);
    let (on, off) = (
        mean_of(&s, GazeImage::Surface),
        mean_of(&s, GazeImage::Refracted),
    );
    assert!(
        on > 1.5 * off,
        "surface image: sharpness {on} looked at vs {off} not"
    );
}
