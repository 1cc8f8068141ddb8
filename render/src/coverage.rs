//! Where the background photo catches every ray a ball refracts towards it, in one eye's
//! image: the frame's proof that lets the glass pass leave out the environment map a ray
//! beside the photo would see (`COVERED` in shaders/glass.wgsl; `GlassPass::plan` in
//! `glass/draws.rs` draws the largest rectangle of proved tiles with that pipeline, the rest
//! with the lookup).
//!
//! The ball's cap that the eye sees is sampled on rings about the axis from the eye to the
//! centre, out to the silhouette, and each sample's ray is refracted as the shader refracts it
//! (the paper's model, eq. 7-8, or both surfaces of the ball) and met with the background
//! plane. A sample fails where it lands off the photo, behind, or closer to the photo's edge
//! than `SAFETY` times its farthest neighbour's landing is from it, or, through two surfaces,
//! where the ray would be reflected inside the ball; each failing sample takes out of the
//! proof every tile of the eye's image that its four grid cells cover (the box of their
//! corners as the eye sees them, grown for the curvature of a cell). Between samples the
//! landing moves smoothly over the cap (the refracted direction saturates towards the
//! silhouette rather than turning fast), so a pixel whose cell has four passing corners lands
//! between them, on the photo. Sampled 8 times finer, no covered tile shows a ray beside the
//! photo (the tests' property, over moved heads, balls and photo sizes).
//!
//! Rays that meet the ball too grazingly to carry 1e-4 of the light are left out
//! ([`PhotoCoverage::grazing_cos`]): at the silhouette, where the samples end, and, through two
//! surfaces, also where the ray from the refraction origin grazes the ball (a thin band when
//! refraction is seen from between the eyes), whose exit is as grazing as its entry and which
//! rounding may reflect inside, on the GPU as on the CPU. The covered shader takes that share
//! of the light from the photo where the ray points.

use glam::{Mat4, Vec2, Vec3};

use crate::camera::EyeParams;
use crate::optics::{refract, refract_heckbert};
use crate::radial_map::mesh_center;
use crate::scene::{Refraction, SceneDesc};
use crate::two_surface::RADIAL_NORMAL_COS;

/// Steps from the cap's centre to its silhouette: `RINGS + 1` rings of samples, both ends
/// included.
const RINGS: usize = 24;
/// Samples per ring.
const SPOKES: usize = 48;
/// Vertices whose distance from the centre differs from the largest by more than this share
/// make the mesh something other than a ball.
const BALL_TOLERANCE: f32 = 1e-4;
/// The cosine of the incidence under which the paper's model's rays are left out: its
/// empirical Fresnel term passes under 1e-4 of the light there.
const PAPER_GRAZING_COS: f32 = 1e-5;
/// The same through two surfaces: both exact Fresnel transmissions together pass under 1e-4,
/// and the exit's radicand (the square of this) stays far above f32 rounding.
const TWO_SURFACE_GRAZING_COS: f32 = 1e-3;
/// How far inside the photo's edge a passing sample must land, in its farthest neighbour's
/// landing's distance from it: room for a cell whose landings bulge between its corners.
const SAFETY: f32 = 1.5;

/// A scene whose glass is a ball refracting towards the background photo: what the proof
/// needs of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotoCoverage {
    /// The ball's centre and radius, model units (the mesh's bounding-box centre, as the
    /// shader's `g.radial`).
    center: Vec3,
    radius: f32,
    /// Relative index of refraction.
    ior: f32,
    model: Refraction,
    /// Maps the world into the background plane's frame (its photo on the unit square).
    background_from_world: Mat4,
}

