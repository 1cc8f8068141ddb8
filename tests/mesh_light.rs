//! The glass's light through a mesh that is neither a ball nor a convex gem, in the room, on the
//! machine's Vulkan device with validation on, against the physical reference's CPU ray tracer
//! (which splits the light at every surface): the shipped goblet (goblet-real.toml, eq. 6 off so
//! that the eye image is the glass's light itself) inside its outline, where every position of
//! a pixel meets the glass. Its mean light and its pixels come close to the real goblet's,
//! bowl and stem alike.

use glam::Vec2;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::display::Compensation;
use vitreous_optics::two_surface::Body;
use vitreous_reference::world::Glass;
use vitreous_reference::{Window, World, render_eye};
use vitreous_scene::Scene;
use vitreous_tests::{left_eye_light, neutral_eyes, shipped_scene};

const SIZE: (u32, u32) = (640, 480);

/// The pixels of `window` whose every corner's ray, and the centre's, meets `glass`: as (index
/// in the window, index in the whole image, row from the window's top).
fn covered(glass: &Glass, camera: &EyeParams, window: Window) -> Vec<(usize, usize, u32)> {
    let rays = camera.pixel_rays(Vec2::new(SIZE.0 as f32, SIZE.1 as f32));
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
                let index = ((window.y + y) * SIZE.0 + window.x + x) as usize;
                out.push(((y * window.width + x) as usize, index, y));
            }
        }
    }
    out
}

/// The goblet's bounding box on the left eye's image, with a margin of 2 pixels.
fn around_the_goblet(scene: &Scene, camera: &EyeParams) -> Window {
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let m = scene.object.world_from_model_at(
        scene.object.center_m,
        scene.rest_placement().object_rotation,
    );
    let (lo, hi) = scene.object.mesh.positions.iter().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| {
            let at = camera
                .project_to_pixel(m.transform_point3(p), size)
                .expect("the goblet in view");
            (lo.min(at), hi.max(at))
        },
    );
    let (x0, y0) = ((lo.x - 2.0).max(0.0) as u32, (lo.y - 2.0).max(0.0) as u32);
    Window {
        x: x0,
        y: y0,
        width: ((hi.x + 2.0) as u32).min(SIZE.0) - x0,
        height: ((hi.y + 2.0) as u32).min(SIZE.1) - y0,
    }
}

#[test]
fn the_goblets_light_comes_close_to_the_real_goblets() {
    let mut scene = shipped_scene("goblet-real.toml");
    scene.compensation = Compensation::None;
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_goblet(&scene, &camera);
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let glass = world.glass.clone().expect("the goblet");
    let pixels = covered(&glass, &camera, window);
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
