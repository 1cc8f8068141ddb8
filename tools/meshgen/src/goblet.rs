//! Glass goblet (wine glass) of unit height standing on +y: a solid of revolution that is not
//! convex and not star-shaped, with an open cup, a solid stem and a foot.
//!
//! The solid is the glass itself, so its surface is one closed profile turned about the axis:
//! from the middle of the foot's underside out to the foot's edge, up the edge, in along the
//! foot's top, up the stem, out along the bowl's outside, over the rounded rim and down the
//! bowl's inside to the middle of the cup's bottom. Both ends lie on the axis, which closes the
//! surface there. Where two pieces of the profile meet at an angle (the foot's edge) the ring
//! of vertices is doubled, one copy with each side's normal; elsewhere the pieces meet with
//! one tangent and share their ring, so the shading is smooth across them.

use crate::mesh::Mesh;
use anyhow::{Result, ensure};
use glam::{DVec2, DVec3, Vec2};
use std::f64::consts::{PI, TAU};

/// The shape of the profile before it is scaled to unit height; lengths in the same units,
/// radius from the axis and height above the foot's underside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proportions {
    /// Radius of the foot disc.
    pub foot_radius: f64,
    /// Thickness of the foot at its edge.
    pub foot_thickness: f64,
    /// Radius of the stem.
    pub stem_radius: f64,
    /// Height where the foot's top has turned into the stem.
    pub stem_bottom: f64,
    /// Height where the stem flares into the bowl.
    pub stem_top: f64,
    /// Widest radius the bowl's outside is pulled towards.
    pub bowl_radius: f64,
    /// Outer radius of the rim.
    pub rim_radius: f64,
    /// Height of the outer edge of the rim, before its rounding.
    pub rim_height: f64,
    /// Thickness of the bowl's wall at the rim (the rim's rounding is half of it).
    pub wall: f64,
    /// Height of the cup's inside bottom on the axis.
    pub cup_bottom: f64,
}

impl Default for Proportions {
    fn default() -> Self {
        Proportions {
            foot_radius: 0.30,
            foot_thickness: 0.025,
            stem_radius: 0.035,
            stem_bottom: 0.16,
            stem_top: 0.40,
            bowl_radius: 0.33,
            rim_radius: 0.25,
            rim_height: 0.99,
            wall: 0.02,
            cup_bottom: 0.53,
        }
    }
}

/// Bands of triangles along the profile, per piece (foot underside, foot edge, foot top, stem,
/// bowl outside, rim, bowl inside).
const STEPS: [u32; 7] = [4, 1, 8, 3, 16, 6, 14];

/// A point of the profile: `(radius, height)`, the unit outward normal in the same plane, and
/// whether the surface continues smoothly into the next point (false across a sharp corner,
/// where the next point is the same position with the other side's normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfilePoint {
    /// `(radius, height)`.
    pub at: DVec2,
    /// Unit outward normal `(radial, vertical)`.
    pub normal: DVec2,
    /// Whether a band of triangles joins this point to the next.
    pub joined_to_next: bool,
}

/// One smooth piece of the profile: position and tangent (any length) at `t` in `[0, 1]`.
type Piece = Box<dyn Fn(f64) -> (DVec2, DVec2)>;

/// A cubic Bézier curve and its derivative.
fn bezier(p: [DVec2; 4]) -> Piece {
    Box::new(move |t| {
        let s = 1.0 - t;
        let at = p[0] * (s * s * s)
            + p[1] * (3.0 * s * s * t)
            + p[2] * (3.0 * s * t * t)
            + p[3] * (t * t * t);
        let tangent = (p[1] - p[0]) * (3.0 * s * s)
            + (p[2] - p[1]) * (6.0 * s * t)
            + (p[3] - p[2]) * (3.0 * t * t);
        (at, tangent)
    })
}

/// A straight segment.
fn line(from: DVec2, to: DVec2) -> Piece {
    Box::new(move |t| (from.lerp(to, t), to - from))
}

/// Outward normal of a profile run in the direction of `tangent`: the glass lies to the left.
fn outward(tangent: DVec2) -> DVec2 {
    DVec2::new(tangent.y, -tangent.x).normalize()
}

