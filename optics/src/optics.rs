//! The optics the shaders compute, in plain Rust: the CPU twin of each shader function and
//! the reference the GPU output is tested against; and the interface optics of a smooth
//! dielectric (Snell refraction, mirror reflection, exact Fresnel reflectance) that the CPU
//! tracers (two-surface refraction, the caustics baker) use.

use glam::{Vec2, Vec3};

/// eq. 7-8 (Heckbert's form; METHOD.md section 3 corrects the printed eq. 8): the refracted
/// direction at a surface point, first refraction only.
///
/// `incident` is the unit direction from the eye to the surface point, `normal` the unit
/// normal facing the eye (`incident . normal < 0`) and `n` the relative index of refraction
/// (inside over outside: glass 1.51, diamond 2.42). With V' = I / |I . N| and
/// k_f = 1 / sqrt(n^2 |V'|^2 - |V' + N|^2), eq. 7 gives T = k_f (N + V') - N, parallel to the
/// Snell refraction of I. Returns `None` for total internal reflection (a non-positive
/// radicand), which needs n < 1. T is not normalised, as in the paper. Mirrored by
/// `refract_heckbert` in shaders/glass.wgsl.
pub fn refract_heckbert(incident: Vec3, normal: Vec3, n: f32) -> Option<Vec3> {
    let v = incident / incident.dot(normal).abs();
    let radicand = n * n * v.length_squared() - (v + normal).length_squared();
    if radicand <= 0.0 {
        return None;
    }
    let k_f = 1.0 / radicand.sqrt();
    Some(k_f * (normal + v) - normal)
}

/// Bias of the empirical Fresnel term (The Cg Tutorial ch. 7): the reflectance at normal
/// incidence of n = 1.5 glass.
pub const FRESNEL_BIAS: f32 = 0.04;
/// Scale of the empirical Fresnel term.
pub const FRESNEL_SCALE: f32 = 0.96;
/// Power of the empirical Fresnel term.
pub const FRESNEL_POWER: f32 = 5.0;

/// The empirical Fresnel reflection factor bias + scale (1 + I.N)^power, clamped to 0..1, for
/// a unit incident direction and the unit normal facing it (mirrored in shaders/glass.wgsl).
pub fn fresnel(incident: Vec3, normal: Vec3) -> f32 {
    (FRESNEL_BIAS + FRESNEL_SCALE * (1.0 + incident.dot(normal)).max(0.0).powf(FRESNEL_POWER))
        .clamp(0.0, 1.0)
}

/// Where a ray from `origin` along `direction` meets a plane given by `plane_from_world`
/// (which maps the plane's unit square [-0.5, 0.5]^2 at z = 0 to the origin's frame, inverted),
/// as photo texture coordinates (u right, v down from the photo's top edge). `None` when the
/// ray runs parallel to the plane, points away from it, or hits outside the photo.
pub fn plane_uv(origin: Vec3, direction: Vec3, plane_from_world: glam::Mat4) -> Option<Vec2> {
    plane_hit(origin, direction, plane_from_world)
        .filter(|hit| hit.x.abs() <= 0.5 && hit.y.abs() <= 0.5)
        .map(photo_coordinates)
}

/// [`plane_uv`] also where the ray meets the plane off the photo: photo texture coordinates
/// outside the unit square there. `None` when the ray runs parallel to the plane or points
/// away from it.
pub fn plane_photo_point(
    origin: Vec3,
    direction: Vec3,
    plane_from_world: glam::Mat4,
) -> Option<Vec2> {
    plane_hit(origin, direction, plane_from_world).map(photo_coordinates)
}

/// Where the ray meets the plane, in the plane's frame (the photo on `[-0.5, 0.5]^2` at
/// z = 0), if ahead of it.
fn plane_hit(origin: Vec3, direction: Vec3, plane_from_world: glam::Mat4) -> Option<Vec3> {
    let o = plane_from_world.transform_point3(origin);
    let d = plane_from_world.transform_vector3(direction);
    if d.z.abs() < 1e-12 {
        return None;
    }
    let t = -o.z / d.z;
    (t > 0.0).then(|| o + d * t)
}

