//! A ball drawn on a proxy: where the glass's pipelines find the ball's light from its sphere
//! alone (a ball's two parts in the room: shaders/shared/glass_positions.wgsl), its triangles
//! only say which pixels to shade. The model's own (9024 triangles for the shipped sphere, about
//! one and a half pixels each at 1280 x 960) make the device shade each pixel about nine times
//! (lavapipe; a GPU shades 2 x 2 quads, as many on triangles that small), and every time the
//! whole pixel's positions. A geodesic polyhedron of 80 faces, every face outside the sphere,
//! holds the ball's whole outline in about two hundred pixels a triangle (1.8 invocations a
//! pixel on lavapipe; 320 faces, 2.5); its vertex shader (`vs_ball_proxy`) gives the sphere's
//! radius, and a pixel whose centre's ray passes beside the sphere draws nothing, as one outside
//! the model's triangles did.

use ash::vk;
use glam::Vec3;

use super::patches::Patches;
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Buffer;

/// Times the icosahedron's faces are split in four.
const SPLITS: u32 = 1;

/// How far beyond the sphere the faces lie at least, as a share of its radius: room for
/// rounding in the vertex positions and the rasteriser.
const MARGIN: f32 = 1e-4;

/// A ball's proxy on the device: its vertices (the scene's vertex layout) and its triangles in
/// patches (`patches.rs`).
pub struct Proxy {
    pub patches: Patches,
    pub vertices: Buffer,
    pub indices: Buffer,
}

impl Proxy {
    /// The proxy of the ball about `center` of `radius` (model units), uploaded.
    pub fn new(ctx: &GpuContext, center: Vec3, radius: f32) -> Result<Proxy> {
        let (positions, indices) = polyhedron(center, radius);
        let vertices: Vec<f32> = positions
            .iter()
            .flat_map(|&p| {
                let n = (p - center).normalize_or_zero();
                [p.x, p.y, p.z, n.x, n.y, n.z, 0.0, 0.0]
            })
            .collect();
        let patches = Patches::new(&positions, &indices, center);
        let vertices = Buffer::with_data(
            ctx,
            "glass proxy's vertices",
            bytemuck::cast_slice(&vertices),
            vk::BufferUsageFlags::VERTEX_BUFFER,
        )?;
        let indices = Buffer::with_data(
            ctx,
            "glass proxy's indices",
            bytemuck::cast_slice(&patches.indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
        )?;
        Ok(Proxy {
            patches,
            vertices,
            indices,
        })
    }
}

/// A geodesic polyhedron about `center` whose every face lies outside the sphere of `radius`
/// by at least `MARGIN` of it: its vertices and its triangles, wound counter-clockwise seen
/// from outside (as glTF winds a front face).
pub fn polyhedron(center: Vec3, radius: f32) -> (Vec<Vec3>, Vec<u32>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut directions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|v| Vec3::from_array(v).normalize())
    .to_vec();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..SPLITS {
        let mut middles = std::collections::HashMap::new();
        let mut middle = |a: u32, b: u32, directions: &mut Vec<Vec3>| -> u32 {
            *middles.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (directions[a as usize] + directions[b as usize]).normalize();
                directions.push(m);
                directions.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = middle(a, b, &mut directions);
                let bc = middle(b, c, &mut directions);
                let ca = middle(c, a, &mut directions);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    // The faces' least distance from the centre, the vertices on the unit sphere.
    let least = faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| directions[i as usize]);
            (b - a).cross(c - a).normalize().dot(a)
        })
        .fold(f32::INFINITY, f32::min);
    let scale = radius * (1.0 + MARGIN) / least;
    let positions = directions.iter().map(|&d| center + d * scale).collect();
    (positions, faces.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_face_lies_outside_the_sphere_and_faces_outwards() {
        let (center, radius) = (Vec3::new(0.1, -0.2, 0.3), 0.04);
        let (positions, indices) = polyhedron(center, radius);
        assert_eq!(indices.len(), 3 * 80);
        assert_eq!(positions.len(), 42);
        let mut farthest = 0.0f32;
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|i| positions[t[i] as usize] - center);
            let normal = (b - a).cross(c - a).normalize();
            let offset = normal.dot(a);
            // Counter-clockwise seen from outside, and beyond the sphere.
            assert!(offset >= radius * (1.0 + 0.5 * MARGIN), "{offset}");
            farthest = farthest.max(a.length());
        }
        // Close about it: the vertices within 10 % of the radius.
        assert!(farthest < radius * 1.1, "{farthest}");
    }

    #[test]
    fn the_surface_is_closed() {
        let (_, indices) = polyhedron(Vec3::ZERO, 1.0);
        // Each edge in one direction once, and in the other once.
        let mut edges = std::collections::HashMap::new();
        for t in indices.chunks_exact(3) {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(count, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
    }

    #[test]
    fn every_direction_from_the_centre_meets_a_face_beyond_the_sphere() {
        // Rays from the centre: each leaves the polyhedron through one face, beyond the radius.
        let (positions, indices) = polyhedron(Vec3::ZERO, 1.0);
        for i in 0..500 {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 500.0;
            let around = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new(r * around.cos(), z, r * around.sin());
            let exits: Vec<f32> = indices
                .chunks_exact(3)
                .filter_map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
                    let n = (b - a).cross(c - a);
                    let s = n.dot(a) / n.dot(d);
                    let p = d * s;
                    let inside = [(a, b), (b, c), (c, a)]
                        .iter()
                        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= -1e-6);
                    (s > 0.0 && inside).then_some(s)
                })
                .collect();
            assert!(!exits.is_empty(), "{d}");
            assert!(exits.iter().all(|&s| s >= 1.0), "{exits:?}");
        }
    }
}