impl Proportions {
    /// The profile's pieces in order, each with its number of steps.
    fn pieces(&self) -> Vec<(u32, Piece)> {
        let p = *self;
        let v = DVec2::new;
        let foot_edge = v(p.foot_radius, 0.0);
        let foot_top = v(p.foot_radius, p.foot_thickness);
        let stem_bottom = v(p.stem_radius, p.stem_bottom);
        let stem_top = v(p.stem_radius, p.stem_top);
        // The bowl's outside leaves the stem vertically and leans in towards the rim (a tulip).
        let bowl = [
            stem_top,
            v(p.stem_radius, p.cup_bottom),
            v(
                p.bowl_radius,
                p.stem_top + 0.3 * (p.rim_height - p.stem_top),
            ),
            v(p.rim_radius, p.rim_height),
        ];
        let rim_up = (bowl[3] - bowl[2]).normalize();
        let rim_out = outward(rim_up);
        let rim_centre = bowl[3] - rim_out * (p.wall / 2.0);
        let inner_rim = bowl[3] - rim_out * p.wall;
        let inside = [
            inner_rim,
            inner_rim - rim_up * (0.6 * (p.rim_height - p.cup_bottom)),
            v(0.55 * p.rim_radius, p.cup_bottom),
            v(0.0, p.cup_bottom),
        ];
        let half_wall = p.wall / 2.0;
        vec![
            (STEPS[0], line(DVec2::ZERO, foot_edge)),
            (STEPS[1], line(foot_edge, foot_top)),
            (
                STEPS[2],
                bezier([
                    foot_top,
                    v(0.55 * p.foot_radius, p.foot_thickness + 0.015),
                    v(p.stem_radius, p.foot_thickness + 0.045),
                    stem_bottom,
                ]),
            ),
            (STEPS[3], line(stem_bottom, stem_top)),
            (STEPS[4], bezier(bowl)),
            (
                STEPS[5],
                Box::new(move |t: f64| {
                    let (sin, cos) = (t * PI).sin_cos();
                    let radial = rim_out * cos + rim_up * sin;
                    (
                        rim_centre + radial * half_wall,
                        rim_up * cos - rim_out * sin,
                    )
                }),
            ),
            (STEPS[6], bezier(inside)),
        ]
    }

    /// The profile as points from the middle of the foot's underside to the middle of the
    /// cup's bottom, scaled to unit height with the foot's underside at 0.
    pub fn profile(&self) -> Vec<ProfilePoint> {
        let height = self.height();
        let mut points = self.unscaled_profile();
        for p in &mut points {
            p.at /= height;
        }
        points
    }

    /// Height of the rim's top above the foot's underside, before scaling to unit height.
    pub fn height(&self) -> f64 {
        self.unscaled_profile()
            .iter()
            .map(|p| p.at.y)
            .fold(0.0, f64::max)
    }

    /// The profile in the units of the proportions.
    fn unscaled_profile(&self) -> Vec<ProfilePoint> {
        let mut points: Vec<ProfilePoint> = Vec::new();
        for (steps, piece) in self.pieces() {
            for k in 0..=steps {
                let (at, tangent) = piece(f64::from(k) / f64::from(steps));
                let normal = outward(tangent);
                if k == 0
                    && let Some(last) = points.last_mut()
                {
                    if last.normal.dot(normal) > 1.0 - 1e-9 {
                        continue; // the pieces meet with one tangent: share the ring
                    }
                    last.joined_to_next = false;
                }
                points.push(ProfilePoint {
                    at,
                    normal,
                    joined_to_next: true,
                });
            }
        }
        if let Some(last) = points.last_mut() {
            last.joined_to_next = false;
        }
        points
    }

    /// Checks that the proportions describe a goblet whose pieces do not cross.
    fn check(&self) -> Result<()> {
        let p = self;
        ensure!(
            p.wall > 0.0 && p.foot_thickness > 0.0 && p.stem_radius > 0.0,
            "goblet wall, foot thickness and stem radius must be positive"
        );
        ensure!(
            p.stem_radius < p.rim_radius - p.wall && p.rim_radius < p.bowl_radius,
            "goblet stem radius must be less than the rim's inner radius, and the rim narrower \
             than the bowl"
        );
        ensure!(
            p.foot_thickness + 0.05 < p.stem_bottom
                && p.stem_bottom < p.stem_top
                && p.stem_top < p.cup_bottom
                && p.cup_bottom < p.rim_height,
            "goblet heights must rise: foot, stem bottom, stem top, cup bottom, rim"
        );
        ensure!(
            2.0 * p.foot_radius.max(p.bowl_radius) < p.rim_height,
            "goblet must be taller than it is wide, so that its height is the 1.0 across"
        );
        Ok(())
    }
}

