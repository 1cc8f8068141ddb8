//! Closed triangle meshes for CPU ray tracing: the caustics baker's light paths and the
//! two-surface refraction reference both trace through a [`Solid`] with its [`bvh::Bvh`].
//!
//! Checks that a triangle mesh bounds a volume (every edge shared by exactly two triangles,
//! consistently wound), orients it outwards, and splits it into smooth patches.
//!
//! A smooth patch is a set of triangles joined across edges where the vertex normals agree,
//! so a flat-shaded facet (the diamond's kites) is one patch and a smooth-shaded sphere is
//! one patch across its UV seam. The wavefront baker only interpolates between light paths
//! that cross the same patches in the same order.

pub mod bvh;

use std::collections::HashMap;

use glam::Vec3;
use thiserror::Error;

/// The object's centre: the middle of its bounding box (model units); the origin of the frame
/// the glass shader finds where a ray leaves the object in.
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

/// Why a triangle mesh is not a closed solid.
#[derive(Debug, Error)]
pub enum SolidError {
    /// The mesh has no triangles with area.
    #[error("the object's mesh has no triangles with non-zero area")]
    EmptyMesh,
    /// Indices or positions are malformed.
    #[error("the object's mesh is malformed: {0}")]
    BadMesh(String),
    /// Some edges are not shared by exactly two triangles.
    #[error(
        "the object's mesh does not enclose a volume: {open_edges} edge(s) are not shared by \
         exactly two triangles (one near {example_m}); glass must be a closed solid: give a \
         surface modelled as a single sheet its thickness (in Blender, the Solidify modifier), \
         close any holes, and merge duplicated vertices (Blender: Merge by Distance)"
    )]
    OpenMesh {
        /// Number of welded edges used by one, or more than two, triangles.
        open_edges: usize,
        /// Midpoint of one such edge, in the frame and units of the positions given.
        example_m: Vec3,
    },
    /// Neighbouring triangles disagree about which side is outside.
    #[error(
        "the object's mesh is inconsistently wound: {edges} edge(s) are traversed in the same \
         direction by both triangles (one near {example_m}); make every face \
         counter-clockwise seen from outside (Blender: Recalculate Outside)"
    )]
    InconsistentWinding {
        /// Number of such edges.
        edges: usize,
        /// Midpoint of one such edge, in the frame of the positions given.
        example_m: Vec3,
    },
}

/// A closed, outward-wound triangle mesh.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Corner positions of each non-degenerate triangle, metres, counter-clockwise seen
    /// from outside.
    pub triangles_m: Vec<[Vec3; 3]>,
    /// Unit shading normals at each triangle's corners, pointing outwards.
    pub corner_normals: Vec<[Vec3; 3]>,
    /// Smooth-patch index of each triangle.
    pub patch: Vec<u32>,
    /// Number of smooth patches.
    pub patch_count: u32,
}

/// Cosine above which two vertex normals count as the same (smooth shading across the edge).
const SMOOTH_COS: f32 = 0.9999;

impl Solid {
    /// Builds a solid from positions (metres), unit vertex normals and a triangle list.
    /// Triangles with zero area are dropped; everything else must close up.
    pub fn new(
        positions_m: &[Vec3],
        normals: &[Vec3],
        indices: &[u32],
    ) -> Result<Self, SolidError> {
        if indices.is_empty() || positions_m.is_empty() {
            return Err(SolidError::EmptyMesh);
        }
        if !indices.len().is_multiple_of(3) {
            return Err(SolidError::BadMesh(format!(
                "the index list has {} entries, not a multiple of 3",
                indices.len()
            )));
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions_m.len()) {
            return Err(SolidError::BadMesh(format!(
                "index {i} is out of range for {} vertices",
                positions_m.len()
            )));
        }
        if let Some(p) = positions_m.iter().find(|p| !p.is_finite()) {
            return Err(SolidError::BadMesh(format!(
                "vertex position {p} is not finite"
            )));
        }
        let have_normals = normals.len() == positions_m.len();

        // Weld positions closer than a millionth of the mesh size so UV seams, flat shading
        // and rounding at a seam do not look like holes.
        let (lo, hi) = positions_m
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| {
                (l.min(p), h.max(p))
            });
        let tol = ((hi - lo).max_element() * 1e-6).max(f32::MIN_POSITIVE);
        let welded = weld(positions_m, tol);

