//! The live-caustics tests' helpers (tests/live_caustics.rs, tests/live_caustics_sweep.rs):
//! the shipped scenes in live mode with their bakes, the baker's own maps, live maps rendered
//! on the machine's Vulkan device with validation on, and the measures the tests compare
//! them by.

use std::time::Instant;

use glam::{Quat, Vec2, Vec3};
use vitreous_frames::render_desc;
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_optics::live_caustics::LiveCausticsDesc;
use vitreous_render::renderer::Want;
use vitreous_render::{FrameParams, Look, Renderer, ScenePose};
use vitreous_scene::Scene;
use vitreous_tests::shipped_scene;

/// The shipped scene `name` with its bake loaded.
pub(crate) fn baked_scene(name: &str) -> Scene {
    let mut scene = shipped_scene(name);
    scene.load_caustics().unwrap_or_else(|e| panic!("{e}"));
    scene
}

/// The scene `name` in live mode on a `side` x `side` map (`None`: the default), and its
/// shipped bake averaged down to that map: the mean of the bake's texels each live texel
/// covers, the same light over the same area (smoothed alike, within 0.5 % of the baker's map
/// at 990 x 990 for the sphere and within 1 % for the diamond; docs/caustics.md).
pub(crate) fn live_scene(name: &str, side: Option<u32>) -> (Scene, Vec<f32>) {
    let baked = baked_scene(name);
    let bake = baked.caustics.gain.as_ref().expect("the bake is loaded");
    let mut live = baked.clone();
    live.caustics.mode = vitreous_scene::CausticsMode::Live;
    if let Some(side) = side {
        live.caustics.resolution_px = side;
    }
    live.load_caustics().unwrap_or_else(|e| panic!("{e}"));
    let side = live.caustics.resolution_px;
    let factor = bake.width_px / side;
    assert_eq!(
        factor * side,
        bake.width_px,
        "the live map divides the bake"
    );
    let averaged = block_mean(&bake.gain, bake.width_px as usize, factor as usize);
    (live, averaged)
}

/// The offline baker's map of `scene`'s object, light and floor at `side` x `side` texels, with
/// `budget` grid rays (the shipped bakes': 2^18).
pub(crate) fn baked_at(scene: &Scene, side: u32, budget: u64) -> Vec<f32> {
    let params = vitreous_caustics::BakeParams {
        width_px: side,
        height_px: side,
        budget_rays: budget,
        ..vitreous_caustics::BakeParams::default()
    };
    vitreous_caustics::bake(
        &vitreous_caustics::CausticScene::from_scene(scene),
        &params,
        &|_, _| {},
    )
    .expect("the scene bakes")
    .bake
    .gain
}

/// One frame's live caustic map.
pub(crate) struct LiveFrame {
    /// The gain map.
    pub gain: Vec<f32>,
    /// Wall-clock milliseconds of the frame.
    pub wall_ms: f64,
    /// The smoothing's tiles written, and the map's.
    pub tiles: [u32; 2],
}

/// Renders one frame with the caustics on for each light position (`None`: the scene's) and
/// returns the live maps. With `fields_first`, the inducer's fields are read back before the
/// first frame.
pub(crate) fn live_gains(
    scene: &Scene,
    live: LiveCausticsDesc,
    lights: &[Option<Vec3>],
    fields_first: bool,
) -> Vec<LiveFrame> {
    let rest = ScenePose::of(&render_desc::scene_desc(scene, None));
    let poses: Vec<_> = lights
        .iter()
        .map(|light| {
            light.map(|light_position_m| ScenePose {
                light_position_m,
                ..rest
            })
        })
        .collect();
    live_gains_at(scene, live, &poses, fields_first)
}

