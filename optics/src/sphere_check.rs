//! The sphere check: what each pixel of an eye image samples from the registered background
//! photo through an analytic sphere, under the paper's model (eq. 7-8) or two-surface
//! refraction ([`crate::two_surface`], with the absorption of a tinted glass), computed on the
//! CPU. The GPU's refraction layer is tested against it; `vitreous replay --sphere-check`
//! writes it beside the GPU image.

use crate::absorption::Attenuation;
use crate::camera::EyeParams;
use crate::optics::{fresnel, plane_uv, ray_sphere, refract_heckbert};
use crate::refraction::Refraction;
use crate::two_surface::{Ball, MAX_INTERNAL_REFLECTIONS, pass_through};
use glam::{Mat4, Vec2, Vec3};

/// An analytic glass sphere in front of a registered background plane.
#[derive(Clone, Copy, Debug)]
pub struct SphereScene {
    /// Centre, metres (world).
    pub center_m: Vec3,
    /// Radius, metres.
    pub radius_m: f32,
    /// Relative index of refraction.
    pub ior: f32,
    /// How the view ray is refracted.
    pub refraction: Refraction,
    /// Absorption inside the glass (two-surface refraction only: the paper's model has no path
    /// inside).
    pub attenuation: Attenuation,
    /// Inverse of the background plane's `world_from_plane`.
    pub background_from_world: Mat4,
}

/// What a pixel sees of the sphere's refraction layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RefractionSample {
    /// The pixel's ray misses the sphere.
    Miss,
    /// The ray enters the sphere.
    Hit {
        /// Where the refracted ray meets the background photo, as texture coordinates (u right,
        /// v down); `None` when it misses it (the environment map is seen instead).
        uv: Option<Vec2>,
        /// Fraction of the refracted image that reaches the eye: 1 minus the empirical Fresnel
        /// factor (paper), or the product of the exact Fresnel transmittances at both
        /// interfaces (two-surface).
        transmission: f32,
        /// Fraction of each linear RGB channel left by absorption inside the glass
        /// (Beer-Lambert over the path inside; exactly 1 under the paper's model and for clear
        /// glass).
        absorption: Vec3,
    },
}

/// Traces one pixel of one eye: eye ray -> sphere -> first refraction (eq. 7-8), or both
/// refractions with total internal reflection (two-surface) -> background. A two-surface ray
/// still inside after the reflection limit sees the environment (`uv` is `None`).
pub fn refraction_sample(
    eye: &EyeParams,
    pixel: Vec2,
    size: Vec2,
    scene: &SphereScene,
) -> RefractionSample {
    let dir = eye.pixel_ray(pixel, size);
    let origin = eye.position_m;
    if scene.refraction == Refraction::TwoSurface {
        let ball = Ball {
            center_m: scene.center_m,
            radius_m: scene.radius_m,
        };
        return match pass_through(&ball, origin, dir, scene.ior, MAX_INTERNAL_REFLECTIONS) {
            None => RefractionSample::Miss,
            Some(p) => RefractionSample::Hit {
                uv: p
                    .escaped
                    .then(|| plane_uv(p.exit_m, p.direction, scene.background_from_world))
                    .flatten(),
                transmission: p.transmission,
                absorption: scene.attenuation.transmittance(p.inside_m),
            },
        };
    }
    let Some(t) = ray_sphere(origin, dir, scene.center_m, scene.radius_m) else {
        return RefractionSample::Miss;
    };
    let hit = origin + dir * t;
    let normal = (hit - scene.center_m).normalize();
    RefractionSample::Hit {
        uv: refract_heckbert(dir, normal, scene.ior)
            .and_then(|refracted| plane_uv(hit, refracted, scene.background_from_world)),
        transmission: 1.0 - fresnel(dir, normal),
        absorption: Vec3::ONE,
    }
}

/// Centroid (pixels) of the refracted image of a bright `marker` (a rectangle of photo texture
/// coordinates: min, max) on a black photo, each pixel weighted by the light it shows
/// (its Fresnel transmission: the tests' marker is seen through clear glass), and the number
/// of pixels that see the marker.
pub fn marker_centroid(
    eye: &EyeParams,
    size: (u32, u32),
    scene: &SphereScene,
    marker: (Vec2, Vec2),
) -> Option<(Vec2, usize)> {
    let dims = Vec2::new(size.0 as f32, size.1 as f32);
    let mut sum = glam::DVec2::ZERO;
    let mut weight = 0.0f64;
    let mut count = 0usize;
    for y in 0..size.1 {
        for x in 0..size.0 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            if let RefractionSample::Hit {
                uv: Some(uv),
                transmission,
                ..
            } = refraction_sample(eye, p, dims, scene)
                && uv.cmpge(marker.0).all()
                && uv.cmple(marker.1).all()
            {
                sum += p.as_dvec2() * f64::from(transmission);
                weight += f64::from(transmission);
                count += 1;
            }
        }
    }
    (count > 0).then(|| ((sum / weight).as_vec2(), count))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Fov;
    use glam::Quat;

    #[test]
    fn the_centre_ray_refracts_straight_to_the_plane_centre() {
        let fov = Fov {
            left_rad: -0.6,
            right_rad: 0.6,
            up_rad: 0.45,
            down_rad: -0.45,
        };
        let eye = EyeParams::new(Vec3::ZERO, Quat::IDENTITY, fov);
        let scene = SphereScene {
            center_m: Vec3::new(0.0, 0.0, -0.2),
            radius_m: 0.075,
            ior: 1.51,
            refraction: Refraction::Paper,
            attenuation: Attenuation {
                color: Vec3::splat(0.5),
                distance_m: 0.1,
            },
            background_from_world: Mat4::from_translation(Vec3::new(0.0, 0.0, -0.4)).inverse(),
        };
        let s = refraction_sample(&eye, Vec2::new(50.0, 40.0), Vec2::new(100.0, 80.0), &scene);
        match s {
            RefractionSample::Hit {
                uv: Some(uv),
                transmission,
                absorption,
            } => {
                assert!(uv.abs_diff_eq(Vec2::splat(0.5), 1e-3));
                assert!((transmission - 0.96).abs() < 1e-3);
                // The paper's model has no path inside the glass.
                assert_eq!(absorption, Vec3::ONE);
            }
            other => panic!("{other:?}"),
        }
        // Two-surface: straight through the centre, 2 R = 0.15 m inside.
        let two = SphereScene {
            refraction: Refraction::TwoSurface,
            ..scene
        };
        match refraction_sample(&eye, Vec2::new(50.0, 40.0), Vec2::new(100.0, 80.0), &two) {
            RefractionSample::Hit { absorption, uv, .. } => {
                assert!(uv.is_some());
                assert!(
                    absorption.abs_diff_eq(Vec3::splat(0.5f32.powf(1.5)), 1e-5),
                    "{absorption}"
                );
            }
            other => panic!("{other:?}"),
        }
        let corner = refraction_sample(&eye, Vec2::new(0.5, 0.5), Vec2::new(100.0, 80.0), &scene);
        assert_eq!(corner, RefractionSample::Miss);
    }
}
