//! A flat bounding-volume hierarchy over the object's triangles (binned surface-area
//! heuristic), for closest-hit and all-hits ray queries.

use glam::Vec3;

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;
/// Centroid bins per axis when choosing a split.
const BINS: usize = 12;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first triangle slot; inner node: index of the left child (right = left + 1).
    first: u32,
    /// Triangle count; 0 for inner nodes.
    count: u32,
}

/// Triangle data laid out for Möller–Trumbore.
#[derive(Clone, Copy, Debug)]
struct Tri {
    p0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Index into the caller's triangle list.
    id: u32,
}

/// The nearest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter (distance for a unit direction), metres.
    pub t_m: f32,
    /// Index of the triangle in the list given to [`Bvh::new`].
    pub triangle: u32,
    /// Barycentric weight of corner 1.
    pub u: f32,
    /// Barycentric weight of corner 2.
    pub v: f32,
}

/// A bounding-volume hierarchy over a fixed triangle list.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles_m` (corner positions).
    pub fn new(triangles_m: &[[Vec3; 3]]) -> Self {
        let mut refs: Vec<(u32, Vec3, Vec3, Vec3)> = triangles_m
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let lo = t[0].min(t[1]).min(t[2]);
                let hi = t[0].max(t[1]).max(t[2]);
                (i as u32, lo, hi, (lo + hi) * 0.5)
            })
            .collect();
        let mut nodes = vec![Node {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            first: 0,
            count: 0,
        }];
        let n = refs.len();
        build(&mut nodes, 0, &mut refs, 0, n);
        let tris = refs
            .iter()
            .map(|&(i, ..)| {
                let t = triangles_m[i as usize];
                Tri {
                    p0: t[0],
                    e1: t[1] - t[0],
                    e2: t[2] - t[0],
                    id: i,
                }
            })
            .collect();
        Bvh { nodes, tris }
    }

    /// The closest intersection with `0 < t < t_max_m`, if any. `dir` need not be unit.
    pub fn closest(&self, origin: Vec3, dir: Vec3, t_max_m: f32) -> Option<Hit> {
        let inv = dir.recip();
        let mut best: Option<Hit> = None;
        let mut t_max = t_max_m;
        let mut stack = [0u32; 64];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if slab(node, origin, inv) >= t_max {
                continue;
            }
            if node.count > 0 {
                for tri in &self.tris[node.first as usize..(node.first + node.count) as usize] {
                    if let Some((t, u, v)) = intersect(tri, origin, dir)
                        && t < t_max
                    {
                        t_max = t;
                        best = Some(Hit {
                            t_m: t,
                            triangle: tri.id,
                            u,
                            v,
                        });
                    }
                }
            } else {
                let (l, r) = (node.first, node.first + 1);
                let dl = slab(&self.nodes[l as usize], origin, inv);
                let dr = slab(&self.nodes[r as usize], origin, inv);
                // Push the farther child first so the nearer one is searched first.
                let (near, far, dnear, dfar) = if dl <= dr {
                    (l, r, dl, dr)
                } else {
                    (r, l, dr, dl)
                };
                if dfar < t_max && sp < stack.len() {
                    stack[sp] = far;
                    sp += 1;
                }
                if dnear < t_max && sp < stack.len() {
                    stack[sp] = near;
                    sp += 1;
                }
            }
        }
        best
    }

    /// Number of intersections with `t > 0` along the whole ray (for inside/outside tests).
    pub fn count_hits(&self, origin: Vec3, dir: Vec3) -> usize {
        let inv = dir.recip();
        let mut hits = 0;
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            if slab(node, origin, inv) == f32::INFINITY {
                continue;
            }
            if node.count > 0 {
                hits += self.tris[node.first as usize..(node.first + node.count) as usize]
                    .iter()
                    .filter(|tri| intersect(tri, origin, dir).is_some())
                    .count();
            } else {
                stack.extend([node.first, node.first + 1]);
            }
        }
        hits
    }
}

/// One node of [`Bvh::flat`]'s hierarchy: its box, and either its left child (an inner node,
/// `count` 0; the right child follows it) or its first triangle slot and triangle count (a leaf).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatNode {
    /// The box's low corner.
    pub lo: Vec3,
    /// The box's high corner.
    pub hi: Vec3,
    /// Inner node: index of the left child; leaf: first slot in the triangle order.
    pub first: u32,
    /// Triangles of a leaf; 0 for an inner node.
    pub count: u32,
}

impl Bvh {
    /// The hierarchy as flat arrays, for a traversal elsewhere (the glass shader's,
    /// shaders/glass.wgsl `mesh_hit`): the nodes, the root first, and for each triangle slot the
    /// index of its triangle in the list given to [`Bvh::new`].
    pub fn flat(&self) -> (Vec<FlatNode>, Vec<u32>) {
        let nodes = self
            .nodes
            .iter()
            .map(|n| FlatNode {
                lo: n.lo,
                hi: n.hi,
                first: n.first,
                count: n.count,
            })
            .collect();
        (nodes, self.tris.iter().map(|t| t.id).collect())
    }

