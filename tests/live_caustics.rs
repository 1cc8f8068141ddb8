//! Caustics computed on the GPU for the current pose (photon splatting, docs/caustics.md)
//! against the offline bake of the same scene at the same resolution, on the machine's
//! Vulkan device with validation on.

use std::time::Instant;

use glam::{Mat4, Quat, Vec2, Vec3};
use vitreous::scene::{Scene, load_scene};
use vitreous::views;
use vitreous_render::camera::{EyeParams, Fov};
use vitreous_render::floor::LiveCausticsDesc;
use vitreous_render::renderer::Want;
use vitreous_render::{FrameParams, Look, Renderer, ScenePose};
use vitreous_tests::{shipped_scene, workspace};

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
    live.caustics.mode = vitreous::scene::CausticsMode::Live;
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
    tiles: [u32; 2],
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
    let rest = ScenePose::of(&views::scene_desc(scene, None));
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
fn live_gains_at(
    scene: &Scene,
    live: LiveCausticsDesc,
    poses: &[Option<ScenePose>],
    fields_first: bool,
) -> Vec<LiveFrame> {
    let ctx = vitreous_tests::validated_context();
    let desc = views::scene_desc(scene, None);
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
fn lit_tiles(gain: &[f32], side: u32) -> u32 {
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
fn square_side(gain: &[f32]) -> u32 {
    let side = (gain.len() as f64).sqrt() as u32;
    assert_eq!((side * side) as usize, gain.len(), "a square map");
    side
}

/// The texels `[x0, y0, x1, y1]` (ends excluded) holding every non-zero gain of a `width`
/// texels wide map; `None` when all are 0.
fn nonzero_box(gain: &[f32], width: u32) -> Option<[u32; 4]> {
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

#[test]
fn live_sphere_caustics_match_the_bake_and_focus_on_the_light_axis() {
    check_sphere(None, LiveCausticsDesc::default());
}

/// The moving-light scene's own map, photons and smoothing (fewer than the defaults: the
/// ball's caustic is smooth) meet the same bar at the glass sphere's pose.
#[test]
fn the_moving_light_scenes_settings_match_the_bake_too() {
    let moving = shipped_scene("moving-light.toml");
    let c = &moving.caustics;
    assert_eq!(c.mode, vitreous::scene::CausticsMode::Live);
    let live = LiveCausticsDesc {
        photons_per_side: c.photons_per_side,
        smoothing_px: c.smoothing_px,
        min_path_weight: c.min_path_weight,
        ..LiveCausticsDesc::default()
    };
    assert!(
        live.photons_per_side < LiveCausticsDesc::default().photons_per_side,
        "the scene's own, fewer photons"
    );
    check_sphere(Some(c.resolution_px), live);
    // The paths its larger least weight ends carry little light: the map's total is lower
    // than with the default weight, by less than 1 %.
    let (scene, _) = live_scene("glass-sphere.toml", Some(c.resolution_px));
    let total = |min_path_weight| -> f64 {
        let desc = LiveCausticsDesc {
            min_path_weight,
            ..live
        };
        let frames = live_gains(&scene, desc, &[None], false);
        frames[0].gain.iter().map(|&g| f64::from(g)).sum()
    };
    let default = LiveCausticsDesc::default().min_path_weight;
    assert!(
        live.min_path_weight > default,
        "the scene's own, larger weight"
    );
    let (cut, full) = (total(live.min_path_weight), total(default));
    eprintln!(
        "total G {cut:.1} with paths ending below {}, {full:.1} below {default}",
        live.min_path_weight
    );
    assert!(cut < full && cut > 0.99 * full, "{cut} against {full}");
}

/// Live settings outside their ranges are refused with an error, and the renderer still
/// draws with its bake.
#[test]
fn live_settings_out_of_range_are_refused() {
    let scene = baked_scene("glass-sphere.toml");
    let desc = views::scene_desc(&scene, None);
    let mut renderer =
        Renderer::new(vitreous_tests::validated_context(), &desc, 32, 32).expect("renderer");
    let good = LiveCausticsDesc::default();
    let bad = [
        LiveCausticsDesc {
            photons_per_side: 0,
            ..good
        },
        LiveCausticsDesc {
            max_interactions: 0,
            ..good
        },
        LiveCausticsDesc {
            smoothing_px: 65,
            ..good
        },
    ]
    .into_iter()
    .chain(
        [0.0, 1.0, -0.1, f32::NAN].map(|min_path_weight| LiveCausticsDesc {
            min_path_weight,
            ..good
        }),
    );
    for live in bad {
        let error = renderer.enable_live_caustics(&desc, live).unwrap_err();
        assert!(
            matches!(error, vitreous_render::RenderError::InvalidInput(_)),
            "{live:?}: {error}"
        );
    }
    assert_eq!(renderer.live_caustic_gain().expect("no map"), None);
}

/// The glass sphere's live map on a `side` x `side` map (`None`: the default) with `live`:
/// within 5 % relative RMS of the baker's map at that resolution smoothed alike and of the
/// shipped bake averaged to it, its peak within a texel of where the light's axis through
/// the sphere's centre meets the floor, at the shipped pose and with the light turned a
/// quarter round.
fn check_sphere(side: Option<u32>, live: LiveCausticsDesc) {
    let (scene, averaged) = live_scene("glass-sphere.toml", side);
    let (w, h) = (scene.caustics.resolution_px, scene.caustics.resolution_px);
    // The shipped pose, then the light turned a quarter round the sphere (to its left).
    let center = scene.object.center_m;
    let offset = scene.light.position_m - center;
    let turned = center + Quat::from_rotation_y(std::f32::consts::FRAC_PI_2) * offset;
    let frames = live_gains(&scene, live, &[None, Some(turned)], false);
    let LiveFrame { gain, wall_ms, .. } = &frames[0];
    // The baker's map at the live map's resolution, and the shipped bake averaged down to it.
    let reference = smoothed(&baked_at(&scene, w, 1 << 18), w as usize, live.smoothing_px);
    let rms = relative_rms(gain, &reference);
    let rms_averaged = relative_rms(gain, &smoothed(&averaged, w as usize, live.smoothing_px));
    let (bx, by) = peak(&reference, w);
    for (LiveFrame { gain, wall_ms, .. }, light) in
        frames.iter().zip([scene.light.position_m, turned])
    {
        let (px, py) = peak(gain, w);
        let expected = axis_texel(&scene, light, w, h);
        eprintln!(
            "live sphere caustics at {w}x{h}, light at {light}: peak G {:.0} at ({px}, {py}), \
             the light axis meets the floor at ({:.2}, {:.2}); frame with the computation \
             {wall_ms:.0} ms wall clock",
            gain[(py * w + px) as usize],
            expected.x,
            expected.y
        );
        let centre = Vec2::new(px as f32 + 0.5, py as f32 + 0.5);
        assert!(
            (centre - expected).abs().max_element() <= 1.0,
            "peak at {centre}, the axis at {expected}"
        );
    }
    eprintln!(
        "{n}^2 photons: relative RMS {:.2} % against the baker's map at {w}x{h} smoothed alike \
         (box radius {} texels; peak {:.0} at ({bx}, {by})), {:.2} % against the shipped bake \
         averaged to it; first frame {wall_ms:.0} ms",
        rms * 100.0,
        live.smoothing_px,
        reference[(by * w + bx) as usize],
        rms_averaged * 100.0,
        n = live.photons_per_side
    );
    assert!(rms < 0.05, "relative RMS {rms}");
    assert!(
        rms_averaged < 0.05,
        "relative RMS {rms_averaged} against the averaged bake"
    );
    // Outside the caustic region, where the relative figure does not look (the baker's map
    // below 0.1 there), too few photons show as speckles: single texels of thinly spread light
    // well off the baker's map. The defaults are at most 0.19 off, the moving-light scene's
    // settings 0.13; with 48 x 48 photons on its 495 x 495 map 0.28, with 32 x 32 0.72.
    let speckle = speckle(gain, &reference);
    eprintln!("outside the caustic region at most {speckle:.3} off the baker's map");
    assert!(speckle <= 0.25, "a speckle {speckle} off the baker's map");
}

/// Every way the GPU smooths (no box, the short kernel's passes for radii 1 and 2, the ring
/// buffers' for wider boxes) against the CPU's direct convolution of the GPU's unsmoothed
/// map, on maps whose width is no multiple of four (their rows are padded on the GPU): the
/// default 990 x 990, and 66 x 66, where the widest box spans half the map.
#[test]
fn the_gpu_smoothing_is_the_three_box_kernel_at_every_radius() {
    for side in [990, 66] {
        let (scene, _) = live_scene("glass-sphere.toml", Some(side));
        assert_ne!(side % 4, 0, "the rows need padding");
        let gains = |smoothing_px| {
            let live = LiveCausticsDesc {
                smoothing_px,
                ..LiveCausticsDesc::default()
            };
            live_gains(&scene, live, &[None], false).remove(0).gain
        };
        let raw = gains(0);
        assert_eq!(raw.len(), (side * side) as usize);
        assert!(
            raw.iter().all(|&g| g == 0.0 || g >= 1e-3),
            "gains below MIN_GAIN are zeroed"
        );
        let raw_peak = raw.iter().copied().fold(0.0f32, f32::max);
        assert!(
            raw_peak > 0.1,
            "{side}: the caustic is in the unsmoothed map ({raw_peak})"
        );
        for radius in [1, 2, 3, 5] {
            let gpu = gains(radius);
            let cpu = smoothed(&raw, side as usize, radius);
            let peak_gpu = gpu.iter().copied().fold(0.0f32, f32::max);
            let peak_cpu = cpu.iter().copied().fold(0.0f32, f32::max);
            let worst = gpu
                .iter()
                .zip(&cpu)
                .map(|(g, c)| (g - c).abs())
                .fold(0.0f32, f32::max);
            eprintln!(
                "{side} x {side}, radius {radius}: worst texel {worst:.2e} off the CPU's \
                 smoothing of the unsmoothed map, peak G {peak_gpu:.3} against {peak_cpu:.3}"
            );
            // The GPU smooths the sums before zeroing gains below MIN_GAIN (0.001), the CPU
            // the map zeroed first (up to 0.001 a texel); wide boxes round their sums to f32
            // (a few 1e-5 of the peak): that is all that may differ.
            assert!(
                worst <= 2e-3 + 2e-4 * peak_cpu,
                "{side}, radius {radius}: a texel {worst} off"
            );
            assert!(
                (peak_gpu - peak_cpu).abs() <= 1e-3 * peak_cpu,
                "{side}, radius {radius}"
            );
            assert!(
                gpu.iter().all(|&g| g == 0.0 || g >= 1e-3),
                "{side}, radius {radius}: gains below MIN_GAIN are zeroed"
            );
        }
    }
}

/// The short kernel's passes skip the tiles whose gains are certain to be stored as 0: the
/// map is the same, bit for bit, as when every texel is smoothed, at every radius they take,
/// on maps whose rows are padded (18 x 18: three tiles across, the last of one vector of
/// four); and they do skip most of the glass sphere's floor.
#[test]
fn skipping_tiles_leaves_the_map_unchanged() {
    for side in [990, 66, 18] {
        let (scene, _) = live_scene("glass-sphere.toml", Some(side));
        for smoothing_px in [0, 1, 2] {
            let frame = |skip_tiles| {
                let live = LiveCausticsDesc {
                    smoothing_px,
                    skip_tiles,
                    ..LiveCausticsDesc::default()
                };
                live_gains(&scene, live, &[None], false).remove(0)
            };
            let (skipping, every) = (frame(true), frame(false));
            let [written, total] = skipping.tiles;
            eprintln!(
                "{side} x {side}, radius {smoothing_px}: {written} of {total} tiles written \
                 ({:.0} %), {} hold gains",
                100.0 * f64::from(written) / f64::from(total),
                lit_tiles(&skipping.gain, side)
            );
            assert_eq!(every.tiles, [total, total], "without skipping every tile");
            let differing = skipping
                .gain
                .iter()
                .zip(&every.gain)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            assert_eq!(differing, 0, "{side}, radius {smoothing_px}: texels differ");
            // On the 18 x 18 map (55 mm texels) the smoothed focus stays below 0.1.
            let least = if side >= 66 { 0.1 } else { 0.0 };
            assert!(
                skipping.gain.iter().any(|&g| g > least),
                "{side}, radius {smoothing_px}: the caustic is there"
            );
            if side == 990 {
                // The sphere's caustic and the light it reflects cover about a third of the
                // floor's tiles (smoothed over more, a little more).
                assert!(
                    written * 2 < total,
                    "radius {smoothing_px}: {written} of {total} tiles written"
                );
            }
        }
    }
}

#[test]
fn live_diamond_caustics_match_the_bake() {
    let (scene, averaged) = live_scene("diamond.toml", None);
    let side = scene.caustics.resolution_px;
    let live = LiveCausticsDesc::default();
    let frames = live_gains(&scene, live, &[None], false);
    let LiveFrame { gain, wall_ms, .. } = &frames[0];
    let reference = smoothed(
        &baked_at(&scene, side, 1 << 18),
        side as usize,
        live.smoothing_px,
    );
    let rms = relative_rms(gain, &reference);
    let rms_averaged = relative_rms(gain, &smoothed(&averaged, side as usize, live.smoothing_px));
    let region = reference.iter().filter(|&&g| g > 0.1).count();
    eprintln!(
        "live diamond caustics at {side}x{side}, {}^2 photons, smoothing radius {} texels: \
         relative RMS {:.2} % against the baker's map at that size smoothed alike over {region} \
         texels, {:.2} % against the shipped bake averaged to it; frame {wall_ms:.0} ms",
        live.photons_per_side,
        live.smoothing_px,
        rms * 100.0,
        rms_averaged * 100.0
    );
    assert!(
        rms_averaged < 0.05,
        "relative RMS {rms_averaged} against the averaged bake"
    );
    // About 1100 mm^2 of the 1 m floor.
    assert!(region > 500, "the diamond's caustic covers {region} texels");
    assert!(rms < 0.05, "relative RMS {rms}");
}

#[test]
fn live_caustics_follow_the_object() {
    // The diamond and the light moved together 50 texels along the floor's x: the same light
    // falls 50 texels further on, up to the fixed point's rounding. Photons are traced in the
    // object's model space, so a move that did not reach them would leave the map in place.
    let (scene, _) = live_scene("diamond.toml", None);
    let side = scene.caustics.resolution_px as usize;
    let rest = ScenePose::of(&views::scene_desc(&scene, None));
    let texels = 50;
    let shift = Vec3::X * scene.floor.size_m.x * texels as f32 / side as f32;
    let moved = ScenePose {
        world_from_model: Mat4::from_translation(shift) * rest.world_from_model,
        light_position_m: rest.light_position_m + shift,
    };
    let frames = live_gains_at(
        &scene,
        LiveCausticsDesc::default(),
        &[None, Some(moved)],
        false,
    );
    let (at_rest, after) = (&frames[0].gain, &frames[1].gain);
    // The moved map read 50 texels on, against the map at rest (zeros past the edge).
    let back: Vec<f32> = (0..side * side)
        .map(|i| {
            let (x, y) = (i % side, i / side);
            if x + texels < side {
                after[y * side + x + texels]
            } else {
                0.0
            }
        })
        .collect();
    let rms = relative_rms(&back, at_rest);
    let unmoved = relative_rms(after, at_rest);
    eprintln!(
        "the diamond moved {texels} texels: relative RMS {:.4} % against the map at rest \
         shifted alike, {:.1} % unshifted",
        rms * 100.0,
        unmoved * 100.0
    );
    assert!(rms < 0.005, "relative RMS {rms}");
    assert!(unmoved > 0.5, "the map hardly moved: {unmoved}");
}

#[test]
fn live_torus_caustics_match_a_bake_of_it() {
    // Any closed mesh: the torus is not convex, and photons through its hole cross the shell
    // its surface lies in twice. The reference is a bake of it made here at the live map's
    // resolution (a quarter of the shipped bakes' rays).
    let path = workspace().join("config/scenes/torus.toml");
    let mut scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.caustics.mode = vitreous::scene::CausticsMode::Live;
    scene.load_caustics().unwrap_or_else(|e| panic!("{e}"));
    let side = scene.caustics.resolution_px;
    let started = Instant::now();
    let bake = baked_at(&scene, side, 1 << 16);
    let bake_s = started.elapsed().as_secs_f64();
    let live = LiveCausticsDesc::default();
    let LiveFrame { gain, wall_ms, .. } = &live_gains(&scene, live, &[None], false)[0];
    let reference = smoothed(&bake, side as usize, live.smoothing_px);
    let rms = relative_rms(gain, &reference);
    let region = reference.iter().filter(|&&g| g > 0.1).count();
    eprintln!(
        "live torus caustics at {side}x{side}: relative RMS {:.2} % against its bake smoothed \
         alike over {region} texels; frame {wall_ms:.0} ms, bake {bake_s:.1} s",
        rms * 100.0
    );
    assert!(region > 5000, "the torus's caustic covers {region} texels");
    assert!(rms < 0.05, "relative RMS {rms}");
}

#[test]
fn the_shipped_sphere_and_diamond_are_convex_the_torus_is_not() {
    // Photons leaving a convex mesh outward skip the search for another surface, and inside
    // the diamond (flat facets) they leave through its facet planes without the grid; the
    // shadow mask of a closed one (all three) is drawn from one side's triangles, of a convex
    // one as the hull of its projected vertices.
    for (name, convex, faceted) in [
        ("glass-sphere.toml", true, false),
        ("diamond.toml", true, true),
        ("torus.toml", false, false),
    ] {
        let path = workspace().join("config/scenes").join(name);
        let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let mesh = &scene.object.mesh;
        assert_eq!(
            vitreous_render::convex::is_convex(&mesh.positions, &mesh.indices),
            convex,
            "{name}"
        );
        let planes = vitreous_render::convex::facet_planes(
            &mesh.positions,
            &mesh.normals,
            &mesh.indices,
            glam::Vec3::ZERO,
        );
        assert_eq!(planes.is_some(), faceted, "{name}");
        assert!(
            vitreous_render::convex::is_closed(&mesh.positions, &mesh.indices),
            "{name}"
        );
    }
}

#[test]
fn reading_the_fields_back_first_computes_the_live_map_too() {
    // A read-back of the inducer's fields computes the pose's work, the live caustic map with
    // it: the frame after it must show that map, not an empty one, and the same one as a
    // frame without the read-back (integer atomics: the same bits).
    let (scene, _) = live_scene("diamond.toml", None);
    let live = LiveCausticsDesc::default();
    let plain = live_gains(&scene, live, &[None], false);
    let after_read_back = live_gains(&scene, live, &[None], true);
    let lit = plain[0].gain.iter().filter(|&&g| g > 0.0).count();
    assert!(lit > 1000, "the live map has {lit} lit texels");
    assert!(
        plain[0].gain == after_read_back[0].gain,
        "the map after a read-back differs ({} lit texels)",
        after_read_back[0].gain.iter().filter(|&&g| g > 0.0).count()
    );
}

/// The mean of each `f` x `f` block of a square map `width` texels a side: the same light
/// over the same area on a map `f` times coarser.
fn block_mean(gain: &[f32], width: usize, f: usize) -> Vec<f32> {
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
