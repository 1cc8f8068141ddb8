//! Faceted convex objects (a cut gem): the planes of their facets, so that the glass shader
//! finds where a ray inside leaves them exactly (shaders/glass.wgsl `convex_exit`) from a loop
//! over the planes, without a search of the triangles.

use std::collections::HashMap;

use glam::{Vec2, Vec3, Vec4};

/// Most facet planes a convex object may have for the exact exit (a round brilliant has 73
/// with its girdle band): each internal reflection tests every plane once.
pub const MAX_FACET_PLANES: usize = 256;

/// A plane that no ray meets and that holds every point on its inner side (no normal, the
/// centre a unit inside): what [`in_eights`] pads with.
pub const NO_PLANE: Vec4 = Vec4::new(0.0, 0.0, 0.0, 1.0);

/// `planes` padded with [`NO_PLANE`] to a whole number of eights (eight at least): the glass
/// shader tests eight planes a round of its loops (shaders/glass.wgsl `convex_exit`), since
/// lavapipe ends an invocation's loops once they have run 65,535 rounds together.
pub fn in_eights(mut planes: Vec<Vec4>) -> Vec<Vec4> {
    planes.resize(planes.len().max(1).next_multiple_of(8), NO_PLANE);
    planes
}

/// Cosine above which a vertex normal counts as its triangle's face normal (flat shading).
const FLAT_NORMAL_COS: f32 = 0.9999;

/// The facet planes of a flat-shaded convex mesh, about `center` (model units): per plane,
/// xyz its outward unit normal and w its distance from `center`. None when the mesh is not
/// flat-shaded (a vertex normal differs from its triangle's face normal: the shader would
/// then bend rays by other normals than the planes'), not convex (a vertex lies outside a
/// facet's plane), degenerate, or has more than [`MAX_FACET_PLANES`] distinct planes.
///
/// Triangles of one facet give one plane: planes within 1e-5 in normal and 1e-5 of the
/// object's size in distance are merged.
pub fn facet_planes(
    positions: &[Vec3],
    normals: &[Vec3],
    indices: &[u32],
    center: Vec3,
) -> Option<Vec<Vec4>> {
    let size = positions
        .iter()
        .map(|&p| (p - center).length())
        .fold(0.0f32, f32::max);
    let usable = size.is_finite() && size > 0.0;
    if !usable || !indices.len().is_multiple_of(3) || indices.is_empty() {
        return None;
    }
    let tolerance = 1e-5 * size;
    let mut planes: Vec<Vec4> = Vec::new();
    for tri in indices.chunks_exact(3) {
        let corner = |k: usize| positions.get(tri[k] as usize).copied();
        let (a, b, c) = (corner(0)?, corner(1)?, corner(2)?);
        let cross = (b - a).cross(c - a);
        if cross.length() <= 1e-12 * size * size {
            // A sliver adds no surface; its corners are checked against the other planes.
            continue;
        }
        let normal = cross.normalize();
        let flat = tri.iter().all(|&i| {
            normals
                .get(i as usize)
                .is_some_and(|n| n.normalize_or_zero().dot(normal) >= FLAT_NORMAL_COS)
        });
        if !flat {
            return None;
        }
        let plane = normal.extend(normal.dot(a - center));
        let known = planes
            .iter()
            .any(|q| q.truncate().dot(normal) >= 1.0 - 1e-5 && (q.w - plane.w).abs() <= tolerance);
        if !known {
            if planes.len() == MAX_FACET_PLANES {
                return None;
            }
            planes.push(plane);
        }
    }
    let inside = |p: Vec3| {
        planes
            .iter()
            .all(|q| q.truncate().dot(p - center) <= q.w + tolerance)
    };
    // Convex: every vertex behind every facet's plane; and the centre inside, so that every
    // plane's distance is positive and a ray from inside leaves through exactly one of them.
    (!planes.is_empty() && positions.iter().all(|&p| inside(p)) && planes.iter().all(|q| q.w > 0.0))
        .then_some(planes)
}