    /// Depth of the hierarchy: nodes on the longest path from the root to a leaf.
    pub fn depth(&self) -> usize {
        fn below(nodes: &[Node], at: usize) -> usize {
            let n = &nodes[at];
            // An inner node's children come after it (an empty hierarchy's root is a leaf).
            if n.count > 0 || n.first as usize <= at {
                1
            } else {
                let l = n.first as usize;
                1 + below(nodes, l).max(below(nodes, l + 1))
            }
        }
        below(&self.nodes, 0)
    }
}

/// Entry distance of the ray into the node's box, or infinity when it misses.
#[inline]
fn slab(node: &Node, origin: Vec3, inv: Vec3) -> f32 {
    let t0 = (node.lo - origin) * inv;
    let t1 = (node.hi - origin) * inv;
    let tmin = t0.min(t1).max_element().max(0.0);
    let tmax = t0.max(t1).min_element();
    // NaN (origin on a slab with a zero direction component) counts as a hit: safe.
    if tmin <= tmax || tmin.is_nan() || tmax.is_nan() {
        tmin
    } else {
        f32::INFINITY
    }
}

/// Möller–Trumbore, both sides; `(t, u, v)` for `t > 0`.
#[inline]
fn intersect(tri: &Tri, origin: Vec3, dir: Vec3) -> Option<(f32, f32, f32)> {
    let p = dir.cross(tri.e2);
    let det = tri.e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - tri.p0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(tri.e1);
    let v = dir.dot(q) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = tri.e2.dot(q) * inv_det;
    (t > 0.0).then_some((t, u, v))
}

fn area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

fn build(
    nodes: &mut Vec<Node>,
    at: usize,
    refs: &mut [(u32, Vec3, Vec3, Vec3)],
    first: usize,
    n: usize,
) {
    let items = &mut refs[first..first + n];
    let (lo, hi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), r| {
            (l.min(r.1), h.max(r.2))
        });
    nodes[at].lo = lo;
    nodes[at].hi = hi;
    let make_leaf = |nodes: &mut Vec<Node>| {
        nodes[at].first = first as u32;
        nodes[at].count = n as u32;
    };
    if n <= LEAF_SIZE {
        return make_leaf(nodes);
    }
    let (clo, chi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), r| {
            (l.min(r.3), h.max(r.3))
        });
    let extent = chi - clo;
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut bins = [(0usize, Vec3::INFINITY, Vec3::NEG_INFINITY); BINS];
        let bin_of =
            |c: f32| (((c - clo[axis]) / extent[axis] * BINS as f32) as usize).min(BINS - 1);
        for r in items.iter() {
            let b = &mut bins[bin_of(r.3[axis])];
            b.0 += 1;
            b.1 = b.1.min(r.1);
            b.2 = b.2.max(r.2);
        }
        for split in 1..BINS {
            let side = |range: &[(usize, Vec3, Vec3)]| {
                range
                    .iter()
                    .fold((0usize, Vec3::INFINITY, Vec3::NEG_INFINITY), |a, b| {
                        (a.0 + b.0, a.1.min(b.1), a.2.max(b.2))
                    })
            };
            let (nl, ll, lh) = side(&bins[..split]);
            let (nr, rl, rh) = side(&bins[split..]);
            if nl == 0 || nr == 0 {
                continue;
            }
            let cost = nl as f32 * area(ll, lh) + nr as f32 * area(rl, rh);
            if best.is_none_or(|b| cost < b.0) {
                let pos = clo[axis] + extent[axis] * split as f32 / BINS as f32;
                best = Some((cost, axis, pos));
            }
        }
    }
    let mid = match best {
        Some((_, axis, pos)) => {
            let mut i = 0;
            for j in 0..n {
                if items[j].3[axis] < pos {
                    items.swap(i, j);
                    i += 1;
                }
            }
            i
        }
        None => 0,
    };
    // All centroids in one place: split the list in half.
    let mid = if mid == 0 || mid == n { n / 2 } else { mid };
    let left = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        first: 0,
        count: 0,
    });
    nodes.push(Node {
        lo,
        hi,
        first: 0,
        count: 0,
    });
    nodes[at].first = left as u32;
    nodes[at].count = 0;
    build(nodes, left, refs, first, mid);
    build(nodes, left + 1, refs, first + mid, n - mid);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(tris: &[[Vec3; 3]], o: Vec3, d: Vec3) -> Option<(f32, u32)> {
        tris.iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let tri = Tri {
                    p0: t[0],
                    e1: t[1] - t[0],
                    e2: t[2] - t[0],
                    id: i as u32,
                };
                intersect(&tri, o, d).map(|(t, ..)| (t, i as u32))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    #[test]
    fn closest_hit_matches_brute_force() {
        // A deterministic cloud of small triangles.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let tris: Vec<[Vec3; 3]> = (0..500)
            .map(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd());
                [
                    c,
                    c + 0.1 * Vec3::new(rnd(), rnd(), rnd()),
                    c + 0.1 * Vec3::new(rnd(), rnd(), rnd()),
                ]
            })
            .collect();
        let bvh = Bvh::new(&tris);
        for _ in 0..500 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 2.0;
            let d = Vec3::new(rnd(), rnd(), rnd()).normalize();
            let got = bvh
                .closest(o, d, f32::INFINITY)
                .map(|h| (h.t_m, h.triangle));
            assert_eq!(got, brute(&tris, o, d));
        }
    }
}
