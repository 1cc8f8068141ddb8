//! Indexed triangle meshes with the vertex layout every vitreous model ships with.

use glam::{DVec3, Vec2, Vec3};

/// An indexed triangle list with one position, normal and texture coordinate per vertex.
///
/// Model units: 1.0 is the object's diameter, so the renderer scales it to the scene size.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, centred on the origin with +y up.
    pub positions: Vec<Vec3>,
    /// Unit outward normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Texture coordinates in the glTF convention (origin at the image's top-left).
    pub uvs: Vec<Vec2>,
    /// Three indices per triangle, counter-clockwise when seen from outside.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends a vertex and returns its index.
    pub fn push_vertex(&mut self, position: Vec3, normal: Vec3, uv: Vec2) -> u32 {
        let index = u32::try_from(self.positions.len()).expect("mesh exceeds u32 indices");
        self.positions.push(position);
        self.normals.push(normal);
        self.uvs.push(uv);
        index
    }

    /// Appends one triangle; the corners must be counter-clockwise seen from outside.
    pub fn push_triangle(&mut self, a: u32, b: u32, c: u32) {
        self.indices.extend_from_slice(&[a, b, c]);
    }

    /// Appends a flat-shaded convex polygon: its own vertices, all carrying the facet normal,
    /// fanned from the first corner. `uv` maps a corner position to its texture coordinate.
    pub fn push_flat_polygon(&mut self, corners: &[DVec3], uv: impl Fn(DVec3) -> Vec2) {
        assert!(corners.len() >= 3, "a facet needs at least three corners");
        let normal = polygon_normal(corners).as_vec3();
        let first = self.positions.len() as u32;
        for &corner in corners {
            self.push_vertex(corner.as_vec3(), normal, uv(corner));
        }
        for k in 1..corners.len() as u32 - 1 {
            self.push_triangle(first, first + k, first + k + 1);
        }
    }

    /// Builds a closed parametric surface from a `(columns + 1) x (rows + 1)` vertex grid.
    ///
    /// `vertex(u, v)` returns position and unit normal for `u, v` in `[0, 1]`; `u` runs to the
    /// right and `v` downwards when the outside is seen, so `(top-left, bottom-left,
    /// bottom-right)` is counter-clockwise. The seam column `u = 1` is duplicated so the texture
    /// coordinates do not wrap. With `poles`, the first and last rows collapse to a point, and
    /// the triangles there that would have zero area are left out.
    pub fn from_grid(
        columns: u32,
        rows: u32,
        poles: bool,
        vertex: impl Fn(f64, f64) -> (DVec3, DVec3),
    ) -> Mesh {
        let mut mesh = Mesh::default();
        for row in 0..=rows {
            let v = f64::from(row) / f64::from(rows);
            for column in 0..=columns {
                let u = f64::from(column) / f64::from(columns);
                let (position, normal) = vertex(u, v);
                mesh.push_vertex(
                    position.as_vec3(),
                    normal.normalize().as_vec3(),
                    Vec2::new(u as f32, v as f32),
                );
            }
        }
        let stride = columns + 1;
        for row in 0..rows {
            for column in 0..columns {
                let top_left = row * stride + column;
                let bottom_left = top_left + stride;
                let bottom_right = bottom_left + 1;
                let top_right = top_left + 1;
                if !(poles && row + 1 == rows) {
                    mesh.push_triangle(top_left, bottom_left, bottom_right);
                }
                if !(poles && row == 0) {
                    mesh.push_triangle(top_left, bottom_right, top_right);
                }
            }
        }
        mesh
    }

    /// Axis-aligned bounds of the positions as `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(min, max), &p| (min.min(p), max.max(p)),
        )
    }

    /// Enclosed volume by the divergence theorem; positive when the winding is
    /// counter-clockwise seen from outside.
    pub fn signed_volume(&self) -> f64 {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| self.positions[t[k] as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }
}

/// Unit normal of a planar polygon from the sum of its edge cross products (Newell's method);
/// it points to the side from which the corners run counter-clockwise.
pub fn polygon_normal(corners: &[DVec3]) -> DVec3 {
    let n = corners.len();
    (0..n)
        .map(|k| corners[k].cross(corners[(k + 1) % n]))
        .sum::<DVec3>()
        .normalize()
}

#[cfg(test)]
pub mod checks {
    //! Topology checks shared by the shape tests.

    use super::Mesh;
    use std::collections::HashMap;

    /// Maps each vertex to the first vertex within `tolerance` of it (welding by position).
    pub fn weld(mesh: &Mesh, tolerance: f32) -> Vec<u32> {
        let mut representatives: Vec<u32> = Vec::new();
        mesh.positions
            .iter()
            .enumerate()
            .map(|(index, &p)| {
                match representatives
                    .iter()
                    .find(|&&r| mesh.positions[r as usize].distance(p) <= tolerance)
                {
                    Some(&r) => r,
                    None => {
                        representatives.push(index as u32);
                        index as u32
                    }
                }
            })
            .collect()
    }

    /// Panics unless, after welding, every edge is used once in each direction: the surface is
    /// closed (watertight), two-manifold along edges and consistently oriented.
    pub fn assert_closed(mesh: &Mesh, tolerance: f32) {
        let welded = weld(mesh, tolerance);
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| welded[t[k] as usize]);
            assert!(a != b && b != c && c != a, "degenerate triangle {t:?}");
            for edge in [(a, b), (b, c), (c, a)] {
                *directed.entry(edge).or_default() += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            assert_eq!(
                count, 1,
                "edge {a}->{b} used {count} times in one direction"
            );
            assert_eq!(
                directed.get(&(b, a)),
                Some(&1),
                "edge {a}->{b} has no opposite: surface is open or inconsistently wound"
            );
        }
    }
}