/// The goblet with `segments` around its axis: unit height, centred on the origin, foot down.
/// Texture `u` runs once around +y (as on the sphere), `v` along the profile from the foot's
/// underside to the cup's bottom. The seam column is duplicated for the texture with positions
/// bit-identical to the first column, so the surface closes exactly.
pub fn mesh(proportions: &Proportions, segments: u32) -> Result<Mesh> {
    proportions.check()?;
    ensure!(
        segments >= 3,
        "goblet needs at least 3 segments, got {segments}"
    );
    let profile = proportions.profile();
    let mut arc = vec![0.0];
    for pair in profile.windows(2) {
        arc.push(arc.last().copied().unwrap_or(0.0) + pair[0].at.distance(pair[1].at));
    }
    let total_arc = arc.last().copied().unwrap_or(1.0);

    let mut mesh = Mesh::default();
    let stride = segments + 1;
    for (point, &along) in profile.iter().zip(&arc) {
        for column in 0..=segments {
            let azimuth = TAU * f64::from(column % segments) / f64::from(segments);
            let around = DVec3::new(-azimuth.cos(), 0.0, azimuth.sin());
            let position = around * point.at.x + DVec3::Y * (point.at.y - 0.5);
            let normal = around * point.normal.x + DVec3::Y * point.normal.y;
            mesh.push_vertex(
                position.as_vec3(),
                normal.normalize().as_vec3(),
                Vec2::new(
                    (f64::from(column) / f64::from(segments)) as f32,
                    (along / total_arc) as f32,
                ),
            );
        }
    }
    for (ring, pair) in profile.windows(2).enumerate() {
        if !pair[0].joined_to_next {
            continue;
        }
        let ring = ring as u32;
        for column in 0..segments {
            let a = ring * stride + column;
            let (b, c, d) = (a + 1, a + stride + 1, a + stride);
            // On the axis a ring is one point: its quads are triangles.
            if pair[0].at.x > 0.0 {
                mesh.push_triangle(a, b, c);
            }
            if pair[1].at.x > 0.0 {
                mesh.push_triangle(a, c, d);
            }
        }
    }
    Ok(mesh)
}

