//! The glass's light through a mesh that is neither a ball nor a convex gem, in the room, on the
//! machine's Vulkan device with validation on, against the physical reference's CPU ray tracer
//! (which splits the light at every surface): the shipped goblet (goblet-real.toml, eq. 6 off so
//! that the eye image is the glass's light itself) inside its outline, where every position of
//! a pixel meets the glass. Its mean light and its pixels come close to the real goblet's,
//! bowl and stem alike.

use glam::{Mat4, Vec2, Vec3};
use vitreous_frames::render_desc::scene_desc;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::display::Compensation;
use vitreous_optics::two_surface::Body;
use vitreous_reference::world::Glass;
use vitreous_reference::{FloorLight, PhotonParams, Window, World, render_eye};
use vitreous_render::{Composition, ScenePose, Want};
use vitreous_scene::Scene;
use vitreous_scene::caustics::Bake;
use vitreous_tests::{
    compose_once, left_eye_light, neutral_eyes, plain_params, scene_renderer, shipped_scene,
    torus_in_the_room,
};

/// The goblet's image size.
const SIZE: (u32, u32) = (640, 480);

/// The torus's image size: a quarter of the goblet's pixels (lavapipe shades a torus pixel for
/// tens of milliseconds), still hundreds of them inside its outline.
const TORUS_SIZE: (u32, u32) = (320, 240);

/// The pixels of `window` whose every corner's ray, and the centre's, meets `glass`: as (index
/// in the window, index in the whole image, row from the window's top).
fn covered(
    glass: &Glass,
    camera: &EyeParams,
    window: Window,
    size: (u32, u32),
) -> Vec<(usize, usize, u32)> {
    let rays = camera.pixel_rays(Vec2::new(size.0 as f32, size.1 as f32));
    let meets = |x: f32, y: f32| {
        glass
            .shape
            .enter(camera.position_m, rays.direction(Vec2::new(x, y)))
            .is_some()
    };
    let mut out = Vec::new();
    for y in 0..window.height {
        for x in 0..window.width {
            let (px, py) = ((window.x + x) as f32, (window.y + y) as f32);
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)];
            if corners.iter().all(|&(dx, dy)| meets(px + dx, py + dy)) {
                let index = ((window.y + y) * size.0 + window.x + x) as usize;
                out.push(((y * window.width + x) as usize, index, y));
            }
        }
    }
    out
}

/// The object's bounding box on the left eye's image of `size`, with a margin of 2 pixels.
fn around_the_object(scene: &Scene, camera: &EyeParams, size: (u32, u32)) -> Window {
    let pixels = Vec2::new(size.0 as f32, size.1 as f32);
    let m = scene.object.world_from_model_at(
        scene.object.center_m,
        scene.rest_placement().object_rotation,
    );
    let (lo, hi) = scene.object.mesh.positions.iter().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| {
            let at = camera
                .project_to_pixel(m.transform_point3(p), pixels)
                .expect("the object in view");
            (lo.min(at), hi.max(at))
        },
    );
    let (x0, y0) = ((lo.x - 2.0).max(0.0) as u32, (lo.y - 2.0).max(0.0) as u32);
    Window {
        x: x0,
        y: y0,
        width: ((hi.x + 2.0) as u32).min(size.0) - x0,
        height: ((hi.y + 2.0) as u32).min(size.1) - y0,
    }
}

#[test]
fn the_goblets_light_comes_close_to_the_real_goblets() {
    let mut scene = shipped_scene("goblet-real.toml");
    scene.compensation = Compensation::None;
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_object(&scene, &camera, SIZE);
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let glass = world.glass.clone().expect("the goblet");
    let pixels = covered(&glass, &camera, window, SIZE);
    assert!(
        pixels.len() > 500,
        "{} pixels inside the outline",
        pixels.len()
    );
    // The real goblet alone in the registered room, each pixel the mean over 3 x 3 positions.
    let real = render_eye(&world, &camera, SIZE, window, 3);
    let gpu = left_eye_light(&scene, SIZE);
    let mean = |of: &dyn Fn(usize, usize) -> f32, rows: &dyn Fn(u32) -> bool| {
        let chosen: Vec<_> = pixels.iter().filter(|p| rows(p.2)).collect();
        chosen.iter().map(|&&(w, i, _)| of(w, i)).sum::<f32>() / chosen.len() as f32
    };
    // The stem: the rows between the cup's bottom and the foot (the middle fifth of the
    // goblet's height, where it is a solid rod).
    let stem = |y: u32| (2 * window.height / 5..3 * window.height / 5).contains(&y);
    let all = |_: u32| true;
    let real_light = |w: usize, _: usize| real.rgb[w].element_sum();
    let gpu_light = |_: usize, i: usize| gpu[i].element_sum();
    let error = |w: usize, i: usize| (gpu[i] - real.rgb[w]).abs().element_sum();
    let (real_all, gpu_all, error_all) = (
        mean(&real_light, &all),
        mean(&gpu_light, &all),
        mean(&error, &all),
    );
    let (real_stem, gpu_stem) = (mean(&real_light, &stem), mean(&gpu_light, &stem));
    eprintln!(
        "goblet ({} px inside its outline): mean light GPU {gpu_all:.4}, real {real_all:.4}, \
         mean error {error_all:.4}; stem GPU {gpu_stem:.4}, real {real_stem:.4}",
        pixels.len()
    );
    assert!(
        (gpu_all / real_all - 1.0).abs() < 0.1,
        "the goblet's light {gpu_all} against the real goblet's {real_all}"
    );
    assert!(
        (gpu_stem / real_stem - 1.0).abs() < 0.2,
        "the stem's light {gpu_stem} against the real stem's {real_stem}"
    );
    assert!(
        error_all < 0.35 * real_all,
        "the goblet's pixels are {error_all} off the real goblet's {real_all}"
    );
}

