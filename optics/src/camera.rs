//! An eye's camera: its view and its projection into Vulkan's clip space from the four angles
//! of an OpenXR field of view, and where a world point lands on its image (the CPU projection
//! the tracers and the tests use).

use glam::{Mat4, Quat, Vec2, Vec3, Vec4Swizzles};

/// Near clipping distance, metres.
pub const NEAR_M: f32 = 0.02;
/// Far clipping distance, metres.
pub const FAR_M: f32 = 100.0;

/// An asymmetric field of view: four signed angles in radians, as OpenXR reports them
/// (left and down negative for a centred view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fov {
    /// Angle of the left edge, radians.
    pub left_rad: f32,
    /// Angle of the right edge, radians.
    pub right_rad: f32,
    /// Angle of the top edge, radians.
    pub up_rad: f32,
    /// Angle of the bottom edge, radians.
    pub down_rad: f32,
}

/// Vulkan clip-space projection (y down, depth 0 at `near` to 1 at `far`) for a right-handed
/// view space looking down -z.
pub fn projection(fov: Fov, near: f32, far: f32) -> Mat4 {
    let (l, r) = (fov.left_rad.tan(), fov.right_rad.tan());
    let (d, u) = (fov.down_rad.tan(), fov.up_rad.tan());
    let a = far / (near - far);
    Mat4::from_cols(
        [2.0 / (r - l), 0.0, 0.0, 0.0].into(),
        [0.0, -2.0 / (u - d), 0.0, 0.0].into(),
        [(r + l) / (r - l), -(u + d) / (u - d), a, -1.0].into(),
        [0.0, 0.0, a * near, 0.0].into(),
    )
}

/// One eye's camera for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeParams {
    /// World to view transform (inverse of the eye's pose).
    pub view_from_world: Mat4,
    /// View to Vulkan clip space.
    pub clip_from_view: Mat4,
    /// The eye's position in the world, metres: where refraction is seen from.
    pub position_m: Vec3,
}

impl EyeParams {
    /// The camera of an eye at `position_m` with `orientation`, seeing `fov`.
    pub fn new(position_m: Vec3, orientation: Quat, fov: Fov) -> EyeParams {
        let world_from_view = Mat4::from_rotation_translation(orientation, position_m);
        EyeParams {
            view_from_world: world_from_view.inverse(),
            clip_from_view: projection(fov, NEAR_M, FAR_M),
            position_m,
        }
    }

    /// World to clip space.
    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_view * self.view_from_world
    }

    /// Where a world point lands on an image of `size` pixels (x right, y down, pixel centres
    /// at half-integers), or `None` behind the eye.
    pub fn project_to_pixel(&self, world: Vec3, size: Vec2) -> Option<Vec2> {
        let clip = self.clip_from_world() * world.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.xy() / clip.w;
        Some((ndc + Vec2::ONE) * 0.5 * size)
    }

    /// Unit direction of the view ray through a pixel position (x right, y down, pixel centres
    /// at half-integers) of an image of `size` pixels.
    pub fn pixel_ray(&self, pixel: Vec2, size: Vec2) -> Vec3 {
        self.pixel_rays(size).direction(pixel)
    }

    /// The view rays of an image of `size` pixels, for many pixels at the cost of one matrix
    /// inverse.
    pub fn pixel_rays(&self, size: Vec2) -> PixelRays {
        PixelRays {
            world_from_clip: self.clip_from_world().inverse(),
            size,
        }
    }
}

/// The view rays of one eye image ([`EyeParams::pixel_rays`]).
#[derive(Clone, Copy, Debug)]
pub struct PixelRays {
    world_from_clip: Mat4,
    size: Vec2,
}

impl PixelRays {
    /// Unit direction of the view ray through a pixel position (x right, y down, pixel centres
    /// at half-integers).
    pub fn direction(&self, pixel: Vec2) -> Vec3 {
        let ndc = pixel / self.size * 2.0 - Vec2::ONE;
        let near = self.world_from_clip.project_point3(ndc.extend(0.0));
        let far = self.world_from_clip.project_point3(ndc.extend(1.0));
        (far - near).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fov() -> Fov {
        Fov {
            left_rad: -0.4,
            right_rad: 0.3,
            up_rad: 0.25,
            down_rad: -0.35,
        }
    }

    #[test]
    fn frustum_edges_map_to_image_edges() {
        let eye = EyeParams::new(Vec3::ZERO, Quat::IDENTITY, fov());
        let size = Vec2::new(100.0, 80.0);
        let f = fov();
        let at = |x: f32, y: f32| eye.project_to_pixel(Vec3::new(x, y, -1.0), size).unwrap();
        assert!((at(f.left_rad.tan(), 0.0).x - 0.0).abs() < 1e-3);
        assert!((at(f.right_rad.tan(), 0.0).x - 100.0).abs() < 1e-3);
        // Up is the top of the image (y = 0) in Vulkan.
        assert!((at(0.0, f.up_rad.tan()).y - 0.0).abs() < 1e-3);
        assert!((at(0.0, f.down_rad.tan()).y - 80.0).abs() < 1e-3);
    }

    #[test]
    fn depth_runs_from_zero_at_near_to_one_at_far() {
        let p = projection(fov(), NEAR_M, FAR_M);
        let depth = |z: f32| {
            let c = p * glam::Vec4::new(0.0, 0.0, z, 1.0);
            c.z / c.w
        };
        assert!(depth(-NEAR_M).abs() < 1e-5);
        assert!((depth(-FAR_M) - 1.0).abs() < 1e-4);
    }

    #[test]
    fn eye_translation_moves_points_the_other_way() {
        let f = Fov {
            left_rad: -0.5,
            right_rad: 0.5,
            up_rad: 0.5,
            down_rad: -0.5,
        };
        let size = Vec2::splat(100.0);
        let left = EyeParams::new(Vec3::new(-0.03, 0.0, 0.0), Quat::IDENTITY, f);
        let right = EyeParams::new(Vec3::new(0.03, 0.0, 0.0), Quat::IDENTITY, f);
        let p = Vec3::new(0.0, 0.0, -0.5);
        let xl = left.project_to_pixel(p, size).unwrap().x;
        let xr = right.project_to_pixel(p, size).unwrap().x;
        // Crossed disparity for a near point: the left eye sees it to the right.
        assert!(xl > 50.0 && xr < 50.0);
        let expected = 0.03 / 0.5 / 0.5_f32.tan() * 50.0;
        assert!((xl - 50.0 - expected).abs() < 1e-3);
    }

    #[test]
    fn pixel_ray_through_the_centre_looks_forward() {
        let fov = Fov {
            left_rad: -0.5,
            right_rad: 0.5,
            up_rad: 0.4,
            down_rad: -0.4,
        };
        let eye = EyeParams::new(Vec3::ZERO, Quat::IDENTITY, fov);
        let d = eye.pixel_ray(Vec2::new(50.0, 40.0), Vec2::new(100.0, 80.0));
        assert!(d.abs_diff_eq(Vec3::NEG_Z, 1e-5), "{d}");
        // A pixel ray projects back onto its pixel.
        let p = Vec2::new(13.5, 71.5);
        let back = eye
            .project_to_pixel(
                eye.pixel_ray(p, Vec2::new(100.0, 80.0)),
                Vec2::new(100.0, 80.0),
            )
            .unwrap();
        assert!(back.abs_diff_eq(p, 1e-3), "{back}");
    }
}