/// Segments around the axis used when none is given.
pub const DEFAULT_SEGMENTS: u32 = 48;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::checks::assert_closed;
    use glam::Vec3;

    fn goblet() -> Mesh {
        mesh(&Proportions::default(), DEFAULT_SEGMENTS).unwrap()
    }

    /// Distances along the ray `origin + t dir` (t > 0) at which it crosses a triangle.
    fn crossings(mesh: &Mesh, origin: Vec3, dir: Vec3) -> Vec<f32> {
        let mut hits: Vec<f32> = mesh
            .indices
            .chunks_exact(3)
            .filter_map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
                let (e1, e2) = (b - a, c - a);
                let p = dir.cross(e2);
                let det = e1.dot(p);
                if det.abs() < 1e-12 {
                    return None;
                }
                let s = origin - a;
                let u = s.dot(p) / det;
                let q = s.cross(e1);
                let v = dir.dot(q) / det;
                let t = e2.dot(q) / det;
                (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
            })
            .collect();
        hits.sort_by(f32::total_cmp);
        hits
    }

    #[test]
    fn goblet_is_a_closed_solid_the_tracers_accept() {
        let mesh = goblet();
        // The seam closes exactly: the duplicated column has the first column's positions
        // bit for bit, so a tracer that does not weld sees no crack either.
        let stride = DEFAULT_SEGMENTS as usize + 1;
        for ring in mesh.positions.chunks_exact(stride) {
            assert_eq!(ring[0].to_array(), ring[stride - 1].to_array());
        }
        assert_closed(&mesh, 1e-6);
        assert!(mesh.signed_volume() > 0.0, "wound inwards");
        let solid =
            vitreous_optics::solid::Solid::new(&mesh.positions, &mesh.normals, &mesh.indices)
                .unwrap();
        assert_eq!(solid.triangles_m.len(), mesh.triangle_count());
        // Smooth everywhere but across the foot's two sharp edges: three patches (underside,
        // edge band, everything else).
        assert_eq!(solid.patch_count, 3);
        let triangles = mesh.triangle_count();
        assert!((2000..6000).contains(&triangles), "{triangles} triangles");
    }

    #[test]
    fn goblet_has_unit_height_and_stands_on_its_foot() {
        let mesh = goblet();
        let (min, max) = mesh.bounds();
        assert!(
            (max.y - min.y - 1.0).abs() < 1e-6,
            "height {}",
            max.y - min.y
        );
        assert!((min.y + 0.5).abs() < 1e-6 && (max.y - 0.5).abs() < 1e-6);
        // Narrower than tall, so the scene's `diameter_m` is its height.
        let width = (max.x - min.x).max(max.z - min.z);
        assert!(width < 0.7, "width {width}");
        // The foot's underside is flat: at the lowest height every normal points down, but at
        // the foot's edge, where the edge band's own normals point out sideways.
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            if p.y == min.y {
                assert!(*n == Vec3::NEG_Y || n.y == 0.0, "{p}: {n}");
            }
        }
    }

    #[test]
    fn the_cup_is_hollow_and_open_at_the_top() {
        let mesh = goblet();
        let p = Proportions::default();
        let cup_bottom = (p.cup_bottom / p.height() - 0.5) as f32;
        // Straight down near the axis from above the rim: the first surface met is the cup's
        // bottom, far below the rim, then the foot's underside.
        let hits = crossings(&mesh, Vec3::new(0.003, 1.0, 0.002), Vec3::NEG_Y);
        assert_eq!(hits.len(), 2, "{hits:?}");
        let first_y = 1.0 - hits[0];
        assert!((first_y - cup_bottom).abs() < 2e-3, "enters at {first_y}");
        assert!(
            first_y < 0.5 - 0.3,
            "enters at {first_y}, near the rim's height"
        );
        assert!((1.0 - hits[1] + 0.5).abs() < 1e-5);
    }

    #[test]
    fn goblet_is_neither_convex_nor_star_shaped() {
        let mesh = goblet();
        // Across the bowl: in and out of the near wall, then of the far wall. A convex solid is
        // crossed at most twice by a line.
        let hits = crossings(&mesh, Vec3::new(-1.0, 0.3, 0.001), Vec3::X);
        assert_eq!(hits.len(), 4, "{hits:?}");
        // Not star-shaped about its centre (in the stem, below the cup): a ray from there up
        // and out leaves through the cup's bottom, then crosses the bowl's wall.
        let from_centre = crossings(&mesh, Vec3::ZERO, Vec3::new(0.5, 1.0, 0.0).normalize());
        assert!(from_centre.len() > 1, "{from_centre:?}");
    }

    #[test]
    fn normals_are_smooth_except_across_the_foots_edge() {
        let mesh = goblet();
        let stride = DEFAULT_SEGMENTS as usize + 1;
        let profile = Proportions::default().profile();
        let corners: Vec<_> = profile.iter().filter(|p| !p.joined_to_next).collect();
        // The two corners of the foot's edge, and the cup's bottom that ends the profile.
        assert_eq!(corners.len(), 3, "{corners:?}");
        for (ring, pair) in profile.windows(2).enumerate() {
            let (a, b) = (
                &mesh.normals[ring * stride],
                &mesh.normals[(ring + 1) * stride],
            );
            if pair[0].joined_to_next {
                // Neighbouring rings turn by 30 degrees at most (the rim's half turn in six).
                assert!(a.dot(*b) > 0.86, "ring {ring}: {a} {b}");
            } else {
                assert_eq!(pair[0].at, pair[1].at, "a crease is one position twice");
                assert!(a.dot(*b) < 0.5, "the foot's edge is sharp: {a} {b}");
            }
        }
        for (&p, &n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((n.length() - 1.0).abs() < 1e-5, "{p}: {n}");
        }
    }

    #[test]
    fn the_bowls_wall_keeps_its_thickness() {
        // Every point of the bowl's inside lies at least 0.75 of the rim's wall from the
        // outside (the pieces do not cross or pinch).
        let p = Proportions::default();
        let profile = p.profile();
        let wall = p.wall / p.height();
        let rim_top = profile
            .iter()
            .position(|q| q.at.y == 1.0)
            .expect("the rim's top is a ring");
        // Up to where the rim's rounding starts; from where it ends.
        let half_rim = STEPS[5] as usize / 2;
        let (outside, inside) = (
            &profile[..rim_top - half_rim],
            &profile[rim_top + half_rim..],
        );
        let segment_distance = |q: DVec2, a: DVec2, b: DVec2| {
            let t = ((q - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            q.distance(a + (b - a) * t)
        };
        let nearest = inside
            .iter()
            .map(|q| {
                outside
                    .windows(2)
                    .map(|s| segment_distance(q.at, s[0].at, s[1].at))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(nearest > 0.75 * wall, "wall {nearest} of {wall}");
    }

    #[test]
    fn goblet_rejects_crossing_proportions() {
        let thin = Proportions {
            wall: 0.0,
            ..Proportions::default()
        };
        assert!(mesh(&thin, 48).is_err());
        let sunk = Proportions {
            cup_bottom: 0.3,
            ..Proportions::default()
        };
        assert!(mesh(&sunk, 48).is_err());
        assert!(mesh(&Proportions::default(), 2).is_err());
    }
}
