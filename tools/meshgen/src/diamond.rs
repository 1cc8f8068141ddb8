//! Round brilliant cut: 57 facets plus a faceted girdle band, girdle diameter 1.0.
//!
//! Every vertex is placed on the planes it belongs to, so kites are exactly planar: the eight
//! bezels share the crown angle and the eight pavilion mains the pavilion angle, each plane
//! running through its girdle corner and level along the girdle tangent. Star and girdle
//! points sit on the bisectors between mains, where two such planes meet by symmetry.
//! The girdle is a regular 16-gon with its corners on the unit-diameter circle, one per
//! bezel/main corner and one per upper/lower girdle meeting point.

use crate::mesh::Mesh;
use anyhow::{Result, ensure};
use glam::{DVec3, Vec2};
use std::f64::consts::TAU;

/// Girdle radius: the girdle's corners lie on a circle of diameter 1.0.
pub const RADIUS: f64 = 0.5;
/// Number of bezels, stars and pavilion mains.
pub const MAINS: usize = 8;
/// Number of flat segments in the girdle band (two per main, fixed by the facet layout).
pub const GIRDLE_SEGMENTS: usize = 2 * MAINS;

/// Cut proportions, lengths as fractions of the girdle diameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proportions {
    /// Table width corner to corner of its octagon, as a fraction of the girdle diameter.
    pub table: f64,
    /// Angle between the bezel facets and the girdle plane.
    pub crown_angle_deg: f64,
    /// Angle between the pavilion mains and the girdle plane.
    pub pavilion_angle_deg: f64,
    /// Height of the girdle band, as a fraction of the girdle diameter.
    pub girdle: f64,
    /// Star length: how far the star points reach from the table edge towards the girdle
    /// (horizontal fraction along the star's axis).
    pub star: f64,
    /// Lower-girdle length: how far the lower girdle facets reach from the girdle towards the
    /// culet (horizontal fraction of the radius).
    pub lower_girdle: f64,
}

impl Default for Proportions {
    /// Tolkowsky-like ideal cut.
    fn default() -> Self {
        Proportions {
            table: 0.56,
            crown_angle_deg: 34.5,
            pavilion_angle_deg: 40.75,
            girdle: 0.02,
            star: 0.5,
            lower_girdle: 0.77,
        }
    }
}

impl Proportions {
    /// Rejects proportions that cannot make a convex round brilliant.
    pub fn validate(&self) -> Result<()> {
        let open = |name: &str, value: f64, low: f64, high: f64| {
            ensure!(
                value > low && value < high,
                "diamond {name} must lie in ({low}, {high}), got {value}"
            );
            Ok(())
        };
        open("table", self.table, 0.0, 1.0)?;
        open("crown angle (deg)", self.crown_angle_deg, 0.0, 90.0)?;
        open("pavilion angle (deg)", self.pavilion_angle_deg, 0.0, 90.0)?;
        open("girdle", self.girdle, 0.0, 1.0)?;
        open("star length", self.star, 0.0, 1.0)?;
        open("lower girdle length", self.lower_girdle, 0.0, 1.0)
    }

    /// Crown height above the girdle, as a fraction of the girdle diameter.
    pub fn crown_height(&self) -> f64 {
        (RADIUS - self.table * RADIUS) * self.crown_angle_deg.to_radians().tan() / (2.0 * RADIUS)
    }

    /// Pavilion depth below the girdle, as a fraction of the girdle diameter.
    pub fn pavilion_depth(&self) -> f64 {
        RADIUS * self.pavilion_angle_deg.to_radians().tan() / (2.0 * RADIUS)
    }

    /// Total depth, table to culet, as a fraction of the girdle diameter.
    pub fn total_depth(&self) -> f64 {
        self.crown_height() + self.girdle + self.pavilion_depth()
    }
}

/// Which family a facet belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FacetKind {
    /// The flat octagon on top.
    Table,
    /// Triangles between the table edges and the bezels.
    Star,
    /// Kite-shaped crown mains.
    Bezel,
    /// Crown triangles meeting the girdle.
    UpperGirdle,
    /// Flat segments of the vertical girdle band.
    Girdle,
    /// Pavilion triangles meeting the girdle.
    LowerGirdle,
    /// Kite-shaped pavilion mains meeting at the culet point.
    PavilionMain,
}

/// One planar facet.
#[derive(Debug, Clone, PartialEq)]
pub struct Facet {
    /// Facet family.
    pub kind: FacetKind,
    /// Corners, counter-clockwise seen from outside.
    pub corners: Vec<DVec3>,
}

/// Direction in the girdle plane at `angle_rad`, counter-clockwise about +y seen from above.
fn around(angle_rad: f64) -> DVec3 {
    DVec3::new(angle_rad.cos(), 0.0, -angle_rad.sin())
}

