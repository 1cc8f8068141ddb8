//! Caustics computed on the GPU for the current pose (photon splatting, docs/caustics.md)
//! against the offline bake of the same scene at the same resolution, on the machine's
//! Vulkan device with validation on.

use std::time::Instant;

use glam::{Mat4, Quat, Vec2, Vec3};
use vitreous_frames::render_desc;
use vitreous_optics::live_caustics::LiveCausticsDesc;
use vitreous_render::{Renderer, ScenePose};
use vitreous_scene::load_scene;
use vitreous_tests::{shipped_scene, workspace};

use crate::live_maps::{
    LiveFrame, axis_texel, baked_at, baked_scene, lit_tiles, live_gains, live_gains_at, live_scene,
    peak, relative_rms, smoothed, speckle,
};

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
    assert_eq!(c.mode, vitreous_scene::CausticsMode::Live);
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
    let desc = render_desc::scene_desc(&scene, None);
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
    let rest = ScenePose::of(&render_desc::scene_desc(&scene, None));
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
    scene.caustics.mode = vitreous_scene::CausticsMode::Live;
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
            vitreous_optics::convex::is_convex(&mesh.positions, &mesh.indices),
            convex,
            "{name}"
        );
        let planes = vitreous_optics::convex::facet_planes(
            &mesh.positions,
            &mesh.normals,
            &mesh.indices,
            glam::Vec3::ZERO,
        );
        assert_eq!(planes.is_some(), faceted, "{name}");
        assert!(
            vitreous_optics::convex::is_closed(&mesh.positions, &mesh.indices),
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

/// One frame of `scene` with live caustics (`live`), counting its work or not, then a second
/// at the same pose: what each counted, and the live map.
fn counted_frames(
    scene: &vitreous_scene::Scene,
    live: LiveCausticsDesc,
    count: bool,
) -> ([Option<vitreous_render::PhotonWork>; 2], Vec<f32>) {
    let desc = render_desc::scene_desc(scene, None);
    let mut renderer =
        Renderer::new(vitreous_tests::validated_context(), &desc, 32, 32).expect("renderer");
    renderer.enable_live_caustics(&desc, live).expect("live");
    if count {
        assert!(renderer.count_invocations().unwrap(), "lavapipe counts");
    }
    let params = vitreous_render::FrameParams {
        eyes: vitreous_tests::neutral_eyes(scene),
        look: vitreous_render::Look {
            inducer: true,
            caustics: true,
            ..vitreous_render::Look::default()
        },
    };
    let want = vitreous_render::renderer::Want::default();
    let mut frame = || {
        renderer.submit(&params, want).expect("submit");
        renderer.flush().expect("flush").pop().expect("a frame")
    };
    // The second frame, at the same pose, computes nothing.
    let works = [frame().work.photons, frame().work.photons];
    let v = renderer.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
    let gain = renderer
        .live_caustic_gain()
        .unwrap()
        .expect("live caustics");
    (works, gain)
}

/// What a computation of the live map counts on the device (`PhotonWork`): the photons that
/// meet the object, against the solid angles of the spheres the tessellated ball lies between
/// and the torus's hole; their deposits; and the texels the smoothing wrote, against the tiles
/// it reports. Counting leaves the map as it is.
#[test]
fn the_live_maps_counted_photons_meet_the_ball_as_its_solid_angle_says() {
    let scene = baked_scene("glass-sphere.toml");
    let live = LiveCausticsDesc {
        photons_per_side: 96,
        ..LiveCausticsDesc::default()
    };
    let ([counted, still], gain) = counted_frames(&scene, live, true);
    let (uncounted, plain) = counted_frames(&scene, live, false);
    assert_eq!(uncounted, [None, None], "nothing counted unless asked");
    assert!(gain == plain, "counting changes no gain");
    let counted = counted.expect("the frame counted its photons");
    assert_eq!(still, Some(vitreous_render::PhotonWork::default()));
    // The emission cone just holds the ball's bounding sphere, so no photon meets the ball
    // outside it, and the shipped 96 x 48 ball holds the sphere of 0.9989 of its radius that
    // touches its flattest triangle's plane: at least 0.9989^2 = 0.9979 of the cone's photons
    // meet the ball (seen from the light 34 radii away, a sphere's solid angle goes as its
    // radius squared within 3e-4).
    let n = u64::from(live.photons_per_side).pow(2);
    assert!(
        counted.traced <= n && counted.traced as f64 >= 0.99 * n as f64,
        "{} of {n} photons traced",
        counted.traced
    );
    // Each traced photon's shadow, the light leaving the ball at its exits, and the reflections
    // off its front that reach the floor.
    assert!(
        counted.splatted > counted.traced && counted.splatted < 8 * counted.traced,
        "{counted:?}"
    );
    // The texels of the tiles the smoothing wrote: 8 x 8 each, those at the map's edges cut.
    let LiveFrame { tiles, .. } = live_gains(&scene, live, &[None], false).remove(0);
    let side = (gain.len() as f64).sqrt() as u64;
    assert!(
        counted.smoothed_texels <= u64::from(tiles[0]) * 64
            && counted.smoothed_texels > (u64::from(tiles[0]) * 64).saturating_sub(2 * 8 * side),
        "{counted:?}, {tiles:?}"
    );
    // The torus: the photons through its hole meet nothing and are not counted.
    let mut torus = load_scene(&workspace().join("config/scenes/torus.toml")).unwrap();
    torus.caustics.mode = vitreous_scene::CausticsMode::Live;
    torus.load_caustics().unwrap();
    let ([counted, _], _) = counted_frames(&torus, live, true);
    let counted = counted.expect("counted");
    // (7504 of 9216 here: the light 44 degrees off its axis sees it inside its bounding
    // sphere's disc, with the hole.)
    assert!(counted.traced < n * 9 / 10, "{counted:?}");
}