/// Where the ray `p + t d` (from inside, `d` unit) leaves the convex body of `planes`: the
/// distance t and the outward normal there. The CPU twin of glass.wgsl `convex_exit`.
pub fn convex_exit(planes: &[Vec4], p: Vec3, d: Vec3) -> Option<(f32, Vec3)> {
    planes
        .iter()
        .filter_map(|q| {
            let along = q.truncate().dot(d);
            (along > 1e-7).then(|| (((q.w - q.truncate().dot(p)) / along).max(0.0), q.truncate()))
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
}

/// One side of an edge: the triangle along it, its far corner, and whether the triangle runs
/// along the edge from its lower id.
type Side = (usize, u32, bool);

/// A mesh with vertices within a tolerance of one another merged: its distinct positions, its
/// triangles over them, and per undirected edge its sides.
struct Welded {
    /// Distinct positions.
    unique: Vec<Vec3>,
    /// Triangles as indices into `unique`, three distinct each.
    triangles: Vec<[u32; 3]>,
    /// Per edge (lower id, higher id): its sides.
    edges: HashMap<(u32, u32), Vec<Side>>,
    /// The tolerance: 1e-5 of the bounding box's diagonal.
    tolerance: f32,
    /// The bounding box's lower corner.
    lo: Vec3,
}

impl Welded {
    /// Vertices within 1e-5 of the mesh's size of one another count as one (flat-shaded
    /// meshes repeat them per facet, seams repeat them rounded). None for no triangles, a
    /// degenerate box, or a triangle with two corners at one position.
    fn new(positions: &[Vec3], indices: &[u32]) -> Option<Welded> {
        if indices.is_empty() || !indices.len().is_multiple_of(3) {
            return None;
        }
        let (lo, hi) = positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| {
                (l.min(p), h.max(p))
            });
        let tolerance = 1e-5 * (hi - lo).length();
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return None;
        }
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let mut unique: Vec<Vec3> = Vec::new();
        let mut welded = Vec::with_capacity(positions.len());
        for &p in positions {
            let cell = ((p - lo) / tolerance).floor().as_i64vec3().to_array();
            let mut found = None;
            'near: for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let key = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                        if let Some(ids) = cells.get(&key) {
                            found = ids
                                .iter()
                                .copied()
                                .find(|&id| unique[id as usize].distance(p) <= tolerance);
                            if found.is_some() {
                                break 'near;
                            }
                        }
                    }
                }
            }
            let id = found.unwrap_or_else(|| {
                unique.push(p);
                let id = unique.len() as u32 - 1;
                cells.entry(cell).or_default().push(id);
                id
            });
            welded.push(id);
        }
        let triangles = indices
            .chunks_exact(3)
            .map(|t| {
                let v = [0, 1, 2].map(|k| welded.get(t[k] as usize).copied());
                match v {
                    [Some(a), Some(b), Some(c)] if a != b && b != c && a != c => Some([a, b, c]),
                    _ => None,
                }
            })
            .collect::<Option<Vec<[u32; 3]>>>()?;
        let mut edges: HashMap<(u32, u32), Vec<Side>> = HashMap::new();
        for (t, v) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b, far) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                edges
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((t, far, a < b));
            }
        }
        Some(Welded {
            unique,
            triangles,
            edges,
            tolerance,
            lo,
        })
    }

    /// Whether every edge joins exactly two triangles, in opposite directions.
    fn closed(&self) -> bool {
        self.edges
            .values()
            .all(|list| matches!(list[..], [(_, _, up0), (_, _, up1)] if up0 != up1))
    }
}

