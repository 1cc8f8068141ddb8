//! A ball's triangles in patches of its surface, each drawn only where it can show: where one
//! of its triangles faces the eye, and where its image meets the rectangle drawn. A rectangle
//! of a split (`coverage/tiles.rs`) then costs about the triangles under it rather than the
//! whole mesh: lavapipe shades every vertex and sets up every triangle of a draw whatever its
//! scissor (about 0.3 ms for the 9024-triangle sphere), and a GPU sets up every triangle too.
//!
//! The ball is convex and drawn with back faces culled, so no two drawn triangles overlap and
//! their order changes no pixel: the patches' triangles are stored one patch after another.

use std::ops::Range;
use vitreous_optics::camera::EyeParams;

use glam::{Mat4, Vec2, Vec3};

/// Patches around the ball's vertical model axis, and from pole to pole.
const LONGITUDES: usize = 16;
const LATITUDES: usize = 8;

/// The patches of a ball's mesh, and its indices reordered patch by patch.
pub struct Patches {
    patches: Vec<Patch>,
    /// The ball's centre, model frame.
    center: Vec3,
    /// The mesh's indices, each patch's triangles together, in patch order.
    pub indices: Vec<u32>,
}

/// Triangles of the ball whose centres lie in one cell of longitude and latitude about its
/// centre.
struct Patch {
    /// Its triangles' indices in [`Patches::indices`].
    indices: Range<u32>,
    /// The corners of the box about its vertices, model frame.
    corners: [Vec3; 8],
    /// The cone about `axis` (unit) that holds its triangles' outward unit normals, as the
    /// cosine of its half angle.
    axis: Vec3,
    spread_cos: f32,
    /// The least distance from the ball's centre of its triangles' planes.
    least_offset: f32,
}

impl Patches {
    /// The patches of the mesh of `positions` and triangle `indices`, a ball about `center`
    /// (model frame).
    pub fn new(positions: &[Vec3], indices: &[u32], center: Vec3) -> Patches {
        let triangles: Vec<[Vec3; 3]> = indices
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|i| positions[t[i] as usize] - center))
            .collect();
        let cell = |t: &[Vec3; 3]| {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            let longitude = (c.x.atan2(c.z) / std::f32::consts::TAU + 0.5) * LONGITUDES as f32;
            let latitude = (c.y / c.length().max(1e-20)).clamp(-1.0, 1.0).acos()
                / std::f32::consts::PI
                * LATITUDES as f32;
            let (lon, lat) = (longitude as usize, latitude as usize);
            lon.min(LONGITUDES - 1) * LATITUDES + lat.min(LATITUDES - 1)
        };
        let mut order: Vec<usize> = (0..triangles.len()).collect();
        order.sort_by_key(|&t| cell(&triangles[t]));
        let mut patches = Vec::new();
        let mut reordered = Vec::with_capacity(indices.len());
        let mut start = 0;
        while start < order.len() {
            let here = cell(&triangles[order[start]]);
            let end = start
                + order[start..]
                    .iter()
                    .take_while(|&&t| cell(&triangles[t]) == here)
                    .count();
            let members = &order[start..end];
            let first = reordered.len() as u32;
            for &t in members {
                reordered.extend_from_slice(&indices[3 * t..3 * t + 3]);
            }
            patches.push(Patch::of(
                members.iter().map(|&t| triangles[t]),
                first..reordered.len() as u32,
                center,
            ));
            start = end;
        }
        Patches {
            patches,
            center,
            indices: reordered,
        }
    }

    /// Where each patch may show in the image of `eye` (`extent` pixels), the ball at
    /// `world_from_model`: the box of pixels its image lies in, grown by a pixel for rounding
    /// (the whole image where a corner of its box is not in front of the eye); `None` where
    /// none of its triangles faces the eye.
    pub fn seen(&self, world_from_model: Mat4, eye: &EyeParams, extent: (u32, u32)) -> Seen {
        let eye_m = world_from_model.inverse().transform_point3(eye.position_m) - self.center;
        let clip_from_model = eye.clip_from_world() * world_from_model;
        let size = Vec2::new(extent.0 as f32, extent.1 as f32);
        let boxes = self
            .patches
            .iter()
            .map(|patch| {
                patch
                    .may_face(eye_m)
                    .then(|| patch.image_box(clip_from_model, size))
            })
            .collect();
        Seen { boxes }
    }

    /// The index ranges to draw for the rectangle `rect` (pixels: x, y, width, height) of an
    /// image where the patches are `seen`: those that face the eye in part and whose image
    /// meets the rectangle, neighbours in one range.
    pub fn ranges(&self, seen: &Seen, rect: [u32; 4]) -> Vec<Range<u32>> {
        let [x, y, w, h] = rect.map(|v| v as f32);
        let (lo, hi) = (Vec2::new(x, y), Vec2::new(x + w, y + h));
        let mut ranges: Vec<Range<u32>> = Vec::new();
        for (patch, image) in self.patches.iter().zip(&seen.boxes) {
            let meets = image.is_some_and(|(min, max)| min.cmple(hi).all() && max.cmpge(lo).all());
            if !meets {
                continue;
            }
            match ranges.last_mut() {
                Some(last) if last.end == patch.indices.start => last.end = patch.indices.end,
                _ => ranges.push(patch.indices.clone()),
            }
        }
        ranges
    }
}

