//! Where the background photo catches every ray a ball refracts towards it, in one eye's
//! image: the frame's proof that lets the glass pass leave out the environment map a ray
//! beside the photo would see (`COVERED` in shaders/glass.wgsl; `GlassPass::plan` in
//! `glass/draws.rs` draws the largest rectangles of proved tiles with that pipeline, the rest
//! of the glass with the lookup: `coverage/tiles.rs`), and the tiles the ball shows in at all
//! (`coverage/shown.rs`).
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
use vitreous_optics::camera::EyeParams;
use vitreous_optics::optics::{plane_photo_point, refract, refract_heckbert};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::solid::mesh_center;
use vitreous_optics::two_surface::RADIAL_NORMAL_COS;

use crate::scene::{MeshRef, SceneDesc};

mod shown;
mod tiles;
pub use tiles::{Split, TILES, Tiles};

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

/// The centre (the bounding box's, as the shader's `g.radial`) and radius of `mesh` (model
/// units) where it is a ball: every vertex at one distance from the centre with a normal along
/// it, so that the shader's front surface is that sphere.
pub fn ball(mesh: &MeshRef) -> Option<(Vec3, f32)> {
    let center = mesh_center(mesh.positions);
    let radius = mesh
        .positions
        .iter()
        .map(|&p| (p - center).length())
        .fold(0.0f32, f32::max);
    let ball = radius > 0.0
        && mesh.positions.len() == mesh.normals.len()
        && mesh.positions.iter().zip(mesh.normals).all(|(&p, &n)| {
            let out = p - center;
            (radius - out.length()) <= BALL_TOLERANCE * radius
                && n.dot(out) > RADIAL_NORMAL_COS * n.length() * out.length()
        });
    ball.then_some((center, radius))
}

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
        let (center, radius) = ball(&desc.mesh)?;
        Some(PhotoCoverage {
            center,
            radius,
            ior: desc.ior,
            model: desc.refraction,
            background_from_world: desc.background.world_from_plane.inverse(),
        })
    }

    /// The tiles of the image of `eye` (`extent` pixels) that the ball at `world_from_model`
    /// may show in (`shown.rs`); all of them where the transform is not a similarity.
    pub fn shown_tiles(
        &self,
        world_from_model: Mat4,
        eye: &EyeParams,
        extent: (u32, u32),
    ) -> Tiles {
        match uniform_scale(world_from_model) {
            Some(scale) => shown::shown_tiles(
                world_from_model.transform_point3(self.center),
                self.radius * scale,
                eye,
                extent,
            ),
            None => Tiles::ALL,
        }
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
    ) -> Tiles {
        let Some(scale) = uniform_scale(world_from_model) else {
            return Tiles::NONE;
        };
        let center = world_from_model.transform_point3(self.center);
        let radius = self.radius * scale;
        let position = eye.position_m;
        let to_eye = position - center;
        let distance = to_eye.length();
        let outside = distance > radius * (1.0 + 1e-4);
        if !outside || extent.0 == 0 || extent.1 == 0 {
            return Tiles::NONE;
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
        let mut tiles = Tiles::ALL;
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
                let (mut lo, mut hi) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
                for r in ring.saturating_sub(1)..=(ring + 1).min(RINGS) {
                    for s in [spoke + SPOKES - 1, spoke, spoke + 1] {
                        // A corner behind the eye: where the cells lie, is not known.
                        let Some(corner) = seen_at[at(r, s)] else {
                            return Tiles::NONE;
                        };
                        (lo, hi) = (lo.min(corner), hi.max(corner));
                    }
                }
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
        plane_photo_point(exit, direction, self.background_from_world)
    }

    /// The shader's `ball_passage` about `center`: the unit ray `incident` enters at `entry`
    /// (normal `facing` towards it), crosses the ball and leaves at its first meeting with the
    /// surface; where and along what, or `None` where rounding would reflect it inside there
    /// (the shader then sends it on straight, which the proof leaves to the pipeline with the
    /// lookup).
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
mod tests;