impl PhotoCoverage {
    /// The proof for `desc`, where it can be given: the object is a ball (every vertex at one
    /// distance from the centre with a normal along it, so the shader's front surface is that
    /// sphere), the refraction reaches the background photo rather than the room, and, for
    /// two-surface refraction, the pass exits the ball as a sphere (`ball_pipelines`). `None`
    /// elsewhere: the pass always keeps the lookup.
    pub fn of(desc: &SceneDesc, ball_pipelines: bool) -> Option<PhotoCoverage> {
        if desc.room || (desc.refraction == Refraction::TwoSurface && !ball_pipelines) {
            return None;
        }
        let m = desc.mesh;
        let center = mesh_center(m.positions);
        let radius = m
            .positions
            .iter()
            .map(|&p| (p - center).length())
            .fold(0.0f32, f32::max);
        let ball = radius > 0.0
            && m.positions.len() == m.normals.len()
            && m.positions.iter().zip(m.normals).all(|(&p, &n)| {
                let out = p - center;
                (radius - out.length()) <= BALL_TOLERANCE * radius
                    && n.dot(out) > RADIAL_NORMAL_COS * n.length() * out.length()
            });
        ball.then(|| PhotoCoverage {
            center,
            radius,
            ior: desc.ior,
            model: desc.refraction,
            background_from_world: desc.background.world_from_plane.inverse(),
        })
    }

    /// The tiles of the image of `eye` (`extent` pixels) where every ray the ball at
    /// `world_from_model` refracts towards the background reaches its photo, refraction seen
    /// from `origin_m` (`glass.rs` `EyePush`). None where the transform is not a similarity
    /// or the eye is inside the ball.
    pub fn covered_tiles(
        &self,
        world_from_model: Mat4,
        eye: &EyeParams,
        origin_m: Vec3,
        extent: (u32, u32),
    ) -> CoveredTiles {
        let Some(scale) = uniform_scale(world_from_model) else {
            return CoveredTiles::NONE;
        };
        let center = world_from_model.transform_point3(self.center);
        let radius = self.radius * scale;
        let position = eye.position_m;
        let to_eye = position - center;
        let distance = to_eye.length();
        let outside = distance > radius * (1.0 + 1e-4);
        if !outside || extent.0 == 0 || extent.1 == 0 {
            return CoveredTiles::NONE;
        }
        let axis = to_eye / distance;
        let (across, up) = axis.any_orthonormal_pair();
        // The cap out to where the eye's ray meets the ball at the grazing cosine:
        // cos(incidence) at cap angle a is (distance cos a - radius) / |eye - point|, falling
        // as a grows to the silhouette, acos(radius / distance).
        let cos_incidence = |a: f32| {
            let point = radius * Vec3::new(a.sin(), 0.0, a.cos());
            (distance * a.cos() - radius) / (Vec3::Z * distance - point).length()
        };
        let (mut last, mut beyond) = (0.0, (radius / distance).acos());
        for _ in 0..40 {
            let mid = 0.5 * (last + beyond);
            if cos_incidence(mid) > self.grazing_cos() {
                last = mid;
            } else {
                beyond = mid;
            }
        }
        let clip_from_world = eye.clip_from_world();
        let count = (RINGS + 1) * SPOKES;
        let (mut landings, mut seen_at) = (Vec::with_capacity(count), Vec::with_capacity(count));
        let around: [Vec3; SPOKES] = std::array::from_fn(|spoke| {
            let (sin, cos) = (std::f32::consts::TAU * spoke as f32 / SPOKES as f32).sin_cos();
            cos * across + sin * up
        });
        for ring in 0..=RINGS {
            let (sin, cos) = (last * ring as f32 / RINGS as f32).sin_cos();
            for side in around {
                let normal = cos * axis + sin * side;
                let point = center + radius * normal;
                landings.push(self.landing(center, point, normal, position, origin_m));
                let clip = clip_from_world * point.extend(1.0);
                // Where the eye's image shows the point (pixels), if in front of it.
                seen_at.push((clip.w > 0.0).then(|| {
                    let ndc = clip.truncate().truncate() / clip.w;
                    (ndc + 1.0) * 0.5 * Vec2::new(extent.0 as f32, extent.1 as f32)
                }));
            }
        }
        let at = |r: usize, s: usize| r * SPOKES + s % SPOKES;
        let mut tiles = CoveredTiles::ALL;
        for ring in 0..=RINGS {
            for spoke in 0..SPOKES {
                let here = at(ring, spoke);
                let neighbours = [
                    Some(at(ring, spoke + 1)),
                    Some(at(ring, spoke + SPOKES - 1)),
                    (ring > 0).then(|| at(ring - 1, spoke)),
                    (ring < RINGS).then(|| at(ring + 1, spoke)),
                ];
                let farthest = neighbours
                    .iter()
                    .flatten()
                    .map(|&n| match (landings[here], landings[n]) {
                        (Some(a), Some(b)) => a.distance(b),
                        _ => f32::INFINITY,
                    })
                    .fold(0.0f32, f32::max);
                let inside = landings[here].map_or(-1.0, |uv| uv.min(Vec2::ONE - uv).min_element());
                if inside >= SAFETY * farthest {
                    continue;
                }
                // The sample fails: every pixel whose point lies in one of its four cells
                // loses the proof. The cells lie within the box of their corners, grown by a
                // quarter for the image's curvature over a cell and a pixel for rounding.
                let mut corners = Vec::with_capacity(9);
                for r in ring.saturating_sub(1)..=(ring + 1).min(RINGS) {
                    for s in [spoke + SPOKES - 1, spoke, spoke + 1] {
                        corners.push(seen_at[at(r, s)]);
                    }
                }
                let Some(corners) = corners.into_iter().collect::<Option<Vec<Vec2>>>() else {
                    // Behind the eye: where, is not known.
                    return CoveredTiles::NONE;
                };
                let lo = corners.iter().fold(Vec2::INFINITY, |m, &c| m.min(c));
                let hi = corners.iter().fold(Vec2::NEG_INFINITY, |m, &c| m.max(c));
                let grow = (hi - lo) * 0.25 + 1.0;
                tiles.remove(lo - grow, hi + grow, extent);
            }
        }
        tiles
    }