/// The floor under a torus lying on the table as its glass shows it: lit as the floor's light
/// map says (its shadow and the bright ring of its caustic, for the light's half of the floor's
/// light; here the physical reference's own, as a bake stores it) rather than the bare photo.
/// Where the real torus's floor light changes what it shows, the GPU's changes the same way
/// and comes closer to it; with the object moved away from where the map was made, the glass
/// sees the bare photo again.
#[test]
fn the_floor_seen_through_a_torus_shows_its_shadow_and_caustic() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = torus_in_the_room(dir.path());
    scene.compensation = Compensation::None;
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_object(&scene, &camera, TORUS_SIZE);
    let bare = World::of(&scene, &scene.rest_placement()).unwrap();
    let lit = World {
        floor_light: FloorLight::trace(&bare, &PhotonParams::default()),
        ..bare.clone()
    };
    let floor_light = lit
        .floor_light
        .as_ref()
        .expect("the reference's floor light");
    let pixels = covered(bare.glass.as_ref().unwrap(), &camera, window, TORUS_SIZE);
    let real_bare = render_eye(&bare, &camera, TORUS_SIZE, window, 3);
    let real_lit = render_eye(&lit, &camera, TORUS_SIZE, window, 3);
    let gpu_bare = left_eye_light(&scene, TORUS_SIZE);
    // The map over the floor photo's area, texel centres, as a bake lays it out.
    let n = 1024u32;
    let light = (0..n * n)
        .map(|k| {
            let uv = (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32;
            floor_light.ratio(uv).element_sum() / 3.0
        })
        .collect();
    scene.caustics.gain = Some(Bake {
        width_px: n,
        height_px: n,
        gain: vec![0.0; (n * n) as usize],
        light: Some(light),
        inputs_hash: Some(scene.caustic_inputs_hash()),
        params: "method=reference".into(),
    });
    let gpu_lit = left_eye_light(&scene, TORUS_SIZE);
    // The pixels inside the outline whose real light the floor's light changes visibly.
    let changed: Vec<_> = pixels
        .iter()
        .filter(|&&(w, ..)| (real_lit.rgb[w] - real_bare.rgb[w]).abs().element_sum() > 0.03)
        .collect();
    let mean = |of: &dyn Fn(usize, usize) -> f32| {
        changed.iter().map(|&&(w, i, _)| of(w, i)).sum::<f32>() / changed.len() as f32
    };
    let real_change = mean(&|w, _| (real_lit.rgb[w] - real_bare.rgb[w]).abs().element_sum());
    let gpu_change = mean(&|w, i| {
        let sign = (real_lit.rgb[w] - real_bare.rgb[w]).element_sum().signum();
        (gpu_lit[i] - gpu_bare[i]).element_sum() * sign
    });
    let error_lit = mean(&|w, i| (gpu_lit[i] - real_lit.rgb[w]).abs().element_sum());
    let error_bare = mean(&|w, i| (gpu_bare[i] - real_lit.rgb[w]).abs().element_sum());
    eprintln!(
        "floor light under the torus: {} of {} px changed by {real_change:.4} (mean |change|), \
         the GPU's by {gpu_change:.4} the same way; error {error_bare:.4} with the bare photo, \
         {error_lit:.4} lit",
        changed.len(),
        pixels.len()
    );
    assert!(changed.len() > 40, "{} pixels changed", changed.len());
    assert!(
        gpu_change > 0.5 * real_change,
        "the GPU's light changed by {gpu_change} the real way where the real torus's changed by \
         {real_change}"
    );
    assert!(
        error_lit < 0.9 * error_bare,
        "lit {error_lit} against {error_bare} with the bare photo"
    );
    // The torus moved 1 mm: the map no longer holds, and the glass sees the bare photo (the
    // same image as without a map at that pose; a small one, to compare).
    let moved = |scene: &Scene| {
        let mut renderer = scene_renderer(scene, 160, 120);
        let rest = ScenePose::of(&scene_desc(scene, None));
        renderer.set_pose(ScenePose {
            world_from_model: Mat4::from_translation(Vec3::X * 0.001) * rest.world_from_model,
            ..rest
        });
        let params = plain_params(camera);
        let want = Want {
            eyes: true,
            world: false,
        };
        compose_once(&mut renderer, &params, want, Composition::Additive)
            .readback
            .expect("read back")
            .eyes[0]
            .clone()
    };
    let lit_moved = moved(&scene);
    scene.caustics.gain = None;
    assert!(
        lit_moved == moved(&scene),
        "the map is read with the object away from where it was made"
    );
}