/// Photo texture coordinates (u right, v down from the top edge) of a point of the plane's
/// frame.
fn photo_coordinates(hit: Vec3) -> Vec2 {
    Vec2::new(hit.x + 0.5, 0.5 - hit.y)
}

/// Where a ray first meets a sphere: the distance along the unit `direction`, if it does.
pub fn ray_sphere(origin: Vec3, direction: Vec3, center: Vec3, radius: f32) -> Option<f32> {
    let oc = origin - center;
    let b = oc.dot(direction);
    let c = oc.length_squared() - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 0.0).then_some(t)
}

/// Fraction of unpolarised light reflected at a smooth interface (exact Fresnel equations,
/// the mean of the s and p reflectances).
///
/// `cos_incident` is the cosine between the incident ray and the normal on the incident
/// side (0..=1); `eta` is n_incident / n_transmitted. Returns 1 beyond the critical angle
/// (total internal reflection).
pub fn fresnel_reflectance(cos_incident: f32, eta: f32) -> f32 {
    let cos_i = cos_incident.clamp(0.0, 1.0);
    let sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    // Both amplitudes divided through by n_transmitted.
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (rs * rs + rp * rp)).clamp(0.0, 1.0)
}

/// Mirror reflection of the unit direction `dir` about the unit normal `normal`.
pub fn reflect(dir: Vec3, normal: Vec3) -> Vec3 {
    dir - 2.0 * dir.dot(normal) * normal
}