    /// The cosine of the incidence under which a ray carries under 1e-4 of the light and is
    /// left out of the proof.
    pub fn grazing_cos(&self) -> f32 {
        match self.model {
            Refraction::Paper => PAPER_GRAZING_COS,
            Refraction::TwoSurface => TWO_SURFACE_GRAZING_COS,
        }
    }

    /// Where on the photo's plane (photo coordinates, the photo on the unit square) the ray
    /// through the point `point` of the ball about `center` (outward unit `normal`) lands,
    /// seen from `eye` with refraction from `origin`, as the shader's background lookup
    /// computes it; `None` where it never meets the plane or is given up inside.
    fn landing(
        &self,
        center: Vec3,
        point: Vec3,
        normal: Vec3,
        eye: Vec3,
        origin: Vec3,
    ) -> Option<Vec2> {
        let facing = if normal.dot(point - eye) > 0.0 {
            -normal
        } else {
            normal
        };
        let from_origin = (point - origin).normalize();
        let (exit, direction) = match self.model {
            Refraction::Paper => (point, refract_heckbert(from_origin, facing, self.ior)?),
            Refraction::TwoSurface => self.pass_ball(center, point, from_origin, facing)?,
        };
        plane_landing(exit, direction, self.background_from_world)
    }

    /// The covered shader's `ball_passage` about `center`: the unit ray `incident` enters at
    /// `entry` (normal `facing` towards it), crosses the ball and leaves at its first meeting
    /// with the surface; where and along what, or `None` where it would be reflected inside
    /// there (the frame then keeps the pipeline that follows it, `two_surface`).
    fn pass_ball(
        &self,
        center: Vec3,
        entry: Vec3,
        incident: Vec3,
        facing: Vec3,
    ) -> Option<(Vec3, Vec3)> {
        let p = entry - center;
        let d = refract(incident, facing, 1.0 / self.ior)?;
        // The far crossing with the sphere through p (the shader's `sphere_exit`).
        let b = p.dot(d);
        let exit = p + d * (b.abs() - b);
        let leaving = refract(d, -exit.normalize(), self.ior)?;
        Some((exit + center, leaving))
    }
}

/// Tiles per side of an eye's image in [`CoveredTiles`].
pub const TILES: u32 = 8;

/// The tiles of an eye's image ([`TILES`] x [`TILES`], tile `(col, row)` holding pixels
/// `col * width / TILES` up to the next tile's first, rows alike) whose every pixel's refracted
/// ray is proved to reach the background photo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoveredTiles(u64);

impl CoveredTiles {
    /// No tile: the whole image keeps the environment's lookup.
    pub const NONE: CoveredTiles = CoveredTiles(0);
    /// Every tile.
    pub const ALL: CoveredTiles = CoveredTiles(u64::MAX);