/// As [`live_gains`], for each pose of the object and the light (`None`: the scene's).
pub(crate) fn live_gains_at(
    scene: &Scene,
    live: LiveCausticsDesc,
    poses: &[Option<ScenePose>],
    fields_first: bool,
) -> Vec<LiveFrame> {
    let ctx = vitreous_tests::validated_context();
    let desc = render_desc::scene_desc(scene, None);
    let mut renderer = Renderer::new(ctx, &desc, 32, 32).expect("renderer");
    renderer
        .enable_live_caustics(&desc, live)
        .expect("live caustics");
    let fov = Fov {
        left_rad: -0.3,
        right_rad: 0.3,
        up_rad: 0.3,
        down_rad: -0.3,
    };
    let eye = EyeParams::new(Vec3::ZERO, Quat::IDENTITY, fov);
    let params = FrameParams {
        eyes: [eye, eye],
        look: Look {
            inducer: true,
            caustics: true,
            ..Look::default()
        },
    };
    if fields_first {
        renderer.inducer_fields().expect("the fields read back");
    }
    let mut out = Vec::new();
    for pose in poses {
        if let Some(pose) = pose {
            renderer.set_pose(*pose);
        }
        let started = Instant::now();
        renderer.submit(&params, Want::default()).expect("submit");
        renderer.flush().expect("flush");
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        let gain = renderer
            .live_caustic_gain()
            .expect("read back")
            .expect("live caustics are on");
        let side = square_side(&gain);
        let bounds = renderer.live_caustic_bounds().expect("read back");
        assert_eq!(
            bounds,
            nonzero_box(&gain, side),
            "the GPU's bound of the non-zero gains"
        );
        let tiles = renderer
            .live_caustic_tiles()
            .expect("read back")
            .expect("live caustics are on");
        let lit = lit_tiles(&gain, side);
        assert!(
            tiles[0] >= lit && tiles[0] <= tiles[1],
            "{} tiles written of {}, {lit} hold gains",
            tiles[0],
            tiles[1]
        );
        out.push(LiveFrame {
            gain,
            wall_ms,
            tiles,
        });
    }
    let v = renderer.context().validation();
    assert_eq!(
        v.errors() + v.warnings(),
        0,
        "validation messages: {:#?}",
        v.messages()
    );
    out
}

/// docs/caustics.md's quality figure: sqrt(sum (G - G_ref)^2 / sum G_ref^2) over the texels
/// where the reference is visibly brighter than the bare floor (G_ref > 0.1).
pub(crate) fn relative_rms(gain: &[f32], reference: &[f32]) -> f64 {
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for (&g, &r) in gain.iter().zip(reference) {
        if r > 0.1 {
            diff += f64::from(g - r).powi(2);
            norm += f64::from(r).powi(2);
        }
    }
    (diff / norm).sqrt()
}

/// `gain` (`width` texels a row) convolved along rows, then columns, with the kernel of a box
/// of 2 `radius` + 1 texels applied three times, texels beyond the edge taken as 0:
/// docs/caustics.md's smoothing, written out on the CPU as one direct convolution per axis.
pub(crate) fn smoothed(gain: &[f32], width: usize, radius: u32) -> Vec<f32> {
    let r = radius as usize;
    let boxed = vec![1.0 / (2 * r + 1) as f64; 2 * r + 1];
    let convolve = |a: &[f64], b: &[f64]| {
        let mut out = vec![0.0; a.len() + b.len() - 1];
        for (i, x) in a.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                out[i + j] += x * y;
            }
        }
        out
    };
    let kernel = convolve(&convolve(&boxed, &boxed), &boxed);
    let reach = 3 * r as isize;
    let height = gain.len() / width;
    let along = |src: &[f64], step: usize, len: usize, lines: usize, stride: usize| {
        let mut out = vec![0.0f64; src.len()];
        for line in 0..lines {
            for i in 0..len {
                let mut sum = 0.0;
                for (k, w) in (-reach..=reach).zip(&kernel) {
                    let j = i as isize + k;
                    if (0..len as isize).contains(&j) {
                        sum += w * src[line * stride + j as usize * step];
                    }
                }
                out[line * stride + i * step] = sum;
            }
        }
        out
    };
    let wide: Vec<f64> = gain.iter().map(|&g| f64::from(g)).collect();
    let rows = along(&wide, 1, width, height, width);
    along(&rows, width, height, width, 1)
        .into_iter()
        .map(|g| g as f32)
        .collect()
}

