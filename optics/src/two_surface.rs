//! Two-surface refraction on the CPU (`[object] refraction = "two-surface"`): the view ray
//! refracts in at the front surface, crosses the glass, and refracts out at the back surface;
//! where the back surface reflects it totally, the reflection is followed for a bounded number
//! of bounces before the ray is given up to the environment. The reference the GPU's
//! two-surface mode is tested against, for an analytic ball ([`Ball`]) and for any closed mesh
//! ([`MeshBody`], the caustics baker's tracer). The path's length inside gives the absorption
//! of a tinted glass ([`Passage::transmittance`]).

use glam::Vec3;

use crate::absorption::Attenuation;
use crate::optics::{fresnel_reflectance, ray_sphere, reflect, refract};
use crate::solid::bvh::Bvh;
use crate::solid::{Solid, SolidError};

/// Cosine above which a vertex normal counts as pointing away from the object's centre, so
/// that the surface around the vertex is taken as the sphere about the centre through it (twin
/// of shaders/glass.wgsl RADIAL_NORMAL_COS).
pub const RADIAL_NORMAL_COS: f32 = 0.9999;

/// Internal reflections followed at most each time a ray is inside before it is given up (a
/// brilliant sends most light out within three; a torus's ring or a goblet's wall guides some
/// light much further: at 640 x 480 in glass-sphere-real's settings 48 rather than 16 took the
/// torus's disc gap from 0.380 to 0.372 and the goblet's from 0.330 to 0.320; twin of
/// shaders/glass.wgsl MAX_INTERNAL_REFLECTIONS).
pub const MAX_INTERNAL_REFLECTIONS: u32 = 48;

/// Self-intersection offset along a ray leaving a surface point, metres.
const EPS_M: f32 = 1e-6;

/// A closed glass body a ray can enter and leave.
pub trait Body {
    /// Where a ray from outside first meets the body: the distance along the unit `dir` and
    /// the outward unit (shading) normal there.
    fn enter(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)>;
    /// Where a ray inside the body next meets its surface: the distance along the unit `dir`
    /// and the outward unit (shading) normal there.
    fn leave(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)>;
}

/// An analytic glass ball.
#[derive(Clone, Copy, Debug)]
pub struct Ball {
    /// Centre, metres (world).
    pub center_m: Vec3,
    /// Radius, metres.
    pub radius_m: f32,
}

impl Body for Ball {
    fn enter(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        let t = ray_sphere(origin_m, dir, self.center_m, self.radius_m)?;
        Some((t, (origin_m + dir * t - self.center_m).normalize()))
    }

    fn leave(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        let oc = origin_m - self.center_m;
        let b = oc.dot(dir);
        let c = oc.length_squared() - self.radius_m * self.radius_m;
        let t = -b + (b * b - c).max(0.0).sqrt();
        (t > 0.0).then(|| (t, (origin_m + dir * t - self.center_m).normalize()))
    }
}

/// A closed triangle mesh in world coordinates, with the shading normals interpolated across
/// each triangle as the rasteriser does.
pub struct MeshBody {
    /// The outward-wound solid.
    pub(crate) solid: Solid,
    /// Its bounding-volume hierarchy.
    bvh: Bvh,
}

impl MeshBody {
    /// The body of world-space `positions_m`, unit vertex `normals` (outward) and a triangle
    /// list; the mesh must enclose a volume.
    pub fn new(
        positions_m: &[Vec3],
        normals: &[Vec3],
        indices: &[u32],
    ) -> Result<Self, SolidError> {
        let solid = Solid::new(positions_m, normals, indices)?;
        let bvh = Bvh::new(&solid.triangles_m);
        Ok(MeshBody { solid, bvh })
    }

