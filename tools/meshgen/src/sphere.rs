//! UV sphere of unit diameter: the paper's glass ball.

use crate::mesh::Mesh;
use anyhow::{Result, ensure};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Radius of the unit-diameter sphere.
pub const RADIUS: f64 = 0.5;

/// Unit vector at longitude `azimuth_rad` (counter-clockwise about +y seen from above, starting
/// at -x) and colatitude `polar_rad` (0 at +y).
fn direction(azimuth_rad: f64, polar_rad: f64) -> DVec3 {
    let (sin_polar, cos_polar) = polar_rad.sin_cos();
    DVec3::new(
        -azimuth_rad.cos() * sin_polar,
        cos_polar,
        azimuth_rad.sin() * sin_polar,
    )
}

/// Sphere of radius 0.5 centred at the origin with smooth normals and equirectangular texture
/// coordinates: `u` runs once around the +y axis, `v` from the top pole (0) to the bottom (1).
pub fn mesh(segments: u32, rings: u32) -> Result<Mesh> {
    ensure!(
        segments >= 3,
        "sphere needs at least 3 segments, got {segments}"
    );
    ensure!(rings >= 2, "sphere needs at least 2 rings, got {rings}");
    Ok(Mesh::from_grid(segments, rings, true, |u, v| {
        let normal = direction(u * TAU, v * PI);
        (normal * RADIUS, normal)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::checks::assert_closed;

    #[test]
    fn default_sphere_has_unit_diameter_on_every_axis() {
        let mesh = mesh(96, 48).unwrap();
        let (min, max) = mesh.bounds();
        for extent in (max - min).to_array() {
            assert!((extent - 1.0).abs() < 1e-5, "extent {extent}");
        }
        assert!(
            (min + max).abs().max_element() < 1e-6,
            "not centred: {min} {max}"
        );
    }

    #[test]
    fn sphere_winding_is_counter_clockwise_from_outside() {
        let mesh = mesh(96, 48).unwrap();
        let volume = mesh.signed_volume();
        let exact = 4.0 / 3.0 * PI * RADIUS.powi(3);
        assert!(volume > 0.0, "signed volume {volume}");
        assert!(
            (volume - exact).abs() / exact < 0.01,
            "volume {volume} vs {exact}"
        );
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            let face = (b - a).cross(c - a);
            assert!(face.dot(a + b + c) > 0.0, "triangle {t:?} faces inwards");
        }
    }

    #[test]
    fn sphere_normals_are_unit_radial_and_outward() {
        let mesh = mesh(96, 48).unwrap();
        for (&p, &n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((n.length() - 1.0).abs() < 1e-6);
            assert!(n.dot(p) > 0.0);
            assert!((p / RADIUS as f32 - n).length() < 1e-6);
            assert!((p.length() - RADIUS as f32).abs() < 1e-6);
        }
    }

    #[test]
    fn sphere_counts_seam_and_closure() {
        let mesh = mesh(96, 48).unwrap();
        assert_eq!(mesh.vertex_count(), 97 * 49);
        assert_eq!(mesh.triangle_count(), 2 * 96 * 47);
        // The seam is duplicated: first and last columns share positions, not u.
        let equator = 24 * 97;
        let (first, last) = (mesh.positions[equator], mesh.positions[equator + 96]);
        assert!(first.distance(last) < 1e-6);
        assert!(mesh.uvs.iter().all(|uv| (0.0..=1.0).contains(&uv.x)));
        assert_eq!(mesh.uvs[0].y, 0.0);
        assert_eq!(mesh.uvs.last().unwrap().y, 1.0);
        assert_closed(&mesh, 1e-5);
    }

    #[test]
    fn texture_is_not_mirrored_seen_from_outside() {
        // Walking towards larger u on the equator must move right for an outside viewer,
        // i.e. counter-clockwise about +y seen from above.
        let a = direction(0.0, PI / 2.0);
        let b = direction(0.1, PI / 2.0);
        assert!(a.cross(b).y > 0.0);
    }
}
