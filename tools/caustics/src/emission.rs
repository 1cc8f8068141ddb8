//! Emission directions: the cone from the point light that just contains the object's
//! bounding sphere, parameterised by the unit square with an equal-solid-angle map, so a
//! regular grid on the square cuts the cone into cells of exactly equal solid angle.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

/// The cone of directions from the light that can reach the object.
#[derive(Clone, Copy, Debug)]
pub struct EmissionCone {
    /// Unit axis, light towards the bounding-sphere centre.
    axis: DVec3,
    /// Unit vectors completing a right-handed frame with `axis`.
    basis_u: DVec3,
    /// Second basis vector.
    basis_v: DVec3,
    /// 1 - cos(half angle), computed without cancellation.
    one_minus_cos: f64,
    /// Rotation of the grid about the axis (the seed's effect), radians.
    rotation_rad: f64,
}

impl EmissionCone {
    /// The cone from `light_m` around the sphere (`center_m`, `radius_m`), rotated about its
    /// axis by `rotation_rad`. A light inside the sphere gets the whole sphere of directions.
    pub fn new(light_m: Vec3, center_m: Vec3, radius_m: f32, rotation_rad: f64) -> Self {
        let to_center = (center_m - light_m).as_dvec3();
        let dist = to_center.length();
        let r = radius_m as f64;
        let axis = if dist > 0.0 {
            to_center / dist
        } else {
            DVec3::NEG_Y
        };
        let one_minus_cos = if dist <= r {
            2.0
        } else {
            // 1 - cos a = 2 sin^2(a / 2), with sin a = r / d.
            let half = 0.5 * (r / dist).asin();
            2.0 * half.sin().powi(2)
        };
        let helper = if axis.x.abs() < 0.6 {
            DVec3::X
        } else {
            DVec3::Y
        };
        let basis_u = helper.cross(axis).normalize();
        let basis_v = axis.cross(basis_u);
        EmissionCone {
            axis,
            basis_u,
            basis_v,
            one_minus_cos,
            rotation_rad,
        }
    }

    /// Solid angle of the cone, steradians.
    pub fn solid_angle_sr(&self) -> f64 {
        2.0 * PI * self.one_minus_cos
    }

    /// Unit direction for a point of the unit square (Shirley–Chiu concentric map to the
    /// disk, then Lambert's equal-area map of the disk onto the cone's cap).
    pub fn direction(&self, s: f64, t: f64) -> Vec3 {
        self.direction_f64(s, t).as_vec3()
    }

    /// [`EmissionCone::direction`] in double precision.
    pub fn direction_f64(&self, s: f64, t: f64) -> DVec3 {
        let (a, b) = (2.0 * s - 1.0, 2.0 * t - 1.0);
        let (r, phi) = if a == 0.0 && b == 0.0 {
            (0.0, 0.0)
        } else if a.abs() > b.abs() {
            (a, PI / 4.0 * (b / a))
        } else {
            (b, PI / 2.0 - PI / 4.0 * (a / b))
        };
        // cos theta = 1 - r^2 (1 - cos a); sin theta from the same quantity without loss.
        let k = r * r * self.one_minus_cos;
        let cos_theta = 1.0 - k;
        // The concentric map's radius is signed (r < 0 stands for the opposite azimuth).
        let sin_theta = (k * (2.0 - k)).max(0.0).sqrt().copysign(r);
        let phi = phi + self.rotation_rad;
        let d = sin_theta * (phi.cos() * self.basis_u + phi.sin() * self.basis_v)
            + cos_theta * self.axis;
        d.normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_edges_map_to_the_tangent_cone() {
        let light = Vec3::new(0.0, 1.0, 0.0);
        let cone = EmissionCone::new(light, Vec3::ZERO, 0.1, 0.3);
        let half = (0.1f32 as f64).asin();
        let expected = 2.0 * PI * (1.0 - half.cos());
        assert!((cone.solid_angle_sr() - expected).abs() < 1e-6 * expected);
        for (s, t) in [(0.0, 0.3), (1.0, 0.7), (0.2, 0.0), (0.5, 1.0), (0.0, 0.0)] {
            let d = cone.direction(s, t).as_dvec3();
            assert!((d.dot(DVec3::NEG_Y).acos() - half).abs() < 1e-6);
        }
        assert!(cone.direction(0.5, 0.5).abs_diff_eq(Vec3::NEG_Y, 1e-7));
        // Opposite corners of the square go to opposite sides of the axis.
        let (p, q) = (cone.direction(0.1, 0.2), cone.direction(0.9, 0.8));
        assert!(
            (p + q).normalize().abs_diff_eq(Vec3::NEG_Y, 1e-6),
            "{p} {q}"
        );
    }

    #[test]
    fn grid_cells_have_equal_solid_angle() {
        // Count directions of a fine grid falling in each coarse cell's image by solid angle:
        // equivalently, the map's Jacobian is constant, checked by finite differences.
        let cone = EmissionCone::new(Vec3::new(0.3, 2.0, -0.1), Vec3::ZERO, 0.5, 0.0);
        let expect = cone.solid_angle_sr();
        let h = 1e-4;
        for (s, t) in [(0.2, 0.3), (0.7, 0.9), (0.51, 0.52), (0.9, 0.1)] {
            let d = cone.direction_f64(s, t);
            let ds = (cone.direction_f64(s + h, t) - d) / h;
            let dt = (cone.direction_f64(s, t + h) - d) / h;
            let jac = ds.cross(dt).length();
            assert!((jac - expect).abs() / expect < 2e-3, "{jac} vs {expect}");
        }
    }
}