    /// Whether tile (`col`, `row`) is covered.
    pub fn contains(self, col: u32, row: u32) -> bool {
        self.0 & (1 << (row * TILES + col)) != 0
    }

    /// Takes out every tile that holds a pixel of the box from `lo` to `hi` (pixels) in an
    /// image of `extent`.
    fn remove(&mut self, lo: Vec2, hi: Vec2, extent: (u32, u32)) {
        let span = |lo: f32, hi: f32, size: u32| {
            (hi >= 0.0 && lo < size as f32).then(|| {
                // The tile holding pixel x: the last whose first pixel is not past it.
                let tile = |x: f32| {
                    let x = x.clamp(0.0, size as f32 - 1.0) as u32;
                    (0..TILES).rev().find(|&t| edge(t, size) <= x).unwrap_or(0)
                };
                tile(lo)..=tile(hi)
            })
        };
        let cols = span(lo.x, hi.x, extent.0);
        if let (Some(cols), Some(rows)) = (cols, span(lo.y, hi.y, extent.1)) {
            for row in rows {
                for col in cols.clone() {
                    self.0 &= !(1 << (row * TILES + col));
                }
            }
        }
    }

    /// The image of `extent` split for drawing: the largest rectangle of covered tiles (none
    /// without one), drawn without the environment's lookup, and the rest of the image around
    /// it in at most four rectangles (above, below, left, right), drawn with it; each
    /// rectangle as pixels: x, y, width, height. At most five draws, whatever the tiles.
    pub fn split(self, extent: (u32, u32)) -> ([u32; 4], Vec<[u32; 4]>) {
        // The largest rectangle of tiles, as first and end column, first and end row.
        let mut best = [0, 0, 0, 0];
        for r0 in 0..TILES {
            for c0 in 0..TILES {
                // Widest run from (c0, r0) in each row going down.
                let mut width = TILES - c0;
                for r1 in r0 + 1..=TILES {
                    let run = (c0..TILES)
                        .take_while(|&c| self.contains(c, r1 - 1))
                        .count();
                    width = width.min(run as u32);
                    let area = |b: [u32; 4]| (b[1] - b[0]) * (b[3] - b[2]);
                    if width == 0 {
                        break;
                    }
                    if width * (r1 - r0) > area(best) {
                        best = [c0, c0 + width, r0, r1];
                    }
                }
            }
        }
        let [c0, c1, r0, r1] = best;
        let (w, h) = extent;
        let (x0, x1) = (edge(c0, w), edge(c1, w));
        let (y0, y1) = (edge(r0, h), edge(r1, h));
        let rest = [
            [0, 0, w, y0],
            [0, y1, w, h - y1],
            [0, y0, x0, y1 - y0],
            [x1, y0, w - x1, y1 - y0],
        ];
        let rest = rest.into_iter().filter(|r| r[2] > 0 && r[3] > 0).collect();
        ([x0, y0, x1 - x0, y1 - y0], rest)
    }
}

/// The first pixel of tile `i` along an image side of `size` pixels.
fn edge(i: u32, size: u32) -> u32 {
    (u64::from(i) * u64::from(size) / u64::from(TILES)) as u32
}

/// Where the ray from `origin` along `direction` meets the plane that `plane_from_world` maps
/// to z = 0, in the photo's coordinates (`optics::plane_uv`'s, also off the photo); `None`
/// where it runs parallel or away.
fn plane_landing(origin: Vec3, direction: Vec3, plane_from_world: Mat4) -> Option<Vec2> {
    let o = plane_from_world.transform_point3(origin);
    let d = plane_from_world.transform_vector3(direction);
    let t = -o.z / d.z;
    (d.z.abs() >= 1e-12 && t > 0.0).then(|| {
        let hit = o + d * t;
        Vec2::new(hit.x + 0.5, 0.5 - hit.y)
    })
}

