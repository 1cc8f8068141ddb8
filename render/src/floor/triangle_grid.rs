//! What the live caustics' photons (shaders/caustics_live.wgsl) need of the mesh, built once
//! on the CPU when live caustics are enabled, in model space: a uniform grid of triangle
//! lists, so that a segment tests the few triangles it can meet among the sphere's 9024; the
//! shell every surface point lies in, so that it walks only its stretches through it; and the
//! triangles as a corner and two edges.

use glam::Vec3;

/// Grid cells per triangle of the mesh: smaller cells hold fewer triangles to test, more
/// cells take more steps. Since a ray walks only its stretches through the shell the surface
/// lies in (caustics_live.wgsl `closest_hit`), steps are few: on the glass sphere (9024
/// triangles) 16 cut the unsmoothed `live caustics` stage at 1980 x 1980 from 83 ms to 72 ms
/// against 4 on lavapipe (64, which the 64 cells per axis cap, 71 ms). Before the shell, 4
/// had cut it by about 7 % against 1 (155-156 ms against 164-172 ms).
const CELLS_PER_TRIANGLE: f32 = 16.0;

/// A uniform grid over the mesh's bounding box, model space: the triangles overlapping each
/// cell (x fastest, then y, then z).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Grid {
    /// Lower corner, model units.
    pub origin: Vec3,
    /// Side of a cell, model units.
    pub side: f32,
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// First entry in `triangles` and count, per cell.
    pub cells: Vec<[u32; 2]>,
    /// Triangle indices, cell after cell.
    pub triangles: Vec<u32>,
}

impl Grid {
    /// About [`CELLS_PER_TRIANGLE`] cells per triangle, cubic cells over the bounding box,
    /// every triangle listed in each cell its bounding box overlaps.
    pub fn new(positions: &[Vec3], indices: &[u32]) -> Grid {
        let lo = positions.iter().copied().fold(Vec3::INFINITY, Vec3::min);
        let hi = positions
            .iter()
            .copied()
            .fold(Vec3::NEG_INFINITY, Vec3::max);
        let extent = (hi - lo).max(Vec3::splat(1e-6));
        let count = (indices.len() / 3).max(1) as f32;
        let per_axis = (count * CELLS_PER_TRIANGLE).cbrt().ceil().clamp(1.0, 64.0);
        let side = extent.max_element() / per_axis;
        let pad = Vec3::splat(side * 1e-3);
        let origin = lo - pad;
        let dims = ((extent + 2.0 * pad) / side)
            .ceil()
            .max(Vec3::ONE)
            .as_uvec3()
            .to_array();
        let cell_of = |p: Vec3| {
            ((p - origin) / side)
                .floor()
                .max(Vec3::ZERO)
                .as_uvec3()
                .min(glam::UVec3::from_array(dims) - 1)
        };
        let total = (dims[0] * dims[1] * dims[2]) as usize;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); total];
        for (t, tri) in indices.chunks_exact(3).enumerate() {
            let corners = tri.iter().map(|&i| positions[i as usize]);
            let tlo = corners.clone().fold(Vec3::INFINITY, Vec3::min) - pad;
            let thi = corners.fold(Vec3::NEG_INFINITY, Vec3::max) + pad;
            let (a, b) = (cell_of(tlo), cell_of(thi));
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        lists[(x + dims[0] * (y + dims[1] * z)) as usize].push(t as u32);
                    }
                }
            }
        }
        let mut cells = Vec::with_capacity(total);
        let mut triangles = Vec::new();
        for list in lists {
            cells.push([triangles.len() as u32, list.len() as u32]);
            triangles.extend(list);
        }
        Grid {
            origin,
            side,
            dims,
            cells,
            triangles,
        }
    }
}

/// The smallest distance from `center` to the plane of any of the mesh's triangles (model
/// units; degenerate triangles skipped): every point of the surface is at least that far
/// from `center` (0 where a plane passes through it).
pub(crate) fn inner_radius(positions: &[Vec3], indices: &[u32], center: Vec3) -> f32 {
    indices
        .chunks_exact(3)
        .filter_map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            let normal = (b - a).cross(c - a).try_normalize()?;
            Some(normal.dot(a - center).abs())
        })
        .fold(f32::INFINITY, f32::min)
        .min(
            positions
                .iter()
                .map(|p| p.distance(center))
                .fold(f32::INFINITY, f32::min),
        )
}