/// Snell refraction of the unit direction `dir` through a surface whose unit normal
/// `facing` points back towards the incident side (`dir . facing < 0`), with
/// `eta` = n_incident / n_transmitted. `None` on total internal reflection.
pub fn refract(dir: Vec3, facing: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -dir.dot(facing);
    let sin_t2 = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin_t2 >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    Some((eta * dir + (eta * cos_i - cos_t) * facing).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The vector form of Snell's law for a unit incident direction and a normal facing the
    /// incident side, with eta = n_outside / n_inside.
    fn snell(i: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
        let cos_i = -i.dot(n);
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
        if sin2_t > 1.0 {
            return None;
        }
        Some(eta * i + (eta * cos_i - (1.0 - sin2_t).sqrt()) * n)
    }

    fn unit(v: [f32; 3]) -> Option<Vec3> {
        let v = Vec3::from(v);
        (v.length() > 1e-3).then(|| v.normalize())
    }

    proptest! {
        #[test]
        fn refraction_matches_snell_for_random_rays(
            n in prop::array::uniform3(-1.0f32..1.0),
            i in prop::array::uniform3(-1.0f32..1.0),
            ior in 1.0f32..2.5,
        ) {
            let (Some(normal), Some(incident)) = (unit(n), unit(i)) else { return Ok(()) };
            let cos = incident.dot(normal);
            prop_assume!(cos < -0.02);
            let t = refract_heckbert(incident, normal, ior).expect("no TIR entering a denser medium");
            let s = snell(incident, normal, 1.0 / ior).unwrap();
            let t_unit = t.normalize();
            prop_assert!(t_unit.cross(s).length() < 1e-4, "T {t_unit} vs Snell {s}");
            prop_assert!(t_unit.dot(s) > 0.0);
        }

        #[test]
        fn non_positive_radicand_is_exactly_total_internal_reflection(
            n in prop::array::uniform3(-1.0f32..1.0),
            i in prop::array::uniform3(-1.0f32..1.0),
            ior in 0.3f32..1.0,
        ) {
            let (Some(normal), Some(incident)) = (unit(n), unit(i)) else { return Ok(()) };
            let cos_i = -incident.dot(normal);
            prop_assume!(cos_i > 0.02);
            // Leaving a denser medium: relative index below one.
            let sin2_t = (1.0 - cos_i * cos_i) / (ior * ior);
            prop_assume!((sin2_t - 1.0).abs() > 1e-3);
            let heckbert = refract_heckbert(incident, normal, ior);
            prop_assert_eq!(heckbert.is_none(), sin2_t > 1.0);
            if let Some(t) = heckbert {
                let s = snell(incident, normal, 1.0 / ior).unwrap();
                prop_assert!(t.normalize().cross(s).length() < 1e-3);
            }
        }
    }

    #[test]
    fn normal_incidence_goes_straight_through() {
        let t = refract_heckbert(Vec3::NEG_Z, Vec3::Z, 1.51).unwrap();
        assert!(t.normalize().abs_diff_eq(Vec3::NEG_Z, 1e-6));
    }

    #[test]
    fn plane_uv_maps_corners_and_misses() {
        let world_from_plane = glam::Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 1.0, 1.0),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, 0.0, -1.0),
        );
        let p = world_from_plane.inverse();
        let uv = plane_uv(Vec3::ZERO, Vec3::new(-1.0, 0.5, -1.0), p).unwrap();
        assert!(uv.abs_diff_eq(Vec2::new(0.0, 0.0), 1e-6), "{uv}");
        assert!(plane_uv(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), p).is_none());
        assert!(plane_uv(Vec3::ZERO, Vec3::new(3.0, 0.0, -1.0), p).is_none());
    }

    mod interface {
        use super::super::*;
        use proptest::prelude::*;

        #[test]
        fn normal_incidence_reflectance_is_the_textbook_value() {
            for n in [1.5f32, 1.51, 2.42] {
                let expected = ((n - 1.0) / (n + 1.0)).powi(2);
                assert!((fresnel_reflectance(1.0, 1.0 / n) - expected).abs() < 1e-6);
                // Same from the inside (reciprocity at normal incidence).
                assert!((fresnel_reflectance(1.0, n) - expected).abs() < 1e-6);
            }
        }

        #[test]
        fn p_polarisation_vanishes_at_brewster_angle() {
            let n = 1.5f32;
            let theta_b = n.atan();
            let cos_i = theta_b.cos();
            let eta = 1.0 / n;
            let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
            let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
            assert!(rp.abs() < 1e-5);
            // Only the s part is left, halved.
            let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
            assert!((fresnel_reflectance(cos_i, eta) - 0.5 * rs * rs).abs() < 1e-6);
        }

        #[test]
        fn total_internal_reflection_beyond_the_critical_angle() {
            let n = 2.42f32;
            let critical = (1.0 / n).asin();
            let just_beyond = (critical + 1e-3).cos();
            assert_eq!(fresnel_reflectance(just_beyond, n), 1.0);
            let d = Vec3::new((critical + 1e-3).sin(), -(critical + 1e-3).cos(), 0.0);
            assert!(refract(d, Vec3::Y, n).is_none());
            assert!(fresnel_reflectance((critical - 1e-3).cos(), n) < 1.0);
            // Grazing incidence from outside reflects everything.
            assert!((fresnel_reflectance(0.0, 1.0 / n) - 1.0).abs() < 1e-6);
        }

        proptest! {
            #[test]
            fn snell_refraction_matches_sines_for_random_rays(
                theta in 0.0f32..1.5, phi in 0.0f32..std::f32::consts::TAU, n in 1.0f32..3.0, from_inside: bool,
            ) {
                let eta = if from_inside { n } else { 1.0 / n };
                let d = Vec3::new(theta.sin() * phi.cos(), -theta.cos(), theta.sin() * phi.sin());
                match refract(d, Vec3::Y, eta) {
                    Some(t) => {
                        let sin_i = d.cross(Vec3::Y).length();
                        let sin_t = t.cross(Vec3::Y).length();
                        prop_assert!((sin_i * eta - sin_t).abs() < 1e-4);
                        // Transmitted ray continues through the surface, in the plane of incidence.
                        prop_assert!(t.y < 0.0);
                        prop_assert!(t.dot(d.cross(Vec3::Y)).abs() < 1e-4);
                        prop_assert!(fresnel_reflectance(theta.cos(), eta) < 1.0);
                    }
                    None => prop_assert!(eta * theta.sin() >= 1.0 - 1e-4),
                }
                let r = reflect(d, Vec3::Y);
                prop_assert!((r.y + d.y).abs() < 1e-6 && (r.x - d.x).abs() < 1e-6);
                let f = fresnel_reflectance(theta.cos(), eta);
                prop_assert!((0.0..=1.0).contains(&f));
            }
        }
    }
}
