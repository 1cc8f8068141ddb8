//! The glass over several positions per pixel (`[output] glass_samples`) on the machine's
//! Vulkan device with validation on, against the physical reference's CPU ray tracer, which
//! averages each pixel over its own grid: the glass's pixels come closer to the real ball's
//! pixel averages than one position per pixel does (inside the disc, where the ball minifies the
//! room, and at the pixels that need several positions most: its outline, and the line where its
//! image turns from one photo to another), and the real floor or wall taken away
//! (`[display] compensation = "background"`) is the one over the pixel's footprint, as is the
//! world the see-through preview shows.

use glam::{Vec2, Vec3};
use vitreous_optics::camera::EyeParams;
use vitreous_optics::display::Compensation;
use vitreous_optics::optics::refract;
use vitreous_reference::world::PhotoHit;
use vitreous_reference::{EyeImage, Window, World, render_eye};
use vitreous_scene::Scene;
use vitreous_scene::effects::EffectSet;
use vitreous_tests::{
    compose_once, left_eye_light, left_world_view, neutral_eyes, shipped_scene, validated_context,
};

const SIZE: (u32, u32) = (320, 240);

/// The ball's outline on the left eye's image, with a margin of 3 pixels.
fn around_the_ball(scene: &Scene, camera: &EyeParams) -> Window {
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let centre = camera
        .project_to_pixel(scene.object.center_m, size)
        .unwrap();
    let rim = camera
        .project_to_pixel(
            scene.object.center_m + Vec3::X * scene.object.radius_m,
            size,
        )
        .unwrap();
    let reach = (rim - centre).length() + 3.0;
    let (x0, y0) = ((centre.x - reach) as u32, (centre.y - reach) as u32);
    let side = (2.0 * reach).ceil() as u32;
    Window {
        x: x0,
        y: y0,
        width: side.min(SIZE.0 - x0),
        height: side.min(SIZE.1 - y0),
    }
}

/// Pixels of `window` whose centre's ray passes the ball's centre within `share` of its
/// radius, as (index in the window, index in the whole image).
fn inside(scene: &Scene, camera: &EyeParams, window: Window, share: f32) -> Vec<(usize, usize)> {
    let rays = camera.pixel_rays(Vec2::new(SIZE.0 as f32, SIZE.1 as f32));
    let to = scene.object.center_m - camera.position_m;
    let mut out = Vec::new();
    for y in 0..window.height {
        for x in 0..window.width {
            let (px, py) = (window.x + x, window.y + y);
            let dir = rays.direction(Vec2::new(px as f32 + 0.5, py as f32 + 0.5));
            if (to - dir * to.dot(dir)).length() < share * scene.object.radius_m {
                out.push(((y * window.width + x) as usize, (py * SIZE.0 + px) as usize));
            }
        }
    }
    out
}

/// Mean summed-RGB difference between `gpu` (whole image) and `cpu` (the window) over `pixels`.
fn mean_error(gpu: &[Vec3], cpu: &[Vec3], pixels: &[(usize, usize)]) -> f32 {
    pixels
        .iter()
        .map(|&(w, i)| (gpu[i] - cpu[w]).abs().element_sum())
        .sum::<f32>()
        / pixels.len() as f32
}

fn with_samples(scene: &Scene, samples: u32, compensation: Compensation) -> Scene {
    let mut scene = scene.clone();
    scene.output.glass_samples = samples;
    scene.compensation = compensation;
    scene
}

fn reference(world: &World, camera: &EyeParams, window: Window, samples: u32) -> EyeImage {
    render_eye(world, camera, SIZE, window, samples)
}

#[test]
fn more_positions_per_pixel_bring_the_glass_to_the_real_balls_pixel_average() {
    let scene = shipped_scene("glass-sphere-real.toml");
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_ball(&scene, &camera);
    // The real ball alone in the registered room (its light on the floor left out: the glass
    // shader does not shade the floor it refracts), each pixel the mean over 5 x 5 positions:
    // a grid that neither of the GPU's below shares.
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let real = reference(&world, &camera, window, 5);
    // Inside the outline, where a pixel is all glass for both.
    let disc = inside(&scene, &camera, window, 0.9);
    assert!(disc.len() > 200, "{} pixels", disc.len());

    let one = mean_error(
        &left_eye_light(&with_samples(&scene, 1, Compensation::None), SIZE),
        &real.rgb,
        &disc,
    );
    let four = mean_error(
        &left_eye_light(&with_samples(&scene, 4, Compensation::None), SIZE),
        &real.rgb,
        &disc,
    );
    let mean = disc
        .iter()
        .map(|&(w, _)| real.rgb[w].element_sum())
        .sum::<f32>()
        / disc.len() as f32;
    eprintln!(
        "disc ({} px, real ball's light {mean:.3}): GPU error with 1 position per pixel \
         {one:.4}, with 4 x 4 {four:.4}",
        disc.len()
    );
    assert!(
        four < 0.3 * one,
        "4 x 4 positions ({four}) are not closer to the real ball than one ({one})"
    );
    assert!(
        four < 0.06 * mean,
        "4 x 4 positions are {four} off the real ball's {mean}"
    );
}

