//! The room as the glass's refraction and reflection target (`[environment] room = true`) on
//! the machine's Vulkan device with validation on, against the physical reference's CPU ray
//! tracer: where the real ball shows the floor magnified (the upper half of its disc), the
//! GPU's glass shows the same floor, and much closer to it than the environment map seen from
//! the ball's centre (the room off) does.

use glam::{Vec2, Vec3};
use vitreous_reference::{Window, World, render_eye};
use vitreous_tests::{left_eye_light, neutral_eyes, shipped_scene};

const SIZE: (u32, u32) = (320, 240);

/// The left eye's display light (linear RGB) with nothing taken away.
fn gpu_left(scene: &vitreous_scene::Scene) -> Vec<Vec3> {
    let mut scene = scene.clone();
    scene.compensation = vitreous_optics::display::Compensation::None;
    left_eye_light(&scene, SIZE)
}

#[test]
fn the_room_is_what_the_glass_refracts_as_a_real_ball_does() {
    let scene = shipped_scene("glass-sphere-real.toml");
    assert!(scene.environment.room);
    let camera = neutral_eyes(&scene)[0];
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let centre = camera
        .project_to_pixel(scene.object.center_m, size)
        .unwrap();
    // The real ball, alone in the registered room (its light on the floor left out: the
    // glass shader does not shade the floor it refracts).
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let whole = Window {
        x: 0,
        y: 0,
        width: SIZE.0,
        height: SIZE.1,
    };
    let real = render_eye(&world, &camera, SIZE, whole, 3);
    let seen = render_eye(&world.without_object(), &camera, SIZE, whole, 3);

    // Pixels well inside the upper half of the disc, where the real ball shows the floor.
    let rays = camera.pixel_rays(size);
    let radius = scene.object.radius_m;
    let upper: Vec<usize> = (0..SIZE.1)
        .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let pixel = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let dir = rays.direction(pixel);
            let to = scene.object.center_m - camera.position_m;
            let miss = (to - dir * to.dot(dir)).length();
            miss < 0.8 * radius && pixel.y < centre.y - 1.0
        })
        .map(|(x, y)| (y * SIZE.0 + x) as usize)
        .collect();
    assert!(upper.len() > 15, "{} pixels", upper.len());
    // The real ball's light there is not the floor behind it: the test can tell.
    let differs = upper
        .iter()
        .map(|&i| (real.rgb[i] - seen.rgb[i]).abs().element_sum())
        .sum::<f32>()
        / upper.len() as f32;

    let error = |gpu: &[Vec3]| {
        upper
            .iter()
            .map(|&i| (gpu[i] - real.rgb[i]).abs().element_sum())
            .sum::<f32>()
            / upper.len() as f32
    };
    let with_room = error(&gpu_left(&scene));
    let mut without = scene.clone();
    without.environment.room = false;
    let without_room = error(&gpu_left(&without));
    let mean = upper
        .iter()
        .map(|&i| real.rgb[i].element_sum())
        .sum::<f32>()
        / upper.len() as f32;
    eprintln!(
        "upper disc ({} px): real {mean:.4}, real - seen {differs:.4}; GPU error with the room \
         {with_room:.4}, without {without_room:.4}",
        upper.len()
    );
    assert!(differs > 0.1 * mean, "{differs} vs {mean}");
    assert!(
        with_room < 0.25 * mean,
        "the room's floor seen through the glass is {with_room} off the real ball's {mean}"
    );
    assert!(
        with_room < 0.7 * without_room,
        "the room ({with_room}) is not closer to the real ball than the map ({without_room})"
    );
}