    /// The nearest surface point along a ray, with the outward shading normal interpolated
    /// across its triangle as the rasteriser interpolates it (and the glass shader's search,
    /// shaders/glass.wgsl `mesh_hit`).
    fn hit(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        let hit = self.bvh.closest(origin_m, dir, f32::INFINITY)?;
        let normals = self.solid.corner_normals[hit.triangle as usize];
        let normal = normals[0] * (1.0 - hit.u - hit.v) + normals[1] * hit.u + normals[2] * hit.v;
        Some((hit.t_m, normal.normalize()))
    }
}

impl Body for MeshBody {
    fn enter(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        self.hit(origin_m, dir)
    }

    fn leave(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        self.hit(origin_m + dir * EPS_M, dir)
            .map(|(t, n)| (t + EPS_M, n))
    }
}

/// A view ray's way through a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Passage {
    /// Where the ray enters (the front surface), metres.
    pub entry_m: Vec3,
    /// The outward normal at the entry.
    pub entry_normal: Vec3,
    /// Where the ray left the body, or where it was last inside when given up, metres.
    pub exit_m: Vec3,
    /// Unit direction after the exit (or inside, when given up).
    pub direction: Vec3,
    /// The ray left the body (else it was still reflected inside after
    /// [`MAX_INTERNAL_REFLECTIONS`] and is given up to the environment along `direction`).
    pub escaped: bool,
    /// Total internal reflections on the way.
    pub internal_reflections: u32,
    /// Times the ray entered the body: 1, more where it left a body that is not convex and met
    /// it again ([`MAX_ENTRIES`] at most).
    pub entries: u32,
    /// Fraction of the light that follows this path: (1 - F) at the entry and at the exit,
    /// exact Fresnel for unpolarised light (total internal reflection loses nothing).
    pub transmission: f32,
    /// Length of the path inside the glass, metres (for Beer-Lambert absorption): the sum of
    /// its segments, internal reflections included.
    pub inside_m: f32,
}

impl Passage {
    /// Fraction of each linear RGB channel that follows this path through glass of
    /// `attenuation`: both interfaces' Fresnel transmission times the Beer-Lambert
    /// transmittance of the path inside, `color^(inside_m / distance_m)`.
    pub fn transmittance(&self, attenuation: &Attenuation) -> Vec3 {
        self.transmission * attenuation.transmittance(self.inside_m)
    }
}

/// Entries into the body along one path at most (the first included): out of a body that is
/// not convex, a ray may meet it again (through a torus's hole, past a goblet's cup into its
/// stem) and is followed in there; after the last, it goes on as if the body were not there
/// (twin of shaders/glass.wgsl MAX_ENTRIES).
pub const MAX_ENTRIES: u32 = 4;

/// Traces the unit view ray `dir` from `origin_m` through `body` of relative index `ior`:
/// refraction in (Snell), then at each meeting with the surface from inside either refraction
/// out or, beyond the critical angle, total internal reflection, at most
/// `max_internal_reflections` times each time inside; out of the body, into it again where the
/// ray meets it again, up to [`MAX_ENTRIES`] entries. `None` when the ray misses the body.
pub fn pass_through(
    body: &impl Body,
    origin_m: Vec3,
    dir: Vec3,
    ior: f32,
    max_internal_reflections: u32,
) -> Option<Passage> {
    let (t, entry_normal) = body.enter(origin_m, dir)?;
    let entry_m = origin_m + dir * t;
    let mut passage = Passage {
        entry_m,
        entry_normal,
        exit_m: entry_m,
        direction: dir,
        escaped: false,
        internal_reflections: 0,
        entries: 0,
        transmission: 1.0,
        inside_m: 0.0,
    };
    let mut normal = entry_normal;
    for entries in 1..=MAX_ENTRIES {
        passage.entries = entries;
        // A shading normal can face away from a grazing ray: refract about the side it meets.
        let facing = if passage.direction.dot(normal) < 0.0 {
            normal
        } else {
            -normal
        };
        let cos_in = -passage.direction.dot(facing);
        passage.transmission *= 1.0 - fresnel_reflectance(cos_in, 1.0 / ior);
        passage.direction =
            refract(passage.direction, facing, 1.0 / ior).unwrap_or(passage.direction);
        passage.escaped = false;
        to_the_outside(body, &mut passage, ior, max_internal_reflections);
        if !passage.escaped || entries == MAX_ENTRIES {
            break;
        }
        let from = passage.exit_m + passage.direction * EPS_M;
        let Some((t, again)) = body.enter(from, passage.direction) else {
            break;
        };
        passage.exit_m = from + passage.direction * t;
        normal = again;
    }
    Some(passage)
}