/// What the eye's ray along `dir` from `origin` meets beyond the scene's ball, refracted in and
/// out of it by Snell's law: 0 beside the ball, 1 the floor, 2 the wall, 3 neither.
fn target_through_ball(scene: &Scene, world: &World, origin: Vec3, dir: Vec3) -> u8 {
    let (centre, radius, ior) = (
        scene.object.center_m,
        scene.object.radius_m,
        scene.object.ior,
    );
    let from_centre = origin - centre;
    let b = from_centre.dot(dir);
    let c = from_centre.length_squared() - radius * radius;
    if b * b - c < 0.0 {
        return 0;
    }
    let entry = from_centre + dir * (-b - (b * b - c).sqrt());
    let Some(inside) = refract(dir, entry / radius, 1.0 / ior) else {
        return 3;
    };
    let exit = entry + inside * (-2.0 * entry.dot(inside));
    let Some(leaving) = refract(inside, -exit / radius, ior) else {
        return 3;
    };
    match world.photo_hit(exit + centre, leaving) {
        Some((_, PhotoHit::Floor(_))) => 1,
        Some((_, PhotoHit::Background(_))) => 2,
        None => 3,
    }
}

/// The pixels of `window` whose four corners' rays meet the ball in part (the outline), and
/// those whose corners all meet it but see different targets through it (where its image turns
/// from the wall to the floor, or from a photo to neither), as (index in the window, index in
/// the whole image).
type Pixels = Vec<(usize, usize)>;
fn outline_and_seams(scene: &Scene, camera: &EyeParams, window: Window) -> (Pixels, Pixels) {
    let world = World::of(scene, &scene.rest_placement()).unwrap();
    let rays = camera.pixel_rays(Vec2::new(SIZE.0 as f32, SIZE.1 as f32));
    let (mut outline, mut seams) = (Vec::new(), Vec::new());
    for y in 0..window.height {
        for x in 0..window.width {
            let (px, py) = (window.x + x, window.y + y);
            let corners = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(cx, cy)| {
                let dir = rays.direction(Vec2::new((px + cx) as f32, (py + cy) as f32));
                target_through_ball(scene, &world, camera.position_m, dir)
            });
            let at = ((y * window.width + x) as usize, (py * SIZE.0 + px) as usize);
            if corners.contains(&0) && corners.iter().any(|&t| t != 0) {
                outline.push(at);
            } else if !corners.contains(&0) && corners.iter().any(|&t| t != corners[0]) {
                seams.push(at);
            }
        }
    }
    (outline, seams)
}

#[test]
fn the_pixels_that_need_several_positions_are_shaded_at_several() {
    // The glass shades a ball's light in the room in parts, each over the positions it needs
    // (shaders/shared/glass_positions.wgsl): at its outline and along the line where its image
    // turns from one photo to another it must come closer to the real ball than one position
    // per pixel does.
    let scene = shipped_scene("glass-sphere-real.toml");
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_ball(&scene, &camera);
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let real = reference(&world, &camera, window, 5);
    let (outline, seams) = outline_and_seams(&scene, &camera, window);
    assert!(outline.len() > 40, "{} outline pixels", outline.len());
    assert!(seams.len() > 10, "{} seam pixels", seams.len());
    let one = left_eye_light(&with_samples(&scene, 1, Compensation::None), SIZE);
    let four = left_eye_light(&with_samples(&scene, 4, Compensation::None), SIZE);
    let errors = [("outline", &outline), ("seams", &seams)].map(|(name, pixels)| {
        let (e1, e4) = (
            mean_error(&one, &real.rgb, pixels),
            mean_error(&four, &real.rgb, pixels),
        );
        eprintln!(
            "{name} ({} px): GPU error with 1 position per pixel {e1:.4}, with 4 x 4 {e4:.4}",
            pixels.len()
        );
        (name, e1, e4)
    });
    // At the outline most of what is left is the rim's own light (the room a real ball reflects
    // at grazing incidence, which the Phong look does not draw), the same at any number of
    // positions; what they take away is the pixel's partial cover.
    for ((name, e1, e4), share) in errors.into_iter().zip([0.9, 0.5]) {
        assert!(
            e4 < share * e1,
            "{name}: {e4} with 4 x 4 against {e1} with one"
        );
    }
}