/// The 57 facets and the girdle band, with the bounding box centred on the origin.
pub fn facets(p: &Proportions) -> Vec<Facet> {
    let main_step = TAU / MAINS as f64;
    let half_step = main_step / 2.0;
    let (tan_crown, tan_pavilion) = (
        p.crown_angle_deg.to_radians().tan(),
        p.pavilion_angle_deg.to_radians().tan(),
    );
    let diameter = 2.0 * RADIUS;
    let half_girdle = p.girdle * diameter / 2.0;
    let table_y = half_girdle + p.crown_height() * diameter;
    let culet_y = -half_girdle - p.pavilion_depth() * diameter;
    let centre_y = (table_y + culet_y) / 2.0;
    let at = |angle: f64, radius: f64, y: f64| around(angle) * radius + DVec3::Y * (y - centre_y);
    // Height of a bezel (pavilion main) plane at distance `along` from the axis, measured along
    // the plane's own direction.
    let bezel_y = |along: f64| half_girdle + (RADIUS - along) * tan_crown;
    let main_y = |along: f64| -half_girdle - (RADIUS - along) * tan_pavilion;

    let table_radius = p.table * RADIUS;
    let table_apothem = table_radius * half_step.cos();
    let star_radius = table_apothem + p.star * (RADIUS - table_apothem);
    let lower_radius = RADIUS * (1.0 - p.lower_girdle);

    let main_angle = |i: usize| (i % MAINS) as f64 * main_step;
    let between_angle = |i: usize| main_angle(i) + half_step;
    let table = |i: usize| at(main_angle(i), table_radius, table_y);
    let star = |i: usize| {
        let along = star_radius * half_step.cos();
        at(between_angle(i), star_radius, bezel_y(along))
    };
    let lower = |i: usize| {
        let along = lower_radius * half_step.cos();
        at(between_angle(i), lower_radius, main_y(along))
    };
    let girdle_angle = |k: usize| (k % GIRDLE_SEGMENTS) as f64 * half_step;
    let girdle_top = |k: usize| at(girdle_angle(k), RADIUS, half_girdle);
    let girdle_bottom = |k: usize| at(girdle_angle(k), RADIUS, -half_girdle);
    let culet = at(0.0, 0.0, culet_y);
    let prev = |i: usize| (i + MAINS - 1) % MAINS;

    let mut facets = Vec::with_capacity(57 + GIRDLE_SEGMENTS);
    let mut add = |kind, corners: Vec<DVec3>| facets.push(Facet { kind, corners });
    add(FacetKind::Table, (0..MAINS).map(table).collect());
    for i in 0..MAINS {
        add(FacetKind::Star, vec![table(i), star(i), table(i + 1)]);
    }
    for i in 0..MAINS {
        let bezel = vec![table(i), star(prev(i)), girdle_top(2 * i), star(i)];
        add(FacetKind::Bezel, bezel);
    }
    for i in 0..MAINS {
        let (g, h, g_next) = (
            girdle_top(2 * i),
            girdle_top(2 * i + 1),
            girdle_top(2 * i + 2),
        );
        add(FacetKind::UpperGirdle, vec![star(i), g, h]);
        add(FacetKind::UpperGirdle, vec![star(i), h, g_next]);
    }
    for k in 0..GIRDLE_SEGMENTS {
        let band = vec![
            girdle_bottom(k),
            girdle_bottom(k + 1),
            girdle_top(k + 1),
            girdle_top(k),
        ];
        add(FacetKind::Girdle, band);
    }
    for i in 0..MAINS {
        let (g, h, g_next) = (
            girdle_bottom(2 * i),
            girdle_bottom(2 * i + 1),
            girdle_bottom(2 * i + 2),
        );
        add(FacetKind::LowerGirdle, vec![lower(i), h, g]);
        add(FacetKind::LowerGirdle, vec![lower(i), g_next, h]);
    }
    for i in 0..MAINS {
        let main = vec![culet, lower(i), girdle_bottom(2 * i), lower(prev(i))];
        add(FacetKind::PavilionMain, main);
    }
    facets
}