        let mut tris: Vec<[u32; 3]> = Vec::new();
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions_m[i as usize]);
            let w = [t[0], t[1], t[2]].map(|i| welded[i as usize]);
            if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
                continue;
            }
            if (b - a).cross(c - a).length_squared() <= 0.0 {
                continue;
            }
            tris.push([t[0], t[1], t[2]]);
        }
        if tris.is_empty() {
            return Err(SolidError::EmptyMesh);
        }

        // Every undirected welded edge: (low, high, triangle, runs low->high).
        let mut edges: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(tris.len() * 3);
        for (ti, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (welded[t[k] as usize], welded[t[(k + 1) % 3] as usize]);
                edges.push((a.min(b), a.max(b), ti as u32, a < b));
            }
        }
        edges.sort_unstable();

        let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
        let mut open_edges = 0usize;
        let mut misoriented = 0usize;
        let mut example: Option<Vec3> = None;
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
                j += 1;
            }
            let group = &edges[i..j];
            if group.len() != 2 {
                open_edges += 1;
                example.get_or_insert_with(|| {
                    edge_midpoint(positions_m, &welded, group[0].0, group[0].1)
                });
            } else if group[0].3 == group[1].3 {
                misoriented += 1;
                example.get_or_insert_with(|| {
                    edge_midpoint(positions_m, &welded, group[0].0, group[0].1)
                });
            } else if have_normals {
                let (t0, t1) = (group[0].2 as usize, group[1].2 as usize);
                let smooth = [group[0].0, group[0].1].iter().all(|&wv| {
                    let n0 = corner_normal_at(&tris[t0], &welded, normals, wv);
                    let n1 = corner_normal_at(&tris[t1], &welded, normals, wv);
                    n0.dot(n1) > SMOOTH_COS
                });
                if smooth {
                    union(&mut parent, t0 as u32, t1 as u32);
                }
            }
            i = j;
        }
        if open_edges > 0 {
            return Err(SolidError::OpenMesh {
                open_edges,
                example_m: example.unwrap_or_default(),
            });
        }
        if misoriented > 0 {
            return Err(SolidError::InconsistentWinding {
                edges: misoriented,
                example_m: example.unwrap_or_default(),
            });
        }

        // Outward winding has a positive enclosed volume.
        let volume: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions_m[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let flip = volume < 0.0;

        let mut patch_of_root: HashMap<u32, u32> = HashMap::new();
        let mut patch = Vec::with_capacity(tris.len());
        let mut triangles_m = Vec::with_capacity(tris.len());
        let mut corner_normals = Vec::with_capacity(tris.len());
        for (ti, &tri) in tris.iter().enumerate() {
            let root = find(&mut parent, ti as u32);
            let next = patch_of_root.len() as u32;
            patch.push(*patch_of_root.entry(root).or_insert(next));
            let mut t = tri;
            if flip {
                t.swap(1, 2);
            }
            let p = t.map(|i| positions_m[i as usize]);
            let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            let n = t.map(|i| {
                let n = if have_normals {
                    normals[i as usize]
                } else {
                    face
                };
                // Shading normals must agree with the outward side.
                let n = if flip { -n } else { n };
                if n.is_finite() && n.dot(face) > 0.0 {
                    n.normalize()
                } else {
                    face
                }
            });
            triangles_m.push(p);
            corner_normals.push(n);
        }
        Ok(Solid {
            triangles_m,
            corner_normals,
            patch,
            patch_count: patch_of_root.len() as u32,
        })
    }
}

/// Welded vertex id per position: points within `tol` of an earlier representative share it.
fn weld(positions_m: &[Vec3], tol: f32) -> Vec<u32> {
    let cell = |p: Vec3| (p / tol).floor().as_ivec3();
    let mut grid: HashMap<glam::IVec3, Vec<(Vec3, u32)>> = HashMap::new();
    let mut next = 0u32;
    positions_m
        .iter()
        .map(|&p| {
            let c = cell(p);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        if let Some(reps) = grid.get(&(c + glam::IVec3::new(dx, dy, dz)))
                            && let Some(&(_, id)) = reps.iter().find(|(q, _)| q.distance(p) <= tol)
                        {
                            return id;
                        }
                    }
                }
            }
            let id = next;
            next += 1;
            grid.entry(c).or_default().push((p, id));
            id
        })
        .collect()
}

fn edge_midpoint(positions_m: &[Vec3], welded: &[u32], a: u32, b: u32) -> Vec3 {
    let pa = welded.iter().position(|&w| w == a).map(|i| positions_m[i]);
    let pb = welded.iter().position(|&w| w == b).map(|i| positions_m[i]);
    match (pa, pb) {
        (Some(pa), Some(pb)) => (pa + pb) / 2.0,
        _ => Vec3::ZERO,
    }
}

fn corner_normal_at(tri: &[u32; 3], welded: &[u32], normals: &[Vec3], wv: u32) -> Vec3 {
    tri.iter()
        .find(|&&i| welded[i as usize] == wv)
        .map(|&i| normals[i as usize])
        .unwrap_or(Vec3::ZERO)
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// A cube of side 2 `half` about the origin with flat normals: 24 vertices, 12 triangles,
/// 6 patches (positions, normals, indices). The tests' reference solid: closed, convex, and
/// with paths through it known in closed form.
pub fn flat_cube(half: f32) -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
    let mut p = Vec::new();
    let mut n = Vec::new();
    let mut idx = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            let u =
                Vec3::from_array([0, 1, 2].map(|k| if k == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let v = normal.cross(u);
            let base = p.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                p.push(half * (normal + a * u + b * v));
                n.push(normal);
            }
            idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    (p, n, idx)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The unit cube.
    fn cube() -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
        flat_cube(0.5)
    }

    #[test]
    fn flat_cube_is_closed_with_one_patch_per_face() {
        let (p, n, i) = cube();
        let s = Solid::new(&p, &n, &i).unwrap();
        assert_eq!(s.triangles_m.len(), 12);
        assert_eq!(s.patch_count, 6);
    }

    #[test]
    fn inward_winding_is_flipped_outwards() {
        let (p, n, mut i) = cube();
        for t in i.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        let s = Solid::new(&p, &n, &i).unwrap();
        for t in &s.triangles_m {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            assert!((t[1] - t[0]).cross(t[2] - t[0]).dot(c) > 0.0);
        }
    }

    #[test]
    fn open_and_misoriented_meshes_are_refused() {
        let (p, n, i) = cube();
        let err = Solid::new(&p, &n, &i[..i.len() - 6]).unwrap_err();
        assert!(
            matches!(err, SolidError::OpenMesh { open_edges: 4, .. }),
            "{err}"
        );
        // The message says how to close it, in the words of the tool most models come from.
        let message = err.to_string();
        assert!(
            message.contains("Solidify") && message.contains("Merge by Distance"),
            "{message}"
        );
        let mut i2 = i.clone();
        i2.swap(1, 2);
        i2.swap(4, 5);
        let err = Solid::new(&p, &n, &i2).unwrap_err();
        assert!(
            matches!(err, SolidError::InconsistentWinding { .. }),
            "{err}"
        );
    }
}