#[test]
fn the_background_taken_away_is_the_real_one_over_the_pixels_footprint() {
    let scene = shipped_scene("glass-sphere-real.toml");
    let camera = neutral_eyes(&scene)[0];
    let window = around_the_ball(&scene, &camera);
    let nothing = World::of(&scene, &scene.rest_placement())
        .unwrap()
        .without_object();
    // What the eye sees of the real floor and wall over each pixel (the mean over 5 x 5
    // positions), and at the pixel's centre.
    let seen = reference(&nothing, &camera, window, 5);
    let centre = reference(&nothing, &camera, window, 1);
    let glass = left_eye_light(&with_samples(&scene, 4, Compensation::None), SIZE);
    let shown = left_eye_light(&with_samples(&scene, 4, Compensation::Background), SIZE);
    let disc = inside(&scene, &camera, window, 0.95);
    let wanted = |w: usize, i: usize| (glass[i] - seen.rgb[w]).max(Vec3::ZERO);
    let mean = |f: &dyn Fn(usize, usize) -> f32| {
        disc.iter().map(|&(w, i)| f(w, i)).sum::<f32>() / disc.len() as f32
    };
    // The pass's B (the photos' ripmaps over the footprint) against the pixel's mean; and
    // what taking away B at the pixel's centre would leave.
    let footprint = mean(&|w, i| (shown[i] - wanted(w, i)).abs().element_sum());
    let at_centre = mean(&|w, i| {
        ((glass[i] - centre.rgb[w]).max(Vec3::ZERO) - wanted(w, i))
            .abs()
            .element_sum()
    });
    eprintln!(
        "{} glass pixels: mean difference from max(T - B, 0) with B the real floor or wall over \
         the pixel: {footprint:.4} as drawn (one fetch of the ripmaps), {at_centre:.4} with B at \
         the pixel's centre",
        disc.len()
    );
    assert!(footprint < 0.5 * at_centre, "{footprint} vs {at_centre}");
}

#[test]
fn the_world_view_with_several_positions_per_pixel_is_the_real_one_over_the_footprint() {
    let scene = shipped_scene("glass-sphere-real.toml");
    let camera = neutral_eyes(&scene)[0];
    let whole = Window {
        x: 0,
        y: 0,
        width: SIZE.0,
        height: SIZE.1,
    };
    let nothing = World::of(&scene, &scene.rest_placement())
        .unwrap()
        .without_object();
    // What the eye sees of the real floor and wall over each pixel (the mean over 5 x 5
    // positions).
    let seen = reference(&nothing, &camera, whole, 5);
    let over_footprint = left_world_view(&with_samples(&scene, 4, Compensation::None), SIZE);
    let at_centre = left_world_view(&with_samples(&scene, 1, Compensation::None), SIZE);
    // Each floor pixel's footprint on the photo, in photo texels: how far its neighbours'
    // rays along the row and down the column meet it (the far floor spans several texels).
    let rays = camera.pixel_rays(Vec2::new(SIZE.0 as f32, SIZE.1 as f32));
    let photo = &scene.floor.photo;
    let photo_texels = Vec2::new(photo.width as f32, photo.height as f32);
    let hit = |x: u32, y: u32| {
        let dir = rays.direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
        match nothing.photo_hit(camera.position_m, dir) {
            Some((_, PhotoHit::Floor(uv))) => Some(uv * photo_texels),
            _ => None,
        }
    };
    let mut wide = Vec::new();
    for y in 0..SIZE.1 - 1 {
        for x in 0..SIZE.0 - 1 {
            let (Some(at), Some(across), Some(down)) = (hit(x, y), hit(x + 1, y), hit(x, y + 1))
            else {
                continue;
            };
            if (across - at).abs().max((down - at).abs()).max_element() > 4.0 {
                let i = (y * SIZE.0 + x) as usize;
                wide.push((i, i));
            }
        }
    }
    let footprint_error = mean_error(&over_footprint, &seen.rgb, &wide);
    let centre_error = mean_error(&at_centre, &seen.rgb, &wide);
    let light = wide
        .iter()
        .map(|&(w, _)| seen.rgb[w].element_sum())
        .sum::<f32>()
        / wide.len() as f32;
    eprintln!(
        "floor pixels spanning over 4 texels: {}, the real floor's light {light:.3}; the world \
         view's mean difference from it {footprint_error:.4} over the footprint (4 x 4 \
         positions per glass pixel), {centre_error:.4} at the pixel's centre (one)",
        wide.len()
    );
    assert!(wide.len() > 1000, "{} pixels", wide.len());
    assert!(
        footprint_error < 0.5 * centre_error,
        "{footprint_error} vs {centre_error}"
    );
    assert!(
        footprint_error < 0.1 * light,
        "{footprint_error} of {light}"
    );
}

