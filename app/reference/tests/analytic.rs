//! The reference against optics worked out by hand, independently of its vector code: the
//! image of a point seen through a tilted glass plate (the textbook lateral shift) and through a
//! glass ball (Snell's law as angles in the plane of the ray), at 1280 x 960 within 0.1 px; and
//! its floor light against the scene's caustic bake.
//!
//! The point's image is measured with a wall whose colour says where on it the light comes
//! from: the wall point the traced light of a pixel comes from, against the point, in pixels
//! of the local map from pixels to wall points. Every glass branch is in that light (the
//! weak ghosts of internal reflections too), so it is the image the tracer renders.

use std::path::Path;

use glam::{Mat4, Quat, Vec2, Vec3};
use vitreous_optics::absorption::Attenuation;
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_optics::solid::flat_cube;
use vitreous_reference::{Glass, Picture, Surface, World};

const SIZE: (u32, u32) = (1280, 960);
const IOR: f32 = 1.51;

/// A 40 x 30 degree eye at the origin looking down -z.
fn camera() -> EyeParams {
    let (h, v) = (20f32.to_radians(), 15f32.to_radians());
    EyeParams::new(
        Vec3::ZERO,
        Quat::IDENTITY,
        Fov {
            left_rad: -h,
            right_rad: h,
            up_rad: v,
            down_rad: -v,
        },
    )
}

/// Side of the wall square the tests look at, metres.
const WALL_M: f32 = 0.2;

/// A square of wall facing +z, centred on `point` (whose z it takes), whose photo says where
/// it is: red and green grow linearly with the photo's u and v, blue is 1. Nothing else in the
/// world but `glass`.
fn coordinate_world(point: Vec3, glass: Glass) -> World {
    const TEXELS: u32 = 256;
    let photo = Picture::from_fn(TEXELS, TEXELS, |x, y| {
        Vec3::new(
            (x as f32 + 0.5) / TEXELS as f32,
            (y as f32 + 0.5) / TEXELS as f32,
            1.0,
        )
    });
    World {
        floor: None,
        background: Some(Surface::new(
            Mat4::from_translation(point) * Mat4::from_scale(Vec3::new(WALL_M, WALL_M, 1.0)),
            photo,
        )),
        environment: None,
        glass: Some(glass),
        light_m: Vec3::new(0.0, 10.0, 0.0),
        light_share: 1.0,
        floor_light: None,
    }
}

/// The wall point the eye sees through `pixel` (where the traced light comes from): the
/// photo's colour over its blue, whatever fraction the glass passes.
fn seen_at(world: &World, pixel: Vec2) -> Vec3 {
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let dir = camera().pixel_rays(size).direction(pixel);
    let light = world.radiance(Vec3::ZERO, dir);
    assert!(
        light.z > 0.5,
        "the wall is not seen through {pixel}: {light}"
    );
    let uv = Vec2::new(light.x, light.y) / light.z;
    world.background.as_ref().unwrap().point(uv)
}

/// How many pixels from `pixel` the image of the wall point `spot` lies: the offset between
/// the point seen through `pixel` and `spot`, through the local map from pixels to wall points
/// (differences over one pixel).
fn image_error_px(world: &World, pixel: Vec2, spot: Vec3) -> f32 {
    let at = seen_at(world, pixel);
    let dx = seen_at(world, pixel + Vec2::X) - at;
    let dy = seen_at(world, pixel + Vec2::Y) - at;
    let offset = spot - at;
    // Solve [dx dy] e = offset in the wall's plane (x, y).
    let m = glam::Mat2::from_cols(dx.truncate(), dy.truncate());
    (m.inverse() * offset.truncate()).length()
}

/// A glass plate: `half` extents (x, y, thickness / 2) about the origin, turned by `rotation`
/// and moved to `centre`.
fn plate(half: Vec3, rotation: Quat, centre: Vec3) -> Glass {
    let (p, n, i) = flat_cube(1.0);
    let p: Vec<Vec3> = p.iter().map(|&p| rotation * (p * half) + centre).collect();
    let n: Vec<Vec3> = n.iter().map(|&n| rotation * n).collect();
    Glass::mesh(&p, &n, &i, IOR, Attenuation::NONE).unwrap()
}

