//! Where things fall on the floor plane: the shadow's planar projection (eq. 1), the floor's
//! frame, and the plane-local rectangles the overlay has to cover.

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::pose::ScenePose;
use crate::scene::InducerDesc;

/// eq. 1 (the shadow region): the homogeneous planar projection from a point light at
/// `light_m` onto the plane through `plane_point_m` with unit normal `normal` (pointing to the
/// light's side). A point X maps to `M * (X, 1)`, whose perspective division is where the ray
/// from the light through X meets the plane; points at or beyond the light's height get
/// w <= 0. `None` when the light is not above the plane.
pub fn planar_shadow(plane_point_m: Vec3, normal: Vec3, light_m: Vec3) -> Option<Mat4> {
    let plane = normal.extend(-normal.dot(plane_point_m));
    let light = light_m.extend(1.0);
    let height = plane.dot(light);
    // Also refuses NaN.
    if height.is_nan() || height <= 1e-6 {
        return None;
    }
    // M = (plane . L) I - L plane^T: M X = h X - L (plane . X).
    let column = |j: usize| Mat4::IDENTITY.col(j) * height - light * plane[j];
    Some(Mat4::from_cols(column(0), column(1), column(2), column(3)))
}

/// The floor's geometry as the inducer uses it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Floor {
    /// Unit square [-0.5, 0.5]^2 at z = 0 to the world.
    pub world_from_plane: Mat4,
    /// Its inverse.
    pub plane_from_world: Mat4,
    /// The plane's centre, metres.
    pub center_m: Vec3,
    /// Unit normal of the photographed side.
    pub normal: Vec3,
    /// Width and height of the photographed area, metres.
    pub size_m: Vec2,
}

impl Floor {
    /// The floor whose photo covers the unit square mapped by `world_from_plane`.
    pub fn new(world_from_plane: Mat4) -> Floor {
        let x = world_from_plane.x_axis.truncate();
        let y = world_from_plane.y_axis.truncate();
        Floor {
            world_from_plane,
            plane_from_world: world_from_plane.inverse(),
            center_m: world_from_plane.w_axis.truncate(),
            normal: x.cross(y).normalize(),
            size_m: Vec2::new(x.length(), y.length()),
        }
    }
}

/// Model space to the mask's clip space: the model transform, the planar shadow projection
/// and the floor's unit square to clip space (texel row 0 at the photo's top, +y local).
pub(crate) fn mask_clip_from_model(floor: &Floor, shadow: Mat4, world_from_model: Mat4) -> Mat4 {
    // Plane-local (x, y) in [-0.5, 0.5] to clip (2x, -2y); depth 0; w kept, so that the
    // rasteriser clips what lies beyond the light's height.
    let clip_from_plane = Mat4::from_cols(
        Vec4::new(2.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, -2.0, 0.0, 0.0),
        Vec4::ZERO,
        Vec4::new(0.0, 0.0, 0.0, 1.0),
    );
    clip_from_plane * floor.plane_from_world * shadow * world_from_model
}

/// The part of the floor's unit square (plane-local min x, min y, max x, max y) that can
/// receive inducer light: the bounding rectangle of the mesh's shadow (the projected
/// vertices: the shadow of a triangle mesh lies in their convex hull) grown by the ramp width
/// `margin` (plane-local units) and clamped to the square. The whole square when part of the
/// mesh is at or above the light's height (the shadow is then unbounded); `None` when the
/// rectangle misses the square.
pub fn overlay_rect(
    world_positions: impl IntoIterator<Item = Vec3>,
    shadow: Mat4,
    plane_from_world: Mat4,
    margin: Vec2,
) -> Option<[f32; 4]> {
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for p in world_positions {
        let s = plane_from_world * (shadow * p.extend(1.0));
        if s.w.is_nan() || s.w <= 1e-6 {
            return Some([-0.5, -0.5, 0.5, 0.5]);
        }
        let local = s.truncate().truncate() / s.w;
        lo = lo.min(local);
        hi = hi.max(local);
    }
    let lo = (lo - margin).max(Vec2::splat(-0.5));
    let hi = (hi + margin).min(Vec2::splat(0.5));
    (lo.x < hi.x && lo.y < hi.y).then_some([lo.x, lo.y, hi.x, hi.y])
}