/// Pixels of the left eye's image of `(width, height)` none of whose positions of the glass's
/// grid (`samples` along each side) meets the ball, whose centre passes the ball's centre within
/// `reach` of its radius.
fn beside_the_ball(
    scene: &Scene,
    camera: &EyeParams,
    (width, height): (u32, u32),
    (samples, reach): (u32, f32),
) -> Vec<usize> {
    let size = Vec2::new(width as f32, height as f32);
    let (c, r) = (scene.object.center_m, scene.object.radius_m);
    let off = |p: Vec2| {
        let dir = camera.pixel_ray(p, size);
        let to = c - camera.position_m;
        (to - dir * to.dot(dir)).length()
    };
    (0..width * height)
        .filter(|&i| {
            let corner = Vec2::new((i % width) as f32, (i / width) as f32);
            let misses = (0..samples * samples).all(|k| {
                let grid = Vec2::new((k % samples) as f32, (k / samples) as f32);
                off(corner + (grid + 0.5) / samples as f32) >= r
            });
            misses && off(corner + 0.5) < reach * r
        })
        .map(|i| i as usize)
        .collect()
}

/// The left eye's display light (linear RGB) for `scene` at `size` with the floor's effects
/// (the inducer and the caustic, `c`), both eyes at the neutral head's left eye, composed for
/// an additive display, validation on.
fn left_light_with_the_floors_effects(scene: &Scene, size: (u32, u32)) -> Vec<Vec3> {
    use vitreous_render::{Composition, Reflection, Renderer, Want};
    let desc = vitreous_frames::render_desc::scene_desc(scene, None);
    let mut r = Renderer::new(validated_context(), &desc, size.0, size.1).expect("renderer");
    let eye = neutral_eyes(scene)[0];
    let params = vitreous_render::FrameParams {
        eyes: [eye, eye],
        look: vitreous_frames::look::base_look(
            &EffectSet::parse("c").unwrap(),
            Reflection::EnvironmentFresnel,
        ),
    };
    let want = Want {
        eyes: true,
        world: false,
    };
    let frame = compose_once(&mut r, &params, want, Composition::Additive);
    let eye = &frame.readback.expect("read back").eyes[0];
    eye.chunks_exact(4)
        .map(|p| Vec3::from_array([0, 1, 2].map(|c| vitreous_optics::srgb::to_linear(p[c]))))
        .collect()
}

#[test]
fn beside_the_ball_the_glass_leaves_what_the_floor_pass_drew() {
    // The ball's pipelines with several positions per pixel draw it on a coarse polyhedron
    // about its sphere (render/src/glass/proxy.rs) whose image reaches past the ball's outline:
    // there the glass draws nothing, and the eye image holds what the floor pass drew (the
    // inducer's ramp and the caustic), as with one position per pixel, drawn on the model.
    let scene = with_samples(
        &shipped_scene("glass-sphere-real.toml"),
        4,
        Compensation::None,
    );
    // Large enough that the polyhedron's image reaches pixels past the outline (its faces lie
    // up to a few per cent of the radius beyond the sphere).
    let size = (1280, 960);
    let camera = neutral_eyes(&scene)[0];
    let four = left_light_with_the_floors_effects(&scene, size);
    let one =
        left_light_with_the_floors_effects(&with_samples(&scene, 1, Compensation::None), size);
    let beside = beside_the_ball(&scene, &camera, size, (4, 1.1));
    let lit: Vec<usize> = beside
        .iter()
        .copied()
        .filter(|&i| one[i].element_sum() > 0.01)
        .collect();
    eprintln!(
        "{} pixels beside the ball, {} of them lit",
        beside.len(),
        lit.len()
    );
    assert!(lit.len() > 5, "{} lit pixels beside the ball", lit.len());
    for &i in &beside {
        assert!(
            (four[i] - one[i]).abs().max_element() < 1e-3,
            "pixel {i} beside the ball: {} with 4 x 4 positions, {} with one",
            four[i],
            one[i]
        );
    }
}