/// The light of `passage`, inside `body` at `passage.exit_m` going `passage.direction`, followed
/// to where it leaves (`escaped`, the direction after) or is given up inside after
/// `max_internal_reflections` total internal reflections.
fn to_the_outside(
    body: &impl Body,
    passage: &mut Passage,
    ior: f32,
    max_internal_reflections: u32,
) {
    let mut reflections = 0;
    loop {
        let inside = passage.direction;
        let Some((t, normal)) = body.leave(passage.exit_m, inside) else {
            // Out of the body already, meeting nothing (a grazing entry, or shading normals
            // that bend a ray out through the surface): the light is lost, as in the physical
            // reference.
            passage.transmission = 0.0;
            passage.escaped = true;
            return;
        };
        passage.exit_m += inside * t;
        passage.inside_m += t;
        // The outward normal faces the outside; the ray meets it from inside.
        let facing = if inside.dot(normal) > 0.0 {
            -normal
        } else {
            normal
        };
        let cos_out = -inside.dot(facing);
        match refract(inside, facing, ior) {
            Some(out) => {
                passage.transmission *= 1.0 - fresnel_reflectance(cos_out, ior);
                passage.direction = out;
                passage.escaped = true;
                return;
            }
            None => {
                passage.direction = reflect(inside, facing).normalize();
                if reflections == max_internal_reflections {
                    return;
                }
                reflections += 1;
                passage.internal_reflections += 1;
            }
        }
    }
}

/// Effective focal length of a ball lens of radius `radius_m` and index `ior`, measured from
/// its centre (both principal planes pass through the centre): f = n R / (2 (n - 1)).
pub fn ball_focal_length_m(radius_m: f32, ior: f32) -> f32 {
    ior * radius_m / (2.0 * (ior - 1.0))
}

