//! Torus of unit outer diameter lying flat (axis +y): the object with a hole (paper Sec. 7).

use crate::mesh::Mesh;
use anyhow::{Result, ensure};
use glam::DVec3;
use std::f64::consts::TAU;

/// Outer radius, major plus minor: the torus spans 1.0 across.
pub const OUTER_RADIUS: f64 = 0.5;

/// Tube radius used when none is given.
pub const DEFAULT_MINOR_RADIUS: f64 = 0.15;

/// Torus about +y with `major + minor = 0.5` and smooth normals. Texture `u` runs once around
/// the +y axis (like the sphere), `v` once around the tube, starting at the outer equator and
/// going down first so that the outside is not mirrored.
pub fn mesh(minor_radius: f64, major_segments: u32, minor_segments: u32) -> Result<Mesh> {
    ensure!(
        minor_radius > 0.0 && minor_radius < OUTER_RADIUS / 2.0,
        "torus minor radius must lie in (0, {}) so the hole stays open, got {minor_radius}",
        OUTER_RADIUS / 2.0
    );
    ensure!(
        major_segments >= 3,
        "torus needs at least 3 major segments, got {major_segments}"
    );
    ensure!(
        minor_segments >= 3,
        "torus needs at least 3 minor segments, got {minor_segments}"
    );
    let major_radius = OUTER_RADIUS - minor_radius;
    Ok(Mesh::from_grid(
        major_segments,
        minor_segments,
        false,
        |u, v| {
            let (sin_around, cos_around) = (u * TAU).sin_cos();
            let ring = DVec3::new(-cos_around, 0.0, sin_around);
            let (sin_tube, cos_tube) = (v * TAU).sin_cos();
            let normal = ring * cos_tube - DVec3::Y * sin_tube;
            (ring * major_radius + normal * minor_radius, normal)
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::checks::assert_closed;
    use glam::Vec3;
    use std::f64::consts::PI;

    #[test]
    fn torus_has_unit_outer_diameter_and_lies_flat() {
        let mesh = mesh(DEFAULT_MINOR_RADIUS, 96, 48).unwrap();
        let (min, max) = mesh.bounds();
        assert!((max.x - min.x - 1.0).abs() < 1e-5);
        assert!((max.z - min.z - 1.0).abs() < 1e-5);
        assert!((max.y - min.y - 0.3).abs() < 1e-5);
        assert!((min + max).abs().max_element() < 1e-6);
    }

    #[test]
    fn torus_normals_point_away_from_the_tube_centre() {
        let minor = DEFAULT_MINOR_RADIUS as f32;
        let mesh = mesh(DEFAULT_MINOR_RADIUS, 96, 48).unwrap();
        for (&p, &n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((n.length() - 1.0).abs() < 1e-6);
            let centre = Vec3::new(p.x, 0.0, p.z).normalize() * (0.5 - minor);
            assert!(n.dot(p - centre) > 0.0);
            assert!((p - centre - n * minor).length() < 1e-6);
        }
    }

    #[test]
    fn torus_is_closed_and_wound_outwards() {
        let mesh = mesh(DEFAULT_MINOR_RADIUS, 96, 48).unwrap();
        assert_eq!(mesh.vertex_count(), 97 * 49);
        assert_eq!(mesh.triangle_count(), 2 * 96 * 48);
        let (major, minor) = (0.5 - DEFAULT_MINOR_RADIUS, DEFAULT_MINOR_RADIUS);
        let exact = 2.0 * PI * PI * major * minor * minor;
        let volume = mesh.signed_volume();
        assert!(
            (volume - exact).abs() / exact < 0.01,
            "volume {volume} vs {exact}"
        );
        assert_closed(&mesh, 1e-5);
    }

    #[test]
    fn torus_rejects_a_closed_hole() {
        assert!(mesh(0.25, 96, 48).is_err());
        assert!(mesh(0.0, 96, 48).is_err());
    }
}
