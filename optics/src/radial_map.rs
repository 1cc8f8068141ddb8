//! The radial map (`[object] refraction = "two-surface"` on the GPU): the object's surface seen
//! from its centre, built once on the CPU with the mesh tracer of [`crate::two_surface`], which
//! also holds the rule shared with the glass shader for a ball's surface between its vertices
//! ([`crate::two_surface::RADIAL_NORMAL_COS`]).

use glam::Vec3;

use crate::solid::SolidError;
use crate::two_surface::MeshBody;

/// The object's centre: the middle of its bounding box (model units).
pub fn mesh_center(positions: &[Vec3]) -> Vec3 {
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| {
            (l.min(p), h.max(p))
        });
    if lo.is_finite() && hi.is_finite() {
        (lo + hi) / 2.0
    } else {
        Vec3::ZERO
    }
}

/// Width of the radial map, texels (latitude-longitude; 0.7 degrees a texel).
pub const RADIAL_MAP_WIDTH: u32 = 512;
/// Height of the radial map, texels.
pub const RADIAL_MAP_HEIGHT: u32 = 256;

/// The object's surface seen from its centre, for the GPU's two-surface mode
/// (shaders/glass.wgsl `radial_surface`): for each direction d of a latitude-longitude map
/// (the environment map's layout), the distance r(d) from the centre to the surface and the
/// outward shading normal there. Exact for a body star-shaped about its centre (every convex
/// body is); for other bodies the outermost surface along each direction is kept.
///
/// Stored relative to a sphere, so that half floats keep what matters: rgb = normal - d and
/// a = r - `radius`, both zero for a ball.
#[derive(Clone, Debug)]
pub struct RadialMap {
    /// Centre of the map, model units (the mesh's bounding-box centre).
    pub center: Vec3,
    /// Reference radius, model units (the largest vertex distance from the centre).
    pub radius: f32,
    /// Texels per row.
    pub width: u32,
    /// Rows (row 0 looks up, +y).
    pub height: u32,
    /// RGBA texels, row-major.
    pub texels: Vec<f32>,
    /// Every direction from the centre meets the surface once (the map is exact).
    pub star_shaped: bool,
}

impl RadialMap {
    /// Whether the map is a ball's: every texel at the reference radius (within 1e-5 of it)
    /// with the normal along its direction (within 1e-4), so that the sphere can stand for it.
    pub fn ball(&self) -> bool {
        self.star_shaped
            && self.texels.chunks_exact(4).all(|t| {
                t[3].abs() <= 1e-5 * self.radius && Vec3::new(t[0], t[1], t[2]).length() <= 1e-4
            })
    }
}

/// The unit direction the centre of texel (`x`, `y`) of a `width` x `height`
/// latitude-longitude map looks along (inverse of glass.wgsl `latlong_uv`).
pub fn latlong_direction(x: u32, y: u32, width: u32, height: u32) -> Vec3 {
    let phi = ((x as f32 + 0.5) / width as f32 - 0.5) * std::f32::consts::TAU;
    let theta = (y as f32 + 0.5) / height as f32 * std::f32::consts::PI;
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// Builds the radial map of a closed mesh (model units), casting one ray from the centre per
/// texel through the mesh's hierarchy.
pub fn radial_map(
    positions: &[Vec3],
    normals: &[Vec3],
    indices: &[u32],
    width: u32,
    height: u32,
) -> Result<RadialMap, SolidError> {
    let center = mesh_center(positions);
    let local: Vec<Vec3> = positions.iter().map(|&p| p - center).collect();
    let body = MeshBody::new(&local, normals, indices)?;
    let radius = local.iter().map(|p| p.length()).fold(0.0f32, f32::max);
    let eps = radius * 1e-5;
    let mut texels = Vec::with_capacity((width * height * 4) as usize);
    let mut star_shaped = true;
    for y in 0..height {
        for x in 0..width {
            let d = latlong_direction(x, y, width, height);
            // The outermost crossing: the only one for a star-shaped body.
            let mut found: Option<(f32, Vec3)> = None;
            let mut from = 0.0;
            while let Some(hit) = body.hit_with_curve(d * from, d) {
                if found.is_some() {
                    star_shaped = false;
                }
                from += hit.t_m + eps;
                // From the centre along d: the flat triangle at `from - eps`, the sphere
                // about the centre through radial-normal corners at the interpolated radius.
                let flat = from - eps;
                found = Some((flat + (hit.curved_radius - flat) * hit.curved, hit.normal));
            }
            let (r, n) = found.unwrap_or_else(|| {
                star_shaped = false;
                (radius, d)
            });
            texels.extend_from_slice(&[n.x - d.x, n.y - d.y, n.z - d.z, r - radius]);
        }
    }
    Ok(RadialMap {
        center,
        radius,
        width,
        height,
        texels,
        star_shaped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::two_surface::Ball;
    use crate::two_surface::tests::sphere_mesh;

    #[test]
    fn the_radial_map_of_a_sphere_mesh_is_its_radius_and_radial_normals() {
        let b = Ball {
            center_m: Vec3::new(0.3, -0.1, 0.2),
            radius_m: 1.0,
        };
        let mesh = sphere_mesh(&b, 96, 48);
        let positions: Vec<Vec3> = mesh.solid.triangles_m.iter().flatten().copied().collect();
        let normals: Vec<Vec3> = mesh
            .solid
            .corner_normals
            .iter()
            .flatten()
            .copied()
            .collect();
        let indices: Vec<u32> = (0..positions.len() as u32).collect();
        let map = radial_map(&positions, &normals, &indices, 64, 32).unwrap();
        assert!(map.star_shaped);
        assert!(map.ball());
        assert!(map.center.abs_diff_eq(b.center_m, 1e-5));
        for t in map.texels.chunks_exact(4) {
            // The vertex normals point away from the centre, so the surface between the
            // vertices is the sphere through them, not the flat triangles (which sag inside by
            // up to (pi / 96)^2 / 2 + (pi / 48)^2 / 8, about 7e-4 of the radius).
            assert!(t[3].abs() < 2e-6, "{t:?}");
            assert!(Vec3::new(t[0], t[1], t[2]).length() < 0.05, "{t:?}");
        }
    }

    #[test]
    fn the_radial_map_of_a_cube_keeps_its_flat_faces() {
        // Face normals do not point away from the centre (except at the face centres, which
        // are no vertices): the faces stay flat.
        let (positions, normals, indices) = crate::solid::flat_cube(0.5);
        let (width, height) = (64, 32);
        let map = radial_map(&positions, &normals, &indices, width, height).unwrap();
        assert!(map.star_shaped);
        assert!(!map.ball());
        for y in 0..height {
            for x in 0..width {
                let d = latlong_direction(x, y, width, height);
                let t = &map.texels[((y * width + x) * 4) as usize..][..4];
                let flat = 0.5 / d.abs().max_element();
                assert!(
                    (map.radius + t[3] - flat).abs() < 1e-3 * flat,
                    "direction {d}: radius {} against the face's {flat}",
                    map.radius + t[3]
                );
            }
        }
    }
}