/// Whether the mesh is a closed surface, its triangles wound consistently: every edge joins
/// exactly two triangles, in opposite directions (vertices within 1e-5 of the mesh's size of
/// one another counting as one). Every ray from outside that meets such a surface enters it
/// through a triangle facing the ray and leaves through one facing away, so a silhouette is
/// drawn whole by either kind alone.
pub fn is_closed(positions: &[Vec3], indices: &[u32]) -> bool {
    Welded::new(positions, indices).is_some_and(|w| w.closed())
}

/// Whether the mesh is the closed surface of one convex body, its triangles wound
/// counter-clockwise seen from outside: every edge joins exactly two triangles, in opposite
/// directions; the triangles form one connected surface enclosing a positive volume; and
/// across every edge the far corner of each triangle lies behind the other's plane (or within
/// 1e-5 of the mesh's size in front of it: flat facets split into triangles). A closed,
/// connected surface convex at every edge bounds a convex body, so a ray leaving it outward
/// never meets it again. Vertices within that tolerance of one another count as one
/// (flat-shaded meshes repeat them per facet, seams repeat them rounded); a triangle with
/// two corners at one position makes the answer no.
pub fn is_convex(positions: &[Vec3], indices: &[u32]) -> bool {
    closed_and_convex(positions, indices).1
}

/// [`is_closed`] and [`is_convex`] of the mesh, welding its vertices once.
pub fn closed_and_convex(positions: &[Vec3], indices: &[u32]) -> (bool, bool) {
    match Welded::new(positions, indices) {
        Some(welded) if welded.closed() => (true, convex_when_closed(&welded)),
        _ => (false, false),
    }
}