/// Flat-shaded mesh: every facet has its own vertices carrying the facet normal, and texture
/// coordinates are the top view (`u` from x, `v` from z, both 0..1 across the girdle).
pub fn mesh(p: &Proportions) -> Result<Mesh> {
    p.validate()?;
    let mut mesh = Mesh::default();
    let top_view = |c: DVec3| Vec2::new((c.x + RADIUS) as f32, (c.z + RADIUS) as f32);
    for facet in facets(p) {
        mesh.push_flat_polygon(&facet.corners, top_view);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::checks::{assert_closed, weld};
    use crate::mesh::polygon_normal;
    use std::collections::HashMap;

    fn cuts() -> Vec<Proportions> {
        let ideal = Proportions::default();
        vec![
            ideal,
            Proportions {
                table: 0.53,
                crown_angle_deg: 34.5,
                pavilion_angle_deg: 40.75,
                girdle: 0.02,
                star: 0.55,
                lower_girdle: 0.8,
            },
            Proportions {
                table: 0.6,
                crown_angle_deg: 32.0,
                pavilion_angle_deg: 42.0,
                girdle: 0.035,
                star: 0.45,
                lower_girdle: 0.75,
            },
        ]
    }

    #[test]
    fn facet_counts_match_a_round_brilliant() {
        let facets = facets(&Proportions::default());
        let mut counts: HashMap<FacetKind, usize> = HashMap::new();
        for f in &facets {
            *counts.entry(f.kind).or_default() += 1;
        }
        assert_eq!(counts[&FacetKind::Table], 1);
        assert_eq!(counts[&FacetKind::Star], 8);
        assert_eq!(counts[&FacetKind::Bezel], 8);
        assert_eq!(counts[&FacetKind::UpperGirdle], 16);
        assert_eq!(counts[&FacetKind::LowerGirdle], 16);
        assert_eq!(counts[&FacetKind::PavilionMain], 8);
        assert_eq!(counts[&FacetKind::Girdle], GIRDLE_SEGMENTS);
        assert_eq!(facets.len() - GIRDLE_SEGMENTS, 57);
    }

    #[test]
    fn every_facet_is_planar_and_faces_outwards() {
        for cut in cuts() {
            for facet in facets(&cut) {
                let normal = polygon_normal(&facet.corners);
                let origin = facet.corners[0];
                for &c in &facet.corners {
                    let off = normal.dot(c - origin);
                    assert!(off.abs() < 1e-12, "{:?} off its plane by {off}", facet.kind);
                }
                let centroid = facet.corners.iter().sum::<DVec3>() / facet.corners.len() as f64;
                assert!(normal.dot(centroid) > 0.0, "{:?} faces inwards", facet.kind);
            }
        }
    }

    #[test]
    fn diamond_is_convex() {
        for cut in cuts() {
            let facets = facets(&cut);
            for facet in &facets {
                let normal = polygon_normal(&facet.corners);
                for other in &facets {
                    for &c in &other.corners {
                        let height = normal.dot(c - facet.corners[0]);
                        assert!(
                            height < 1e-12,
                            "{:?} has a corner {height} outside",
                            facet.kind
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn diamond_mesh_is_closed_and_has_positive_volume() {
        for cut in cuts() {
            let mesh = mesh(&cut).unwrap();
            assert_closed(&mesh, 1e-5);
            assert!(mesh.signed_volume() > 0.0);
            // 57 facets + 16 girdle segments welded into one convex polyhedron:
            // Euler's formula V - E + F = 2 over facets.
            let welded = weld(&mesh, 1e-5);
            let mut unique = welded.clone();
            unique.sort_unstable();
            unique.dedup();
            let corners: usize = facets(&cut).iter().map(|f| f.corners.len()).sum();
            let (v, e, f) = (unique.len(), corners / 2, 57 + GIRDLE_SEGMENTS);
            assert_eq!(v + f, e + 2, "V {v} E {e} F {f}");
        }
    }

    #[test]
    fn diamond_normals_are_unit_flat_and_outward() {
        let mesh = mesh(&Proportions::default()).unwrap();
        assert_eq!(
            mesh.vertex_count(),
            8 + 3 * 8 + 4 * 8 + 3 * 16 + 4 * 16 + 3 * 16 + 4 * 8
        );
        assert_eq!(
            mesh.triangle_count(),
            6 + 8 + 2 * 8 + 16 + 2 * 16 + 16 + 2 * 8
        );
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            let face = (b - a).cross(c - a).normalize();
            for &k in t {
                let n = mesh.normals[k as usize];
                assert!((n.length() - 1.0).abs() < 1e-6);
                assert!(n.dot(face) > 0.9999, "normal {n} vs face {face}");
                assert!(n.dot(mesh.positions[k as usize]) > 0.0);
            }
        }
    }

    #[test]
    fn diamond_has_unit_girdle_diameter_and_centred_bounds() {
        let cut = Proportions::default();
        let mesh = mesh(&cut).unwrap();
        let (min, max) = mesh.bounds();
        assert!((max.x - min.x - 1.0).abs() < 1e-5);
        assert!((max.z - min.z - 1.0).abs() < 1e-5);
        assert!((f64::from(max.y - min.y) - cut.total_depth()).abs() < 1e-5);
        assert!((min + max).abs().max_element() < 1e-6, "bounds {min} {max}");
    }

    #[test]
    fn default_cut_has_tolkowsky_like_depths() {
        let cut = Proportions::default();
        assert!((0.14..0.17).contains(&cut.crown_height()));
        assert!((0.425..0.44).contains(&cut.pavilion_depth()));
        assert!((0.58..0.63).contains(&cut.total_depth()));
    }

    #[test]
    fn impossible_proportions_are_rejected() {
        let bad = Proportions {
            table: 1.2,
            ..Proportions::default()
        };
        assert!(mesh(&bad).is_err());
        let bad = Proportions {
            pavilion_angle_deg: 95.0,
            ..Proportions::default()
        };
        assert!(mesh(&bad).is_err());
    }
}