/// How many of the smoothing's 8 x 8 tiles of a square map `side` texels wide hold a non-zero
/// gain.
pub(crate) fn lit_tiles(gain: &[f32], side: u32) -> u32 {
    let tiles = side.div_ceil(8) as usize;
    let mut lit = vec![false; tiles * tiles];
    for (i, &g) in gain.iter().enumerate() {
        if g != 0.0 {
            let (x, y) = (i % side as usize, i / side as usize);
            lit[(y / 8) * tiles + x / 8] = true;
        }
    }
    lit.iter().filter(|&&l| l).count() as u32
}

/// The side of a square map.
pub(crate) fn square_side(gain: &[f32]) -> u32 {
    let side = (gain.len() as f64).sqrt() as u32;
    assert_eq!((side * side) as usize, gain.len(), "a square map");
    side
}

/// The texels `[x0, y0, x1, y1]` (ends excluded) holding every non-zero gain of a `width`
/// texels wide map; `None` when all are 0.
pub(crate) fn nonzero_box(gain: &[f32], width: u32) -> Option<[u32; 4]> {
    let mut b: Option<[u32; 4]> = None;
    for (i, _) in gain.iter().enumerate().filter(|(_, g)| **g != 0.0) {
        let (x, y) = (i as u32 % width, i as u32 / width);
        b = Some(match b {
            None => [x, y, x + 1, y + 1],
            Some([x0, y0, x1, y1]) => [x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1)],
        });
    }
    b
}

/// The largest difference of `gain` from `reference` outside the caustic region (where
/// `reference` is at most 0.1, as `relative_rms` leaves out): speckles of thinly spread light.
pub(crate) fn speckle(gain: &[f32], reference: &[f32]) -> f32 {
    gain.iter()
        .zip(reference)
        .filter(|&(_, r)| *r <= 0.1)
        .map(|(g, r)| (g - r).abs())
        .fold(0.0f32, f32::max)
}

/// The texel (column, row) with the largest gain.
pub(crate) fn peak(gain: &[f32], width: u32) -> (u32, u32) {
    let i = gain
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i as u32)
        .unwrap_or(0);
    (i % width, i / width)
}

/// The texel (continuous, pixel centres at half-integers) where the line from `light` through
/// the sphere's centre meets the floor, for a `w` x `h` map.
pub(crate) fn axis_texel(scene: &Scene, light: Vec3, w: u32, h: u32) -> Vec2 {
    let center = scene.object.center_m;
    let floor_y = scene.floor.pose.position.y;
    let dir = center - light;
    let axis_point = light + dir * ((floor_y - light.y) / dir.y);
    let local = scene
        .floor
        .world_from_plane()
        .inverse()
        .transform_point3(axis_point);
    Vec2::new((local.x + 0.5) * w as f32, (0.5 - local.y) * h as f32)
}

/// The mean of each `f` x `f` block of a square map `width` texels a side: the same light
/// over the same area on a map `f` times coarser.
pub(crate) fn block_mean(gain: &[f32], width: usize, f: usize) -> Vec<f32> {
    let w = width / f;
    let mut out = vec![0.0f32; w * w];
    for (i, texel) in out.iter_mut().enumerate() {
        let (x, y) = (i % w, i / w);
        let sum: f64 = (0..f * f)
            .map(|k| f64::from(gain[(y * f + k / f) * width + x * f + k % f]))
            .sum();
        *texel = (sum / (f * f) as f64) as f32;
    }
    out
}