/// Thick-lens image of a point `object_m` metres from a ball lens's centre (on one side) for
/// paraxial rays: the distance of the image from the centre on the other side,
/// s' = f s / (s - f) (negative: a virtual image on the object's side), and the lateral
/// magnification -s' / s (negative: inverted).
pub fn ball_image(object_m: f32, radius_m: f32, ior: f32) -> (f32, f32) {
    let f = ball_focal_length_m(radius_m, ior);
    let image = f * object_m / (object_m - f);
    (image, -image / object_m)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    const GLASS: f32 = 1.51;
    const DIAMOND: f32 = 2.42;

    fn ball() -> Ball {
        Ball {
            center_m: Vec3::new(0.0, 0.0, -0.2),
            radius_m: 0.075,
        }
    }

    /// A cube of side 2 `half` about the origin with flat normals.
    fn cube(half: f32) -> MeshBody {
        let (p, n, idx) = crate::solid::flat_cube(half);
        MeshBody::new(&p, &n, &idx).expect("a closed cube")
    }

    /// A finely tessellated sphere mesh of `ball()` (smooth normals).
    pub(crate) fn sphere_mesh(ball: &Ball, segments: u32, rings: u32) -> MeshBody {
        let mut p = Vec::new();
        let mut n = Vec::new();
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                let d = Vec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    theta.sin() * phi.cos(),
                );
                p.push(ball.center_m + d * ball.radius_m);
                n.push(d);
            }
        }
        let mut idx = Vec::new();
        let row = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let a = r * row + s;
                let (b, c, d) = (a + row, a + row + 1, a + 1);
                idx.extend([a, b, c, a, c, d]);
            }
        }
        MeshBody::new(&p, &n, &idx).expect("a closed sphere")
    }

    /// Sine of the angle between a unit direction and a unit normal.
    fn sin_between(d: Vec3, n: Vec3) -> f32 {
        d.cross(n).length()
    }

    proptest! {
        #[test]
        fn both_refractions_obey_snell_for_random_rays(
            x in -0.07f32..0.07, y in -0.07f32..0.07, ior in 1.2f32..1.9,
        ) {
            let b = ball();
            let dir = (Vec3::new(x, y, -0.2) - Vec3::new(0.01, -0.02, 0.0)).normalize();
            let origin = Vec3::new(0.01, -0.02, 0.0);
            let Some(p) = pass_through(&b, origin, dir, ior, MAX_INTERNAL_REFLECTIONS) else {
                return Ok(());
            };
            // A ball never reflects totally inside: the chord meets both surfaces at one angle.
            prop_assert!(p.escaped);
            prop_assert_eq!(p.internal_reflections, 0);
            let n_in = (p.entry_m - b.center_m).normalize();
            let n_out = (p.exit_m - b.center_m).normalize();
            let inside = (p.exit_m - p.entry_m).normalize();
            prop_assert!((sin_between(dir, n_in) - ior * sin_between(inside, n_in)).abs() < 1e-4);
            prop_assert!(
                (ior * sin_between(inside, n_out) - sin_between(p.direction, n_out)).abs() < 1e-4
            );
            // All in the plane of incidence: the ray, the two normals and both directions.
            let plane = dir.cross(n_in);
            if plane.length() > 1e-3 {
                let plane = plane.normalize();
                prop_assert!(inside.dot(plane).abs() < 1e-4);
                prop_assert!(p.direction.dot(plane).abs() < 1e-4);
            }
            prop_assert!(p.transmission > 0.0 && p.transmission < 1.0);
            prop_assert!((p.inside_m - p.entry_m.distance(p.exit_m)).abs() < 1e-6);
        }
    }

    #[test]
    fn normal_incidence_passes_straight_through_losing_two_reflections() {
        let b = ball();
        let p = pass_through(&b, Vec3::ZERO, Vec3::NEG_Z, GLASS, 4).unwrap();
        assert!(p.direction.abs_diff_eq(Vec3::NEG_Z, 1e-6));
        assert!(p.exit_m.abs_diff_eq(Vec3::new(0.0, 0.0, -0.275), 1e-6));
        let r = ((GLASS - 1.0) / (GLASS + 1.0)).powi(2);
        assert!((p.transmission - (1.0 - r) * (1.0 - r)).abs() < 1e-5);
    }

    /// Where paraxial rays from an axial point `s` metres behind the ball converge in front of
    /// it, measured from the centre (the crossing of a ray at height h with the axis).
    fn traced_image(b: &Ball, s: f32, h: f32, ior: f32) -> f32 {
        let source = b.center_m + Vec3::new(0.0, 0.0, -s);
        let aim = b.center_m + Vec3::new(0.0, h, 0.0);
        let dir = (aim - source).normalize();
        let p = pass_through(b, source, dir, ior, 4).unwrap();
        // Axis crossing: y + t dy = 0.
        let t = -p.exit_m.y / p.direction.y;
        (p.exit_m + p.direction * t).z - b.center_m.z
    }

    #[test]
    fn a_ball_lens_images_a_point_where_the_thick_lens_formula_says() {
        let b = ball();
        let f = ball_focal_length_m(b.radius_m, GLASS);
        assert!((f - 0.1110).abs() < 1e-3, "{f}");
        for s in [0.2f32, 0.3, 1.0] {
            let (expected, m) = ball_image(s, b.radius_m, GLASS);
            // Paraxial: a ray at 0.2 % of the radius.
            let traced = traced_image(&b, s, 1.5e-4, GLASS);
            assert!(
                (traced - expected).abs() < 2e-3 * expected,
                "s {s}: traced image {traced} m, thick lens {expected} m"
            );
            // Beyond the focal length the image is real and inverted; beyond 2f also shrunk.
            assert!(m < 0.0);
            assert_eq!(m.abs() < 1.0, s > 2.0 * f, "s {s}: magnification {m}");
        }
    }

    #[test]
    fn a_distant_point_beyond_the_focal_length_appears_inverted_and_shrunk() {
        // Chief ray through the centre from a point h above the axis at s; the image point is
        // where a second (marginal) ray from the same point crosses it.
        let b = ball();
        let (s, h) = (1.0f32, 0.05f32);
        let source = b.center_m + Vec3::new(0.0, h, -s);
        let trace = |aim_y: f32| {
            let dir = (b.center_m + Vec3::new(0.0, aim_y, 0.0) - source).normalize();
            pass_through(&b, source, dir, GLASS, 4).unwrap()
        };
        let chief = trace(0.0);
        let marginal = trace(2e-3);
        // Intersect the two exit rays in the y-z plane.
        let (p, d, q, e) = (
            chief.exit_m,
            chief.direction,
            marginal.exit_m,
            marginal.direction,
        );
        let denom = d.y * e.z - d.z * e.y;
        let t = ((q.y - p.y) * e.z - (q.z - p.z) * e.y) / denom;
        let image = p + d * t;
        let (s_img, m) = ball_image(s, b.radius_m, GLASS);
        assert!(
            ((image.z - b.center_m.z) - s_img).abs() < 0.01 * s_img,
            "image at {image}, thick lens {s_img} m from the centre"
        );
        assert!(
            (image.y / h - m).abs() < 0.02,
            "magnification {} vs {m}",
            image.y / h
        );
        assert!(image.y < 0.0 && image.y.abs() < h);
    }

    #[test]
    fn a_fine_sphere_mesh_passes_rays_like_the_ball() {
        let b = ball();
        let mesh = sphere_mesh(&b, 256, 128);
        for (x, y) in [(0.0f32, 0.0f32), (0.03, 0.01), (-0.05, 0.04), (0.06, -0.03)] {
            let dir = Vec3::new(x, y, -0.2).normalize();
            let exact = pass_through(&b, Vec3::ZERO, dir, GLASS, 4).unwrap();
            let traced = pass_through(&mesh, Vec3::ZERO, dir, GLASS, 4).unwrap();
            assert!(traced.escaped);
            assert!(
                traced.direction.angle_between(exact.direction) < 2e-3,
                "ray ({x}, {y}): mesh {} vs ball {}",
                traced.direction,
                exact.direction
            );
            assert!(traced.exit_m.distance(exact.exit_m) < 5e-4);
        }
    }

    #[test]
    fn total_internal_reflection_is_followed_inside_a_diamond_cube() {
        // In through the top at 60 degrees; the side face meets the ray at 69 degrees, beyond
        // the critical angle of diamond (24.4 degrees): it reflects, then leaves through the
        // bottom, mirrored in x.
        let cube = cube(0.01);
        let theta = 60f32.to_radians();
        let dir = Vec3::new(theta.sin(), -theta.cos(), 0.0);
        let origin = Vec3::new(0.008, 0.01, 0.0) - dir * 0.05;
        let p = pass_through(&cube, origin, dir, DIAMOND, 4).unwrap();
        assert!(p.escaped);
        assert_eq!(p.internal_reflections, 1);
        assert!(
            p.direction
                .abs_diff_eq(Vec3::new(-theta.sin(), -theta.cos(), 0.0), 1e-4),
            "{}",
            p.direction
        );
        assert!((p.exit_m.y + 0.01).abs() < 1e-5, "{}", p.exit_m);
        // Total internal reflection loses nothing: both refractions' losses only.
        let cos_inside = (1.0 - (theta.sin() / DIAMOND).powi(2)).sqrt();
        let expected = (1.0 - fresnel_reflectance(theta.cos(), 1.0 / DIAMOND))
            * (1.0 - fresnel_reflectance(cos_inside, DIAMOND));
        assert!((p.transmission - expected).abs() < 1e-5);
    }

    #[test]
    fn absorption_follows_the_chord_snells_law_gives_a_ray_at_each_height() {
        // A ray parallel to the axis at height h meets the surface at sin(i) = h / R and
        // crosses the ball along a chord at sin(t) = h / (n R) from the centre: length
        // 2 sqrt(R^2 - (h / n)^2), 2 R through the centre.
        let b = ball();
        let tint = Attenuation {
            color: Vec3::new(0.25, 0.5, 0.8),
            distance_m: 0.1,
        };
        for h_over_r in [0.0f32, 0.3, 0.6, 0.9] {
            let h = h_over_r * b.radius_m;
            let origin = b.center_m + Vec3::new(0.0, h, 0.5);
            let p = pass_through(&b, origin, Vec3::NEG_Z, GLASS, 4).unwrap();
            let chord = 2.0 * (b.radius_m.powi(2) - (h / GLASS).powi(2)).sqrt();
            assert!(
                (p.inside_m - chord).abs() < 1e-6,
                "h {h_over_r} R: path {} m, chord {chord} m",
                p.inside_m
            );
            let expected = Vec3::new(
                tint.color.x.powf(chord / tint.distance_m),
                tint.color.y.powf(chord / tint.distance_m),
                tint.color.z.powf(chord / tint.distance_m),
            ) * p.transmission;
            let t = p.transmittance(&tint);
            assert!(
                t.abs_diff_eq(expected, 1e-5),
                "h {h_over_r} R: {t} vs {expected}"
            );
            assert_eq!(
                p.transmittance(&Attenuation::NONE),
                Vec3::splat(p.transmission)
            );
        }
        let centre = pass_through(&b, b.center_m + Vec3::Z, Vec3::NEG_Z, GLASS, 4).unwrap();
        assert!((centre.inside_m - 2.0 * b.radius_m).abs() < 1e-6);
    }

    #[test]
    fn absorption_counts_the_path_of_internal_reflections() {
        // The diamond cube's path above: the reflection off the side keeps the vertical
        // component of the direction, so the whole path crosses the cube's height
        // 2 half at cos(t): length 2 half / cos(t), the reflected segment included.
        let half = 0.01;
        let cube = cube(half);
        let theta = 60f32.to_radians();
        let dir = Vec3::new(theta.sin(), -theta.cos(), 0.0);
        let origin = Vec3::new(0.008, 0.01, 0.0) - dir * 0.05;
        let p = pass_through(&cube, origin, dir, DIAMOND, 4).unwrap();
        assert_eq!(p.internal_reflections, 1);
        let cos_inside = (1.0 - (theta.sin() / DIAMOND).powi(2)).sqrt();
        let path = 2.0 * half / cos_inside;
        assert!((p.inside_m - path).abs() < 1e-5, "{} vs {path}", p.inside_m);
        let grey = Attenuation {
            color: Vec3::splat(0.5),
            distance_m: path,
        };
        assert!(
            p.transmittance(&grey)
                .abs_diff_eq(Vec3::splat(0.5 * p.transmission), 1e-4)
        );
    }

    #[test]
    fn a_ray_trapped_by_reflections_is_given_up_after_the_limit() {
        // The path of the test above with no reflections allowed: given up at the side face.
        let cube = cube(0.01);
        let theta = 60f32.to_radians();
        let dir = Vec3::new(theta.sin(), -theta.cos(), 0.0);
        let origin = Vec3::new(0.008, 0.01, 0.0) - dir * 0.05;
        let p = pass_through(&cube, origin, dir, DIAMOND, 0).unwrap();
        assert!(!p.escaped);
        assert_eq!(p.internal_reflections, 0);
        assert!((p.exit_m.x - 0.01).abs() < 1e-5, "{}", p.exit_m);
    }
}