/// Where each patch may show in one eye's image ([`Patches::seen`]).
pub struct Seen {
    boxes: Vec<Option<(Vec2, Vec2)>>,
}

impl Patch {
    /// The patch of `triangles` (vertices about the ball's centre), stored at `indices`; its
    /// box is put back about `center`.
    fn of(
        triangles: impl Iterator<Item = [Vec3; 3]> + Clone,
        indices: Range<u32>,
        center: Vec3,
    ) -> Patch {
        // Outward unit normals: the winding is not relied on, the ball's centre is inside.
        let normal = |t: &[Vec3; 3]| {
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            if n.dot(t[0] + t[1] + t[2]) < 0.0 {
                -n
            } else {
                n
            }
        };
        let axis = triangles
            .clone()
            .map(|t| normal(&t))
            .sum::<Vec3>()
            .normalize_or_zero();
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut spread_cos, mut least_offset) = (1.0f32, f32::INFINITY);
        for t in triangles {
            let n = normal(&t);
            spread_cos = spread_cos.min(n.dot(axis));
            least_offset = least_offset.min(n.dot(t[0]));
            for v in t {
                (lo, hi) = (lo.min(v), hi.max(v));
            }
        }
        let corners = std::array::from_fn(|i| {
            center + Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo)
        });
        Patch {
            indices,
            corners,
            axis,
            spread_cos,
            least_offset,
        }
    }

    /// Whether one of its triangles may face the eye at `eye_m` (model frame, about the
    /// ball's centre): a triangle of outward normal n and plane offset d faces it where
    /// n . eye > d, and over the cone of its normals n . eye is at most |eye| cos(the angle
    /// from the axis to the eye less the cone's half angle).
    fn may_face(&self, eye_m: Vec3) -> bool {
        let distance = eye_m.length();
        if self.spread_cos <= 0.0 || distance == 0.0 {
            return true;
        }
        let to_eye = (eye_m.dot(self.axis) / distance).clamp(-1.0, 1.0).acos();
        let spread = self.spread_cos.clamp(-1.0, 1.0).acos();
        let most = distance * (to_eye - spread).max(0.0).cos();
        // Room for rounding, and for the rasteriser's own test of a triangle seen edge on.
        most - self.least_offset > -1e-4 * (distance + self.least_offset.abs())
    }

    /// The box of pixels of an image of `size` that its image lies in, grown by a pixel: the
    /// box of its corners' images, or the whole plane where a corner is not in front of the
    /// eye.
    fn image_box(&self, clip_from_model: Mat4, size: Vec2) -> (Vec2, Vec2) {
        let (mut min, mut max) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
        for corner in self.corners {
            let clip = clip_from_model * corner.extend(1.0);
            if clip.w <= 1e-6 {
                return (Vec2::NEG_INFINITY, Vec2::INFINITY);
            }
            let pixel = (clip.truncate().truncate() / clip.w + 1.0) * 0.5 * size;
            (min, max) = (min.min(pixel), max.max(pixel));
        }
        (min - 1.0, max + 1.0)
    }
}

#[cfg(test)]
mod tests;