/// The plane-local rectangle (min x, min y, max x, max y) holding every non-zero texel of a
/// `width` x `height` caustic gain map (row 0 at plane-local +y), grown by one texel for the
/// bilinear footprint and clamped to the unit square; `None` when every gain is 0.
pub fn caustic_rect(width: u32, height: u32, gain: &[f32]) -> Option<[f32; 4]> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (i, &g) in gain.iter().enumerate() {
        if g > 0.0 {
            let (x, y) = (i as u32 % width, i as u32 / width);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 == u32::MAX {
        return None;
    }
    Some(texels_plane_rect([x0, y0, x1 + 1, y1 + 1], width, height))
}

/// The plane-local rectangle (min x, min y, max x, max y) of the texels `[x0, y0, x1, y1]`
/// (ends excluded) of a `width` x `height` floor-space image (row 0 at plane-local +y), grown
/// by one texel for the bilinear footprint and clamped to the unit square.
pub(crate) fn texels_plane_rect([x0, y0, x1, y1]: [u32; 4], width: u32, height: u32) -> [f32; 4] {
    let u_lo = (x0 as f32 - 1.0) / width as f32;
    let u_hi = (x1 as f32 + 1.0) / width as f32;
    let v_lo = (y0 as f32 - 1.0) / height as f32;
    let v_hi = (y1 as f32 + 1.0) / height as f32;
    [
        (u_lo - 0.5).max(-0.5),
        (0.5 - v_hi).max(-0.5),
        (u_hi - 0.5).min(0.5),
        (0.5 - v_lo).min(0.5),
    ]
}

/// The texels `[x0, y0, x1, y1]` (ends excluded) of a `width` x `height` floor-space image
/// (row 0 at plane-local +y) that a plane-local rectangle touches, clamped to the image.
pub(crate) fn texel_rect(rect: [f32; 4], width: u32, height: u32) -> [u32; 4] {
    let (w, h) = (width as f32, height as f32);
    let clamp = |v: f32, n: u32| (v.max(0.0) as u32).min(n);
    [
        clamp(((rect[0] + 0.5) * w).floor(), width),
        clamp(((0.5 - rect[3]) * h).floor(), height),
        clamp(((rect[2] + 0.5) * w).ceil(), width),
        clamp(((0.5 - rect[1]) * h).ceil(), height),
    ]
}

/// The smallest rectangle `[x0, y0, x1, y1]` holding both (either may be absent): plane
/// rectangles (f32) or texel rectangles (u32).
pub(crate) fn union_rect<T: Copy + PartialOrd>(
    a: Option<[T; 4]>,
    b: Option<[T; 4]>,
) -> Option<[T; 4]> {
    let low = |x: T, y: T| if y < x { y } else { x };
    let high = |x: T, y: T| if y > x { y } else { x };
    match (a, b) {
        (Some(a), Some(b)) => Some([
            low(a[0], b[0]),
            low(a[1], b[1]),
            high(a[2], b[2]),
            high(a[3], b[3]),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// The mask's projection (eq. 1: `None` when the light is not above the floor) and the
/// plane-local rectangle the inducer's light covers (`None` when nothing can be lit) for the
/// object and light of `pose`.
pub(crate) fn shadow_of(
    floor: &Floor,
    params: &InducerDesc,
    positions: &[Vec3],
    pose: &ScenePose,
) -> (Option<Mat4>, Option<[f32; 4]>) {
    let shadow = planar_shadow(floor.center_m, floor.normal, pose.light_position_m);
    let rect = shadow.and_then(|shadow| {
        // Ramp width plus two texels (rasterisation and the overlay's bilinear footprint).
        let margin =
            Vec2::splat(params.ramp_width_m) / floor.size_m + 2.0 / params.resolution_px as f32;
        let world = positions
            .iter()
            .map(|p| pose.world_from_model.transform_point3(*p));
        overlay_rect(world, shadow, floor.plane_from_world, margin)
    });
    let clip = shadow.map(|s| mask_clip_from_model(floor, s, pose.world_from_model));
    (clip, rect)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_rect_holds_both_rectangles_of_either_kind() {
        assert_eq!(
            union_rect(Some([0.1f32, -0.2, 0.3, 0.0]), Some([-0.1, -0.1, 0.2, 0.4])),
            Some([-0.1, -0.2, 0.3, 0.4])
        );
        assert_eq!(
            union_rect(Some([4u32, 5, 9, 6]), Some([6, 2, 8, 7])),
            Some([4, 2, 9, 7])
        );
        assert_eq!(union_rect(None, Some([1u32, 2, 3, 4])), Some([1, 2, 3, 4]));
        assert_eq!(union_rect(Some([1u32, 2, 3, 4]), None), Some([1, 2, 3, 4]));
        assert_eq!(union_rect::<u32>(None, None), None);
    }

    #[test]
    fn planar_shadow_sends_points_along_the_light_ray_to_the_plane() {
        let light = Vec3::new(0.1, 1.0, -0.5);
        let m = planar_shadow(Vec3::new(0.0, -0.3, 0.0), Vec3::Y, light).unwrap();
        for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.2, -0.1, 0.3)] {
            let s = m * p.extend(1.0);
            assert!(s.w > 0.0);
            let q = s.truncate() / s.w;
            assert!((q.y + 0.3).abs() < 1e-5, "{q}");
            // q lies on the line from the light through p.
            let along = (q - light).normalize().dot((p - light).normalize());
            assert!((along - 1.0).abs() < 1e-5);
        }
        // A point above the light has no shadow on the floor.
        assert!((m * Vec3::new(0.0, 2.0, 0.0).extend(1.0)).w < 0.0);
        assert!(planar_shadow(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, -1.0, 0.0)).is_none());
    }

    #[test]
    fn texel_rect_covers_the_rectangle_with_row_zero_at_the_top() {
        assert_eq!(
            texel_rect([-0.5, -0.5, 0.5, 0.5], 512, 256),
            [0, 0, 512, 256]
        );
        // The upper-left quarter, grown to whole texels.
        assert_eq!(
            texel_rect([-0.5, 0.001, -0.001, 0.5], 100, 100),
            [0, 0, 50, 50]
        );
        assert_eq!(texel_rect([0.1, -0.3, 0.2, -0.1], 10, 10), [6, 6, 7, 8]);
    }

    #[test]
    fn overlay_rect_bounds_the_shadow_plus_margin() {
        let floor = Floor::new(Mat4::from_scale_rotation_translation(
            Vec3::new(1.0, 1.0, 1.0),
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, -0.3, -1.5),
        ));
        assert!(floor.normal.abs_diff_eq(Vec3::Y, 1e-6));
        let light = Vec3::new(0.0, 0.74, -2.5);
        let shadow = planar_shadow(floor.center_m, floor.normal, light).unwrap();
        let center = Vec3::new(0.0, -0.26, -1.5);
        let points = (0..64).map(|i| {
            let a = i as f32 * 0.3;
            center + Vec3::new(a.cos() * 0.04, (a * 1.7).sin() * 0.04, a.sin() * 0.04)
        });
        let rect = overlay_rect(points, shadow, floor.plane_from_world, Vec2::splat(0.14)).unwrap();
        // The shadow falls towards the viewer (+z), which is the photo's -y.
        assert!(
            rect[1] < -0.14 && rect[3] > 0.14 && rect[3] < 0.3,
            "{rect:?}"
        );
        // Something above the light: the whole floor.
        let high = [center, Vec3::new(0.0, 1.0, -2.5)];
        let all = overlay_rect(high, shadow, floor.plane_from_world, Vec2::ZERO).unwrap();
        assert_eq!(all, [-0.5, -0.5, 0.5, 0.5]);
    }
}
