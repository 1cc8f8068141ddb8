//! Interface optics of a smooth dielectric: Snell refraction, mirror reflection and the exact
//! Fresnel reflectance for unpolarised light.

use glam::Vec3;

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
        fn refraction_matches_snell_for_random_rays(
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