/// Whether `center` lies strictly behind the plane of every triangle (wound outward;
/// degenerate ones skipped). For a convex mesh that means it lies inside, and so does the
/// ball of [`inner_radius`] about it: a ray inside the body then meets no surface before it
/// has passed that ball.
pub(crate) fn behind_every_plane(positions: &[Vec3], indices: &[u32], center: Vec3) -> bool {
    indices.chunks_exact(3).all(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
        (b - a)
            .cross(c - a)
            .try_normalize()
            .is_none_or(|n| n.dot(center - a) < 0.0)
    })
}

/// Per triangle its first corner and its two edges from it (model units), in order.
pub(crate) fn corner_and_edges(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    indices
        .chunks_exact(3)
        .flat_map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            [a, b - a, c - a]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_triangle_is_listed_in_the_cells_around_it() {
        let positions = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let indices = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
        let grid = Grid::new(&positions, &indices);
        // Four cells per side over the unit box (cbrt(4 x 16)), one more for the padding's
        // hair beyond it.
        assert_eq!(grid.dims, [5, 5, 5]);
        assert!((grid.side - 0.25).abs() < 1e-6);
        // Each triangle appears at least once, the one facing the origin's corner in all
        // cells its box touches.
        for t in 0..4u32 {
            assert!(grid.triangles.contains(&t));
        }
        let total: u32 = grid.cells.iter().map(|c| c[1]).sum();
        assert_eq!(total as usize, grid.triangles.len());
        let corner = grid.cells[0];
        assert_eq!(corner[1], 4, "every face touches the cell at the origin");
    }

    /// A cube of half-side 1 about the origin, 12 triangles, offset by `shift`.
    fn cube(shift: Vec3) -> (Vec<Vec3>, Vec<u32>) {
        let positions = (0..8)
            .map(|i| {
                let bit = |k: u32| if i >> k & 1 == 1 { 1.0 } else { -1.0 };
                Vec3::new(bit(0), bit(1), bit(2)) + shift
            })
            .collect();
        let faces = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        let indices = faces
            .iter()
            .flat_map(|[a, b, c, d]| [*a, *b, *c, *a, *c, *d])
            .collect();
        (positions, indices)
    }

    #[test]
    fn the_shell_holds_every_surface_point() {
        // About the centre the faces' planes are 1 away, the corners sqrt(3).
        let (positions, indices) = cube(Vec3::ZERO);
        assert!((inner_radius(&positions, &indices, Vec3::ZERO) - 1.0).abs() < 1e-6);
        // Seen from a point in the plane of a face, the shell reaches down to it.
        assert_eq!(inner_radius(&positions, &indices, Vec3::X), 0.0);
        // Points sampled over every triangle lie no nearer than the inner radius, from an
        // off-centre point too.
        let (positions, indices) = cube(Vec3::new(0.3, -0.2, 0.1));
        let center = Vec3::new(0.1, 0.1, -0.2);
        let inner = inner_radius(&positions, &indices, center);
        assert!(inner > 0.5, "{inner}");
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            for (u, v) in [(0.0, 0.0), (0.5, 0.5), (0.2, 0.3), (1.0, 0.0), (0.0, 1.0)] {
                let point = a + u * (b - a) + v * (c - a);
                assert!(point.distance(center) >= inner - 1e-6);
            }
        }
    }

    #[test]
    fn a_centre_is_behind_every_plane_only_inside_the_body() {
        // `cube` winds its faces inward: turned outward.
        let (positions, inward) = cube(Vec3::ZERO);
        let indices: Vec<u32> = inward
            .chunks_exact(3)
            .flat_map(|t| [t[0], t[2], t[1]])
            .collect();
        assert!(!behind_every_plane(&positions, &inward, Vec3::ZERO));
        assert!(behind_every_plane(&positions, &indices, Vec3::ZERO));
        assert!(behind_every_plane(&positions, &indices, Vec3::splat(0.9)));
        assert!(!behind_every_plane(
            &positions,
            &indices,
            Vec3::new(1.1, 0.0, 0.0)
        ));
        // On a face's plane is not behind it.
        assert!(!behind_every_plane(&positions, &indices, Vec3::X));
        // A corner tetrahedron's bounding-box centre lies outside it.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let indices = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
        assert!(!behind_every_plane(&positions, &indices, Vec3::splat(0.5)));
        assert!(behind_every_plane(&positions, &indices, Vec3::splat(0.2)));
    }

    #[test]
    fn a_triangle_is_stored_as_its_first_corner_and_two_edges() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let edges = corner_and_edges(&positions, &[1, 2, 3]);
        assert_eq!(edges, vec![Vec3::X, Vec3::Y - Vec3::X, Vec3::Z - Vec3::X]);
    }
}