#[test]
fn a_tilted_plate_shifts_a_point_by_the_textbook_lateral_displacement() {
    // A 12 mm plate 0.8 m ahead, turned 35 degrees about y and 10 about x; the spot 1.5 m
    // ahead, where the ray through the chosen pixel lands after the plate's shift.
    let thickness = 0.012;
    let rotation = Quat::from_rotation_y(35f32.to_radians()) * Quat::from_rotation_x(0.17);
    let glass = plate(
        Vec3::new(0.15, 0.15, thickness / 2.0),
        rotation,
        Vec3::new(0.02, -0.01, -0.8),
    );
    let pixel = Vec2::new(663.3, 497.8);
    let u = camera()
        .pixel_rays(Vec2::new(SIZE.0 as f32, SIZE.1 as f32))
        .direction(pixel);
    // d = t sin(theta_i - theta_t) / cos(theta_t), towards the plate's inward normal.
    let inward = -(rotation * Vec3::Z);
    let theta_i = u.dot(inward).acos();
    let theta_t = (theta_i.sin() / IOR).asin();
    let shift = thickness * (theta_i - theta_t).sin() / theta_t.cos();
    let towards = (inward - inward.dot(u) * u).normalize();
    let line = u * 0.0 + towards * shift;
    let s = (-1.5 - line.z) / u.z;
    let spot = line + u * s;
    assert!(shift > 0.003, "a visible shift: {shift} m");

    let world = coordinate_world(spot, glass);
    let error = image_error_px(&world, pixel, spot);
    eprintln!("image error {error} px");
    assert!(error < 0.1, "the spot's image is {error} px from {pixel}");
    // Without the shift the spot would be seen elsewhere: the test can fail.
    let unshifted = camera()
        .project_to_pixel(spot, Vec2::new(SIZE.0 as f32, SIZE.1 as f32))
        .unwrap();
    assert!(unshifted.distance(pixel) > 3.0, "{unshifted}");
    let unbent = image_error_px(&world, unshifted, spot);
    assert!(unbent > 3.0, "{unbent}");
}

#[test]
fn a_ball_images_a_point_where_snells_law_in_the_plane_of_the_ray_puts_it() {
    // An 80 mm ball about 1 m ahead, a little right and below; the spot on a wall 1 m behind
    // it, where the ray through the chosen pixel lands after both refractions.
    let centre = Vec3::new(0.05, -0.1, -1.0);
    let radius = 0.04;
    let glass = Glass::ball(centre, radius, IOR, Attenuation::NONE);
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let at_centre = camera().project_to_pixel(centre, size).unwrap();
    let pixel = at_centre + Vec2::new(21.3, -17.6);
    let u = camera().pixel_rays(size).direction(pixel);

    // The plane of the ray: x along the axis to the centre, y towards the ray.
    let distance = centre.length();
    let axis = centre / distance;
    let across = (u - u.dot(axis) * axis).normalize();
    let alpha = u.dot(axis).acos();
    let b = distance * alpha.sin();
    assert!(b < radius * 0.8, "the ray passes through the ball: b = {b}");
    let theta_i = (b / radius).asin();
    let theta_t = (theta_i.sin() / IOR).asin();
    let entry = (distance * alpha.cos() - (radius * radius - b * b).sqrt())
        * Vec2::new(alpha.cos(), alpha.sin());
    // Bent towards the axis by theta_i - theta_t at each surface; the chord is 2 R cos(theta_t).
    let inside = alpha - (theta_i - theta_t);
    let exit = entry + 2.0 * radius * theta_t.cos() * Vec2::new(inside.cos(), inside.sin());
    let out = alpha - 2.0 * (theta_i - theta_t);
    let to_world = |p: Vec2| axis * p.x + across * p.y;
    let direction = to_world(Vec2::new(out.cos(), out.sin()));
    let exit_m = to_world(exit);
    let wall_z = -2.0;
    let spot = exit_m + direction * ((wall_z - exit_m.z) / direction.z);

    let world = coordinate_world(spot, glass);
    let error = image_error_px(&world, pixel, spot);
    eprintln!("image error {error} px");
    assert!(error < 0.1, "the spot's image is {error} px from {pixel}");
    // A real ball inverts: the spot lies on the other side of the centre from its image.
    let seen_from_centre = (spot - centre).dot(across);
    assert!(seen_from_centre < 0.0, "not inverted: {seen_from_centre}");
}

#[test]
fn the_floor_light_puts_the_caustic_where_the_bake_does() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut scene =
        vitreous_scene::load_scene(&root.join("config/scenes/glass-sphere.toml")).unwrap();
    scene.load_caustics().unwrap();
    let bake = scene.caustics.gain.clone().unwrap();
    let world = World::of(&scene, &scene.rest_placement()).unwrap();
    let texel_m = scene.floor.size_m.x / bake.width_px as f32;
    let light = vitreous_reference::FloorLight::trace(
        &world,
        &vitreous_reference::PhotonParams {
            texel_m,
            photons_per_texel: 16.0,
            seed: 1,
        },
    )
    .unwrap();

    // The bake's peak texel.
    let (mut best, mut at) = (f32::MIN, (0, 0));
    for y in 0..bake.height_px {
        for x in 0..bake.width_px {
            let g = bake.gain_at(x, y);
            if g > best {
                best = g;
                at = (x, y);
            }
        }
    }
    let bake_uv = Vec2::new(
        (at.0 as f32 + 0.5) / bake.width_px as f32,
        (at.1 as f32 + 0.5) / bake.height_px as f32,
    );
    let (peak_uv, peak) = light.peak();
    let texels = (peak_uv - bake_uv) * Vec2::new(bake.width_px as f32, bake.height_px as f32);
    assert!(
        texels.abs().max_element() <= 1.0,
        "reference peak {peak_uv} (T = {peak}), bake peak {bake_uv} (G = {best}): {texels} texels apart"
    );
    eprintln!(
        "peaks {peak_uv} T={peak} / {bake_uv} G={best}: {texels}, noise {} photons {}",
        light.noise(),
        light.photons()
    );
    assert!(peak > 2.0, "a focused caustic: T = {peak}");
    assert!(light.noise() < 0.2, "noise {}", light.noise());
}
