//! Two-surface refraction through closed meshes that are not convex (the glass shader's search
//! of the object's triangles, shaders/glass.wgsl `mesh_hit`), on the machine's Vulkan device
//! with validation on, against the CPU mesh tracer (optics/src/two_surface.rs `pass_through`
//! through a `MeshBody`): the shipped torus, tilted so that rays leave the near side of its
//! ring and enter the far side, and the shipped goblet, whose cup a ray leaves and enters again
//! and whose stem and foot it meets past it. Three markers on the background photo, one per
//! colour channel: each marker's image in each eye lands where the tracer says.

use glam::{DVec2, Quat, Vec2, Vec3};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::two_surface::{MAX_INTERNAL_REFLECTIONS, MeshBody, pass_through};
use vitreous_tests::MeshData;

use crate::refraction::{
    CENTER, DISPARITY, IOR, RADIUS, Shot, background_plane, head_eyes, render_shot, shipped_model,
};

/// Eye image size.
const SIZE: (u32, u32) = (640, 480);
/// Texels per side of the photo.
const PHOTO: u32 = 512;
/// The markers' texel ranges (x, then y), red, green and blue.
const MARKERS: [((u32, u32), (u32, u32)); 3] = [
    ((236, 276), (236, 276)),
    ((200, 260), (110, 170)),
    ((330, 370), (280, 320)),
];
/// How far a marker's image may land from the tracer's, pixels.
const BAR_PX: f32 = 0.5;

/// A black photo with the three markers, each white in its own channel.
fn marker_photo() -> Vec<u8> {
    let mut px = vec![0u8; (PHOTO * PHOTO * 4) as usize];
    for y in 0..PHOTO {
        for x in 0..PHOTO {
            let i = ((y * PHOTO + x) * 4) as usize;
            px[i + 3] = 255;
            for (c, ((x0, x1), (y0, y1))) in MARKERS.iter().enumerate() {
                if (*x0..*x1).contains(&x) && (*y0..*y1).contains(&y) {
                    px[i + c] = 255;
                }
            }
        }
    }
    px
}

/// The value a bilinear, edge-clamped sampler reads at `uv` from the photo where it is white
/// over texels `xs` across and `ys` down, black elsewhere.
fn rect_seen(uv: Vec2, xs: (u32, u32), ys: (u32, u32)) -> f32 {
    let axis = |c: f32, (lo, hi): (u32, u32)| {
        let white =
            |t: i64| (i64::from(lo)..i64::from(hi)).contains(&t.clamp(0, i64::from(PHOTO) - 1));
        let f = c * PHOTO as f32 - 0.5;
        let i0 = f.floor();
        let a = f - i0;
        let i0 = i0 as i64;
        f32::from(u8::from(white(i0))) * (1.0 - a) + f32::from(u8::from(white(i0 + 1))) * a
    };
    axis(uv.x, xs) * axis(uv.y, ys)
}

/// The shipped model of `scene` (config/scenes) placed `RADIUS` in radius about `CENTER`,
/// turned by `turn`: the mesh in the world, and the same in the frame `render_shot` places
/// (scaled by RADIUS, half a turn about y, at CENTER).
fn placed(scene: &str, turn: Quat) -> (MeshData, MeshData) {
    let ((positions, normals, uvs, indices), world_from_model) = shipped_model(scene, turn);
    let world: Vec<Vec3> = positions
        .iter()
        .map(|&p| world_from_model.transform_point3(p))
        .collect();
    let normals: Vec<Vec3> = normals.iter().map(|&n| (turn * n).normalize()).collect();
    let back = Quat::from_rotation_y(-std::f32::consts::PI);
    let shot: Vec<Vec3> = world
        .iter()
        .map(|&p| back * (p - CENTER) / RADIUS)
        .collect();
    let shot_normals: Vec<Vec3> = normals.iter().map(|&n| back * n).collect();
    (
        (world, normals, uvs.clone(), indices.clone()),
        (shot, shot_normals, uvs, indices),
    )
}

