//! The patches against the triangles themselves: every triangle that faces the eye and whose
//! image meets a rectangle is drawn there, once.

use super::*;
use proptest::prelude::*;
use vitreous_optics::camera::Fov;

/// A ball of radius 1 about `center` as latitude rings and longitude segments, wound either
/// way (the patches do not rely on the winding).
fn ball(center: Vec3, rings: u32, segments: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut positions = Vec::new();
    for ring in 0..=rings {
        let polar = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..=segments {
            let around = std::f32::consts::TAU * segment as f32 / segments as f32;
            let (s, c) = polar.sin_cos();
            positions.push(center + Vec3::new(s * around.cos(), c, s * around.sin()));
        }
    }
    let mut indices = Vec::new();
    let at = |ring: u32, segment: u32| ring * (segments + 1) + segment;
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b) = (at(ring, segment), at(ring, segment + 1));
            let (c, d) = (at(ring + 1, segment), at(ring + 1, segment + 1));
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    (positions, indices)
}

fn eye(position_m: Vec3, yaw: f32, pitch: f32) -> EyeParams {
    let (h, v) = (20f32.to_radians(), 15f32.to_radians());
    let fov = Fov {
        left_rad: -h,
        right_rad: h,
        up_rad: v,
        down_rad: -v,
    };
    let turn = glam::Quat::from_rotation_y(yaw) * glam::Quat::from_rotation_x(pitch);
    EyeParams::new(position_m, turn, fov)
}

const EXTENT: (u32, u32) = (320, 240);

/// The triangles (as their place in the reordered indices, in triangles) that face the eye and
/// whose image's box meets `rect`, by the triangles themselves.
fn must_draw(
    patches: &Patches,
    positions: &[Vec3],
    world_from_model: Mat4,
    eye: &EyeParams,
    rect: [u32; 4],
) -> Vec<usize> {
    let clip_from_model = eye.clip_from_world() * world_from_model;
    let eye_m = world_from_model.inverse().transform_point3(eye.position_m);
    let size = Vec2::new(EXTENT.0 as f32, EXTENT.1 as f32);
    let [x, y, w, h] = rect.map(|v| v as f32);
    patches
        .indices
        .chunks_exact(3)
        .enumerate()
        .filter(|(_, t)| {
            let v = [0, 1, 2].map(|i| positions[t[i] as usize]);
            let mut n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            if n.dot(v[0] + v[1] + v[2] - 3.0 * patches.center) < 0.0 {
                n = -n;
            }
            let clips = v.map(|p| clip_from_model * p.extend(1.0));
            if n.dot(eye_m - v[0]) <= 1e-6 || clips.iter().any(|c| c.w <= 1e-3) {
                return false;
            }
            let pixels = clips.map(|c| (c.truncate().truncate() / c.w + 1.0) * 0.5 * size);
            let lo = pixels[0].min(pixels[1]).min(pixels[2]);
            let hi = pixels[0].max(pixels[1]).max(pixels[2]);
            lo.x < x + w && hi.x > x && lo.y < y + h && hi.y > y
        })
        .map(|(i, _)| i)
        .collect()
}

#[test]
fn the_indices_are_the_meshs_triangles_in_another_order() {
    let center = Vec3::new(0.1, -0.2, 0.3);
    let (positions, indices) = ball(center, 24, 48);
    let patches = Patches::new(&positions, &indices, center);
    let sorted = |i: &[u32]| {
        let mut t: Vec<[u32; 3]> = i.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        t.sort();
        t
    };
    assert_eq!(sorted(&patches.indices), sorted(&indices));
    let mut end = 0;
    for patch in &patches.patches {
        assert_eq!(patch.indices.start, end);
        end = patch.indices.end;
    }
    assert_eq!(end as usize, indices.len());
}

#[test]
fn a_ball_seen_from_outside_draws_its_near_half() {
    let (positions, indices) = ball(Vec3::ZERO, 48, 96);
    let patches = Patches::new(&positions, &indices, Vec3::ZERO);
    let world_from_model = Mat4::from_scale_rotation_translation(
        Vec3::splat(0.075),
        glam::Quat::IDENTITY,
        Vec3::new(0.0, 0.0, -0.6),
    );
    let eye = eye(Vec3::ZERO, 0.0, 0.0);
    let seen = patches.seen(world_from_model, &eye, EXTENT);
    let whole = patches.ranges(&seen, [0, 0, EXTENT.0, EXTENT.1]);
    let drawn: u32 = whole.iter().map(|r| r.len() as u32).sum();
    let share = drawn as f32 / indices.len() as f32;
    assert!((0.5..0.75).contains(&share), "{share}");
    // A corner of the image, away from the ball: nothing.
    assert!(patches.ranges(&seen, [0, 0, 40, 30]).is_empty());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Soundness: the ranges for a rectangle hold every triangle that faces the eye and whose
    /// image meets it, each once, the ball anywhere about the eye, turned any way.
    #[test]
    fn every_triangle_that_can_show_in_a_rectangle_is_drawn_there(
        at in prop::array::uniform3(-0.4f32..0.4),
        scale in 0.02f32..0.3,
        spin in prop::array::uniform3(-3.2f32..3.2),
        yaw in -0.6f32..0.6,
        pitch in -0.4f32..0.4,
        corner in (0u32..320, 0u32..240),
        size in (1u32..320, 1u32..240),
    ) {
        let (positions, indices) = ball(Vec3::new(0.5, 0.0, -0.25), 16, 32);
        let patches = Patches::new(&positions, &indices, Vec3::new(0.5, 0.0, -0.25));
        let turn = glam::Quat::from_euler(glam::EulerRot::XYZ, spin[0], spin[1], spin[2]);
        let world_from_model = Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            turn,
            Vec3::new(at[0], at[1], at[2] - 0.5),
        );
        let eye = eye(Vec3::ZERO, yaw, pitch);
        let rect = [
            corner.0,
            corner.1,
            size.0.min(EXTENT.0 - corner.0),
            size.1.min(EXTENT.1 - corner.1),
        ];
        let seen = patches.seen(world_from_model, &eye, EXTENT);
        let ranges = patches.ranges(&seen, rect);
        for pair in ranges.windows(2) {
            prop_assert!(pair[0].end < pair[1].start);
        }
        for t in must_draw(&patches, &positions, world_from_model, &eye, rect) {
            let index = 3 * t as u32;
            prop_assert!(
                ranges.iter().any(|r| r.contains(&index)),
                "triangle {} not drawn in {:?}", t, rect
            );
        }
    }
}