/// The uniform scale of a similarity transform; `None` for any other.
fn uniform_scale(m: Mat4) -> Option<f32> {
    let axes = [
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    ];
    let scale = axes[0].length();
    let similar = scale > 0.0
        && axes
            .iter()
            .all(|a| (a.length() - scale).abs() <= 1e-5 * scale)
        && (0..3).all(|i| axes[i].dot(axes[(i + 1) % 3]).abs() <= 1e-5 * scale * scale)
        && m.row(3) == glam::Vec4::W;
    similar.then_some(scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The visual-effects scene's glass (render/../config/scenes/visual-effects.toml): a
    /// 15 cm ball of n = 1.51 0.2 m ahead, a 0.6 m photo 0.4 m ahead.
    fn scene(model: Refraction, photo_m: f32) -> PhotoCoverage {
        let world_from_plane = Mat4::from_scale_rotation_translation(
            Vec3::new(photo_m, photo_m, 1.0),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, 0.0, -0.4),
        );
        PhotoCoverage {
            center: Vec3::ZERO,
            radius: 1.0,
            ior: 1.51,
            model,
            background_from_world: world_from_plane.inverse(),
        }
    }

    fn ball_at(position_m: Vec3) -> Mat4 {
        Mat4::from_scale_rotation_translation(Vec3::splat(0.075), glam::Quat::IDENTITY, position_m)
    }

    const IPD_M: f32 = 0.063;

    /// Two eyes at `head_m` looking down -z turned by `yaw`, seeing the scene's 40 x 30 degrees.
    fn eyes(head_m: Vec3, yaw: f32) -> [EyeParams; 2] {
        let (h, v) = (20f32.to_radians(), 15f32.to_radians());
        let fov = crate::camera::Fov {
            left_rad: -h,
            right_rad: h,
            up_rad: v,
            down_rad: -v,
        };
        let turn = glam::Quat::from_rotation_y(yaw);
        [-1.0, 1.0]
            .map(|side| EyeParams::new(head_m + turn * Vec3::X * side * IPD_M / 2.0, turn, fov))
    }

    /// Refraction seen from each eye (disparity) or from between them.
    fn origins(eyes: &[EyeParams; 2], disparity: bool) -> [Vec3; 2] {
        if disparity {
            eyes.each_ref().map(|e| e.position_m)
        } else {
            [(eyes[0].position_m + eyes[1].position_m) / 2.0; 2]
        }
    }

    /// The image size the tests prove for.
    const EXTENT: (u32, u32) = (320, 240);

    /// Each eye's covered tiles.
    fn tiles(
        coverage: &PhotoCoverage,
        world_from_model: Mat4,
        eyes: &[EyeParams; 2],
        origins: [Vec3; 2],
    ) -> [CoveredTiles; 2] {
        [0, 1].map(|i| coverage.covered_tiles(world_from_model, &eyes[i], origins[i], EXTENT))
    }

    /// The tile of each eye's image where a ray through the ball misses the photo, among the
    /// points of the cap sampled 8 times finer than the proof (but for those the proof leaves
    /// out: within `grazing_cos` of grazing): for each eye, `(col, row)` of every such tile.
    fn dense_misses(
        coverage: &PhotoCoverage,
        world_from_model: Mat4,
        eyes: &[EyeParams; 2],
        origins: [Vec3; 2],
    ) -> [Vec<(u32, u32)>; 2] {
        let center = world_from_model.transform_point3(coverage.center);
        let radius = uniform_scale(world_from_model).unwrap() * coverage.radius;
        [0, 1].map(|i| {
            let (eye, origin) = (&eyes[i], origins[i]);
            let position = eye.position_m;
            let to_eye = (position - center).normalize();
            let (across, up) = to_eye.any_orthonormal_pair();
            let (rings, spokes) = (8 * RINGS, 8 * SPOKES);
            let mut misses = Vec::new();
            for ring in 0..=rings {
                for spoke in 0..spokes {
                    let a = std::f32::consts::FRAC_PI_2 * ring as f32 / rings as f32;
                    let b = std::f32::consts::TAU * spoke as f32 / spokes as f32;
                    let normal = a.cos() * to_eye + a.sin() * (b.cos() * across + b.sin() * up);
                    let point = center + radius * normal;
                    let cos_in = (position - point).normalize().dot(normal);
                    let clip = eye.clip_from_world() * point.extend(1.0);
                    let ndc = clip.truncate().truncate() / clip.w;
                    // Two surfaces: a ray that grazes the ball from the refraction origin
                    // passes as little light as one that grazes it from the eye.
                    let cos_origin = (point - origin).normalize().dot(normal).abs();
                    let least = coverage.grazing_cos();
                    let grazing = cos_in < least
                        || (coverage.model == Refraction::TwoSurface && cos_origin < least);
                    if grazing || clip.w <= 0.0 || ndc.abs().max_element() >= 1.0 {
                        continue;
                    }
                    let on_photo = coverage
                        .landing(center, point, normal, position, origin)
                        .is_some_and(|uv| uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all());
                    if !on_photo {
                        let pixel = (ndc + 1.0) * 0.5 * Vec2::new(EXTENT.0 as f32, EXTENT.1 as f32);
                        let tile = |x: f32, size: u32| {
                            (0..TILES)
                                .rev()
                                .find(|&t| edge(t, size) as f32 <= x)
                                .unwrap_or(0)
                        };
                        let at = (tile(pixel.x, EXTENT.0), tile(pixel.y, EXTENT.1));
                        if !misses.contains(&at) {
                            misses.push(at);
                        }
                    }
                }
            }
            misses
        })
    }

    /// The first miss (eye, column, row) in a tile the proof covers, if any.
    fn covered_miss(
        tiles: &[CoveredTiles; 2],
        misses: &[Vec<(u32, u32)>; 2],
    ) -> Option<(usize, u32, u32)> {
        (0..2).find_map(|eye| {
            misses[eye]
                .iter()
                .find(|&&(col, row)| tiles[eye].contains(col, row))
                .map(|&(col, row)| (eye, col, row))
        })
    }

    #[test]
    fn the_study_scene_is_covered_from_its_viewing_position_in_the_papers_model() {
        let coverage = scene(Refraction::Paper, 0.6);
        let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
        for disparity in [false, true] {
            let eyes = eyes(Vec3::ZERO, 0.0);
            let origins = origins(&eyes, disparity);
            assert_eq!(
                tiles(&coverage, ball, &eyes, origins),
                [CoveredTiles::ALL; 2]
            );
        }
    }

    #[test]
    fn two_surfaces_bend_the_rim_beside_the_photo_in_the_corners_only() {
        let coverage = scene(Refraction::TwoSurface, 0.6);
        let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
        let eyes = eyes(Vec3::ZERO, 0.0);
        let origins = origins(&eyes, true);
        let tiles = tiles(&coverage, ball, &eyes, origins);
        let misses = dense_misses(&coverage, ball, &eyes, origins);
        assert_eq!(covered_miss(&tiles, &misses), None);
        for eye in 0..2 {
            assert!(
                !misses[eye].is_empty(),
                "eye {eye}: the rim's rays miss the photo"
            );
            // The middle of the image is proved.
            for (col, row) in [(3, 3), (4, 4), (3, 4), (4, 3)] {
                assert!(
                    tiles[eye].contains(col, row),
                    "eye {eye}: tile {col}, {row}"
                );
            }
        }
    }

    #[test]
    fn a_photo_whose_edge_shows_through_the_ball_loses_the_tiles_that_see_past_it() {
        for model in [Refraction::Paper, Refraction::TwoSurface] {
            // A 5 cm photo: most rays through the ball pass beside it.
            let coverage = scene(model, 0.05);
            let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
            let eyes = eyes(Vec3::ZERO, 0.0);
            let origins = origins(&eyes, true);
            let tiles = tiles(&coverage, ball, &eyes, origins);
            let misses = dense_misses(&coverage, ball, &eyes, origins);
            assert!(misses.iter().all(|m| m.len() > 10), "{model:?}");
            assert_eq!(covered_miss(&tiles, &misses), None, "{model:?}");
        }
    }

    #[test]
    fn no_proof_for_an_eye_inside_the_ball_or_a_stretched_ball() {
        let coverage = scene(Refraction::Paper, 0.6);
        let eyes = eyes(Vec3::ZERO, 0.0);
        let origins = origins(&eyes, true);
        let inside = ball_at(Vec3::new(0.0, 0.0, -0.05));
        assert_eq!(
            tiles(&coverage, inside, &eyes, origins),
            [CoveredTiles::NONE; 2]
        );
        let stretched = Mat4::from_scale_rotation_translation(
            Vec3::new(0.075, 0.08, 0.075),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, 0.0, -0.2),
        );
        assert_eq!(
            tiles(&coverage, stretched, &eyes, origins),
            [CoveredTiles::NONE; 2]
        );
    }

    #[test]
    fn the_rays_left_out_carry_under_1e4_of_the_light() {
        let incident = |cos: f32| Vec3::new((1.0 - cos * cos).sqrt(), 0.0, -cos);
        // The paper's model: the refracted image is weighted by 1 - F, F the empirical term.
        let paper = scene(Refraction::Paper, 0.6);
        let cos = paper.grazing_cos();
        assert!(1.0 - crate::optics::fresnel(incident(cos), Vec3::Z) < 1e-4);
        assert!(1.0 - crate::optics::fresnel(incident(cos * 10.0), Vec3::Z) > 1e-4);
        // Two surfaces: a ball's exit meets the surface as the entry did, so the light passed
        // is (1 - F)^2, F exact.
        let two = scene(Refraction::TwoSurface, 0.6);
        let passed =
            |cos: f32| (1.0 - crate::optics::fresnel_reflectance(cos, 1.0 / two.ior)).powi(2);
        assert!(
            passed(two.grazing_cos()) < 1e-4,
            "{}",
            passed(two.grazing_cos())
        );
        assert!(passed(two.grazing_cos() * 10.0) > 1e-4);
    }

    #[test]
    fn the_split_draws_each_pixel_once_and_covered_tiles_only_without_the_lookup() {
        // Covered but for the four corners and one tile inside.
        let mut tiles = CoveredTiles::ALL;
        for (col, row) in [(0, 0), (7, 0), (0, 7), (7, 7), (3, 5)] {
            tiles.0 &= !(1 << (row * TILES + col));
        }
        let extent = (101, 77);
        let (covered, rest) = tiles.split(extent);
        let mut owner = vec![0u32; (extent.0 * extent.1) as usize];
        for (rects, without) in [(vec![covered], true), (rest.clone(), false)] {
            for [x, y, w, h] in rects {
                for py in y..y + h {
                    for px in x..x + w {
                        owner[(py * extent.0 + px) as usize] += 1;
                        let col = (0..TILES).rev().find(|&t| edge(t, extent.0) <= px).unwrap();
                        let row = (0..TILES).rev().find(|&t| edge(t, extent.1) <= py).unwrap();
                        assert!(!without || tiles.contains(col, row), "{px}, {py}");
                    }
                }
            }
        }
        assert!(owner.iter().all(|&n| n == 1));
        // The largest: rows 1 to 4, all eight columns.
        assert_eq!(covered, [0, edge(1, 77), 101, edge(5, 77) - edge(1, 77)]);
        assert_eq!(rest.len(), 2);
        assert_eq!(CoveredTiles::ALL.split(extent), ([0, 0, 101, 77], vec![]));
        let (none, all) = CoveredTiles::NONE.split(extent);
        assert_eq!((none[2] * none[3], all), (0, vec![[0, 0, 101, 77]]));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Soundness: no ray of a cap sampled 8 times finer than the proof's misses the photo
        /// in a covered tile; the head, ball and photo vary far enough that tiles are lost.
        #[test]
        fn a_covered_tile_has_no_ray_beside_the_photo(
            head in prop::array::uniform3(-0.15f32..0.15),
            ball in prop::array::uniform3(-0.1f32..0.1),
            yaw in -0.5f32..0.5,
            spin in -3.0f32..3.0,
            photo_m in 0.1f32..0.8,
            two_surface in any::<bool>(),
            disparity in any::<bool>(),
        ) {
            let model = if two_surface { Refraction::TwoSurface } else { Refraction::Paper };
            let coverage = scene(model, photo_m);
            let world_from_model = ball_at(Vec3::new(ball[0], ball[1], ball[2] - 0.2))
                * Mat4::from_rotation_z(spin);
            let eyes = eyes(Vec3::from_array(head), yaw);
            let origins = origins(&eyes, disparity);
            let tiles = tiles(&coverage, world_from_model, &eyes, origins);
            let misses = dense_misses(&coverage, world_from_model, &eyes, origins);
            prop_assert_eq!(covered_miss(&tiles, &misses), None);
        }
    }
}