/// Centroid of channel `c` of an sRGB image weighted by its linear light (pixels above 1 % of
/// white), and the weight.
fn centroid(rgba: &[u8], c: usize) -> (Vec2, f64) {
    let to_linear = |b: u8| ((f64::from(b) / 255.0 + 0.055) / 1.055).powf(2.4);
    let (mut sum, mut weight) = (DVec2::ZERO, 0.0);
    for (i, px) in rgba.chunks_exact(4).enumerate() {
        let l = to_linear(px[c]);
        if l > 0.01 {
            let i = i as u32;
            sum += DVec2::new(f64::from(i % SIZE.0) + 0.5, f64::from(i / SIZE.0) + 0.5) * l;
            weight += l;
        }
    }
    ((sum / weight.max(1e-30)).as_vec2(), weight)
}

/// Renders the shipped model of `scene` turned by `turn` with two-surface refraction towards the
/// photo, and holds each marker's image in each eye to the mesh tracer's; returns the share of
/// the markers' traced light that entered the object more than once.
fn markers_land_where_the_mesh_tracer_says(scene: &str, turn: Quat) -> f64 {
    let (world, shot_mesh) = placed(scene, turn);
    let body = MeshBody::new(&world.0, &world.1, &world.3).expect("a closed solid");
    let eyes = head_eyes(Vec3::ZERO, Quat::IDENTITY);
    let photo = marker_photo();
    let shot = Shot {
        look: DISPARITY,
        surface_dot: false,
        env_marker: false,
        refraction: Refraction::TwoSurface,
        eyes,
        ior: IOR,
        size: SIZE,
        photo: &photo,
        photo_texels: PHOTO,
    };
    let images = render_shot(&shot, (shot_mesh, 1.0));
    let plane = background_plane().inverse();
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let (mut again, mut all) = (0.0, 0.0);
    for (e, eye) in eyes.iter().enumerate() {
        let mut sums = [(DVec2::ZERO, 0.0f64); 3];
        for y in 0..SIZE.1 {
            for x in 0..SIZE.0 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let dir = eye.pixel_ray(p, size);
                let Some(pass) =
                    pass_through(&body, eye.position_m, dir, IOR, MAX_INTERNAL_REFLECTIONS)
                else {
                    continue;
                };
                let uv = pass
                    .escaped
                    .then(|| vitreous_optics::optics::plane_uv(pass.exit_m, pass.direction, plane))
                    .flatten();
                let Some(uv) = uv else { continue };
                for (c, &(xs, ys)) in MARKERS.iter().enumerate() {
                    // The photo as the GPU samples it: each marker filtered bilinearly.
                    let seen = rect_seen(uv, xs, ys);
                    let light = f64::from(pass.transmission * seen);
                    // Below the GPU centroid's 1 % floor in sRGB-encoded light.
                    if light > 0.01 {
                        sums[c].0 += p.as_dvec2() * light;
                        sums[c].1 += light;
                        all += light;
                        if pass.entries > 1 {
                            again += light;
                        }
                    }
                }
            }
        }
        for (c, &(sum, weight)) in sums.iter().enumerate() {
            let (gpu, gpu_weight) = centroid(&images[e], c);
            assert!(
                weight > 0.0,
                "{scene} eye {e}: the tracer sees no marker {c}"
            );
            let traced = (sum / weight).as_vec2();
            eprintln!(
                "{scene} eye {e} marker {c}: GPU {gpu} (weight {gpu_weight:.1}), mesh tracer \
                 {traced} (weight {weight:.1}): {:.3} px",
                (gpu - traced).length()
            );
            assert!(
                (gpu - traced).length() < BAR_PX,
                "{scene} eye {e} marker {c}: GPU at {gpu}, mesh tracer at {traced}"
            );
        }
    }
    again / all
}

#[test]
fn light_through_a_torus_lands_where_the_mesh_tracer_says() {
    let again = markers_land_where_the_mesh_tracer_says("torus.toml", Quat::from_rotation_x(0.35));
    eprintln!(
        "torus: {:.1} % of the markers' light entered twice",
        100.0 * again
    );
    assert!(
        again > 0.05,
        "too little light crosses the hole into the far side: {again}"
    );
}

#[test]
fn light_through_a_goblet_lands_where_the_mesh_tracer_says() {
    let again =
        markers_land_where_the_mesh_tracer_says("goblet-real.toml", Quat::from_rotation_x(0.2));
    eprintln!(
        "goblet: {:.1} % of the markers' light entered twice",
        100.0 * again
    );
    assert!(again > 0.05, "too little light crosses the cup: {again}");
}