/// [`is_convex`] of a welded mesh already known to be closed.
fn convex_when_closed(welded: &Welded) -> bool {
    let Welded {
        unique,
        triangles,
        edges,
        tolerance,
        lo,
    } = welded;
    let corner = |id: u32| unique[id as usize];
    let normal = |t: usize| {
        let [a, b, c] = triangles[t].map(corner);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let in_front = |t: usize, id: u32| normal(t).dot(corner(id) - corner(triangles[t][0]));
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    fn root(parent: &mut [usize], mut t: usize) -> usize {
        while parent[t] != t {
            parent[t] = parent[parent[t]];
            t = parent[t];
        }
        t
    }
    for list in edges.values() {
        let [(t0, far0, _), (t1, far1, _)] = list[..] else {
            return false;
        };
        if in_front(t0, far1) > *tolerance || in_front(t1, far0) > *tolerance {
            return false;
        }
        let (r0, r1) = (root(&mut parent, t0), root(&mut parent, t1));
        parent[r0] = r1;
    }
    let first = root(&mut parent, 0);
    let connected = (0..triangles.len()).all(|t| root(&mut parent, t) == first);
    // Six times the enclosed volume, positive when the triangles face outward.
    let volume: f32 = triangles
        .iter()
        .map(|v| {
            let [a, b, c] = v.map(corner);
            (a - *lo).dot((b - *lo).cross(c - *lo))
        })
        .sum();
    connected && volume > 0.0
}

/// The convex hull of `points`: its corners counter-clockwise (x right, y up) from the
/// lowest-leftmost one, without points on its edges. Fewer than three corners when the points
/// are fewer or collinear; empty when a coordinate is not finite. Andrew's monotone chain,
/// with the turn of each corner in f64 (exact for f32 inputs up to rounding of one product).
pub fn hull_2d(points: &[Vec2]) -> Vec<Vec2> {
    if points.iter().any(|p| !p.is_finite()) {
        return Vec::new();
    }
    let mut sorted = points.to_vec();
    sorted.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    sorted.dedup();
    if sorted.len() < 3 {
        return sorted;
    }
    // Twice the signed area of (o, a, b): positive for a left (counter-clockwise) turn.
    let turn = |o: Vec2, a: Vec2, b: Vec2| {
        let (o, a, b) = (o.as_dvec2(), a.as_dvec2(), b.as_dvec2());
        (a - o).perp_dot(b - o)
    };
    let mut hull: Vec<Vec2> = Vec::with_capacity(sorted.len() + 1);
    // Adds `p` after popping the corners it does not turn left from, keeping the first `keep`.
    let add = |hull: &mut Vec<Vec2>, p: Vec2, keep: usize| {
        while hull.len() >= keep + 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    };
    // The lower chain left to right, then the upper chain back from the rightmost point.
    for &p in &sorted {
        add(&mut hull, p, 0);
    }
    let lower = hull.len() - 1;
    for &p in sorted.iter().rev().skip(1) {
        add(&mut hull, p, lower);
    }
    // The last point is the first again.
    hull.pop();
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solid::flat_cube as cube;

    /// Twice the signed area of (o, a, b), in f64.
    fn turn(o: Vec2, a: Vec2, b: Vec2) -> f64 {
        (a.as_dvec2() - o.as_dvec2()).perp_dot(b.as_dvec2() - o.as_dvec2())
    }

    #[test]
    fn hull_of_a_square_drops_the_points_inside_and_on_its_edges() {
        let mut points = vec![
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 0.0),
            Vec2::new(1.0, 0.5),
        ];
        points.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(Vec2::from));
        points.push(Vec2::new(1.0, 1.0));
        let hull = hull_2d(&points);
        let expected = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(Vec2::from);
        assert_eq!(hull, expected);
        assert!(hull_2d(&[Vec2::ZERO, Vec2::ONE, Vec2::splat(2.0)]).len() < 3);
        assert!(hull_2d(&[Vec2::ZERO, Vec2::X, Vec2::new(f32::NAN, 1.0)]).is_empty());
    }

    proptest::proptest! {
        /// Every point lies inside or on the hull, whose corners are input points turning left
        /// at every corner.
        #[test]
        fn hull_holds_every_point_and_turns_left(
            raw in proptest::collection::vec((-1.0f32..1.0, -1.0f32..1.0), 3..200)
        ) {
            let points: Vec<Vec2> = raw.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
            let hull = hull_2d(&points);
            proptest::prop_assume!(hull.len() >= 3);
            let n = hull.len();
            for (i, &corner) in hull.iter().enumerate() {
                proptest::prop_assert!(points.contains(&corner));
                let (next, after) = (hull[(i + 1) % n], hull[(i + 2) % n]);
                proptest::prop_assert!(turn(corner, next, after) > 0.0);
                for &p in &points {
                    proptest::prop_assert!(turn(corner, next, p) >= -1e-12, "{p} outside");
                }
            }
        }
    }

    #[test]
    fn a_cube_has_six_outward_planes_and_rays_leave_it_where_geometry_says() {
        let (p, n, i) = cube(0.5);
        let planes = facet_planes(&p, &n, &i, Vec3::ZERO).expect("a convex faceted cube");
        assert_eq!(planes.len(), 6);
        for q in &planes {
            assert!((q.w - 0.5).abs() < 1e-6, "{q}");
        }
        // From the centre along a diagonal-ish direction: leaves through x = 0.5.
        let d = Vec3::new(1.0, 0.5, 0.25).normalize();
        let (t, normal) = convex_exit(&planes, Vec3::ZERO, d).unwrap();
        assert!((t * d.x - 0.5).abs() < 1e-6, "t {t}");
        assert_eq!(normal, Vec3::X);
        // From a point on the -y face going up: leaves through +y, 1 away.
        let (t, normal) = convex_exit(&planes, Vec3::new(0.1, -0.5, 0.2), Vec3::Y).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && normal == Vec3::Y, "{t} {normal}");
    }

    #[test]
    fn planes_come_in_eights_that_change_no_exit() {
        let (p, n, i) = crate::solid::flat_cube(1.0);
        let planes = facet_planes(&p, &n, &i, Vec3::ZERO).expect("a convex faceted cube");
        let padded = in_eights(planes.clone());
        assert_eq!(padded.len(), 8);
        assert_eq!(&padded[..6], &planes[..]);
        assert_eq!(in_eights(Vec::new()), vec![NO_PLANE; 8]);
        // The shader's exit: the nearest plane ahead; the padding is never ahead, and holds
        // any point inside the cube inside it.
        let exit = |planes: &[Vec4], p: Vec3, d: Vec3| {
            planes
                .iter()
                .filter(|q| q.truncate().dot(d) > 1e-7)
                .map(|q| (q.w - q.truncate().dot(p)) / q.truncate().dot(d))
                .fold(f32::INFINITY, f32::min)
        };
        let (p0, d) = (
            Vec3::new(0.1, -0.2, 0.05),
            Vec3::new(0.3, 0.5, -0.8).normalize(),
        );
        assert_eq!(exit(&padded, p0, d), exit(&planes, p0, d));
        assert!(padded[6..].iter().all(|q| q.w - q.truncate().dot(p0) > 0.0));
    }

    #[test]
    fn smooth_or_concave_meshes_have_no_facet_planes() {
        let (p, n, i) = cube(0.5);
        // Smooth normals (pointing from the centre) are not the faces'.
        let smooth: Vec<Vec3> = p.iter().map(|v| v.normalize()).collect();
        assert!(facet_planes(&p, &smooth, &i, Vec3::ZERO).is_none());
        // The -x face pushed in past the centre: the faces around it then reach outside its plane.
        let mut dented = p.clone();
        for v in dented.iter_mut().take(4) {
            v.x = 0.3;
        }
        assert!(facet_planes(&dented, &n, &i, Vec3::ZERO).is_none());
        // No mesh at all.
        assert!(facet_planes(&[], &[], &[], Vec3::ZERO).is_none());
    }

    #[test]
    fn convex_meshes_are_told_from_dented_open_split_and_inside_out_ones() {
        let (p, _, i) = cube(0.5);
        assert!(is_convex(&p, &i));
        // The -x face pushed in past the centre.
        let mut dented = p.clone();
        for v in dented.iter_mut().take(4) {
            v.x = 0.3;
        }
        assert!(!is_convex(&dented, &i));
        // One face missing: open.
        assert!(!is_convex(&p, &i[..i.len() - 6]));
        // Wound inward.
        let inward: Vec<u32> = i.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
        assert!(!is_convex(&p, &inward));
        // Two cubes side by side: each convex, together not one body.
        let mut two = p.clone();
        two.extend(p.iter().map(|v| *v + Vec3::new(2.0, 0.0, 0.0)));
        let mut both = i.clone();
        both.extend(i.iter().map(|&k| k + p.len() as u32));
        assert!(!is_convex(&two, &both));
    }

    #[test]
    fn closed_meshes_are_told_from_open_and_inconsistently_wound_ones() {
        let (p, _, i) = cube(0.5);
        assert!(is_closed(&p, &i));
        // Wound inward, or two bodies: still closed.
        let inward: Vec<u32> = i.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
        assert!(is_closed(&p, &inward));
        let mut two = p.clone();
        two.extend(p.iter().map(|v| *v + Vec3::new(2.0, 0.0, 0.0)));
        let mut both = i.clone();
        both.extend(i.iter().map(|&k| k + p.len() as u32));
        assert!(is_closed(&two, &both));
        // One triangle missing: open.
        assert!(!is_closed(&p, &i[..i.len() - 3]));
        // One triangle turned over: its edges run the same way as its neighbours'.
        let mut flipped = i.clone();
        flipped.swap(1, 2);
        assert!(!is_closed(&p, &flipped));
        // Nothing at all.
        assert!(!is_closed(&p, &[]));
        // Both answers from one weld: closed and convex, closed only, neither.
        assert_eq!(closed_and_convex(&p, &i), (true, true));
        assert_eq!(closed_and_convex(&p, &inward), (true, false));
        assert_eq!(closed_and_convex(&p, &i[..i.len() - 3]), (false, false));
    }
}
