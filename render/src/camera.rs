//! Per-eye view and projection for Vulkan's clip space, and the CPU projection tests use.

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
}

/// How the reflected image is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reflection {
    /// The environment map in the mirror direction, weighted by the Fresnel term.
    #[default]
    EnvironmentFresnel,
    /// A Phong highlight of the scene's point light (the paper's choice).
    Phong,
}

/// Gaze-dependent defocus of one frame (eq. 9-14): the kernel width K_g of eq. 13 for each
/// image, in pixels of its own photo or texture (0: sharp).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Defocus {
    /// K_g of the refracted image (the background photo), pixels.
    pub refracted_k_g_px: f32,
    /// K_g of the surface image (the surface texture), pixels.
    pub surface_k_g_px: f32,
}

/// Which layers of the method are drawn, per frame (so one process can alternate them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Look {
    /// Refract each eye's own view ray to the registered background plane (eq. 7-8), giving
    /// the refracted image its own disparity. Off, the baseline refracts into the environment
    /// map, unless `defocus` is on: then the background plane is refracted from the point
    /// between the eyes, the same for both eyes (no refracted-image disparity).
    pub disparity: bool,
    /// Gaze-dependent defocus; `None`: both images sharp.
    pub defocus: Option<Defocus>,
    /// How the reflected image is drawn.
    pub reflection: Reflection,
    /// Add the shadow inducer's floor overlay (eq. 1-5, render/src/inducer.rs).
    pub inducer: bool,
    /// Add the corrected caustics G L_r (eq. 6) to the floor overlay; needs the scene's
    /// caustic gain map ([`crate::SceneDesc::caustics`]), draws nothing without one.
    pub caustics: bool,
    /// Draw nothing of the method: the display adds no light (a study's blank between two
    /// stimuli, or a condition where a real object is shown instead). The real-world photos
    /// are still drawn behind where the composition needs them.
    pub blank: bool,
}

/// Everything the renderer needs to draw one stereo frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// Left and right eye, in that order.
    pub eyes: [EyeParams; 2],
    /// Which layers are drawn and how.
    pub look: Look,
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
}
