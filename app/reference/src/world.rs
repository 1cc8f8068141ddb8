//! The real world the reference traces: the registered photos on their planes, the
//! environment beyond them, the point light and the glass object.

use std::f32::consts::{PI, TAU};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use vitreous_optics::absorption::Attenuation;
use vitreous_optics::solid::SolidError;
use vitreous_optics::two_surface::{Ball, Body, MeshBody};
use vitreous_scene::{Image, PixelData, Placement, RealPlane, Scene};

use crate::light_map::FloorLight;

/// Most interfaces one path meets (total internal reflections included); deeper branches carry
/// no light. A cut gem guides light through dozens of total internal reflections: at 16 the
/// diamond's light (ior 2.42) was 11 % short of what 64 finds, a goblet's 8 %; at 64 the
/// diamond's disc was still 1.1 % short of Mitsuba 3's path tracer, which agrees within 0.1 %
/// when cut at the same depth and at 256 (docs/realism.md, "Against Mitsuba 3"). The branches'
/// weight (`MIN_WEIGHT`) ends most paths long before: a ball's image is the same at 64.
pub const MAX_INTERFACES: u32 = 256;

/// Branches carrying less than this fraction of the ray's light are not followed.
pub const MIN_WEIGHT: f32 = 1e-4;

/// Offset off a surface along a ray leaving it, metres.
pub(crate) const EPS_M: f32 = 1e-6;

/// What a ray meets first among the registered photos.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PhotoHit {
    /// The floor at this photo coordinate.
    Floor(Vec2),
    /// The background at this photo coordinate.
    Background(Vec2),
}

/// A picture in linear RGB: a photo (decoded from sRGB) or an environment map.
#[derive(Clone, Debug)]
pub struct Picture {
    width: u32,
    height: u32,
    rgb: Vec<Vec3>,
}

impl Picture {
    /// A `width` x `height` picture whose texel `(x, y)` (row 0 at the top) is `texel(x, y)`.
    pub fn from_fn(width: u32, height: u32, texel: impl Fn(u32, u32) -> Vec3) -> Picture {
        let rgb = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| texel(x, y))
            .collect();
        Picture { width, height, rgb }
    }

    /// A loaded photo (sRGB, decoded to linear) or map (linear).
    pub fn of(image: &Image) -> Picture {
        let rgb = match &image.data {
            PixelData::Srgb8(bytes) => bytes
                .chunks_exact(4)
                .map(|p| {
                    Vec3::new(
                        vitreous_optics::srgb::to_linear(p[0]),
                        vitreous_optics::srgb::to_linear(p[1]),
                        vitreous_optics::srgb::to_linear(p[2]),
                    )
                })
                .collect(),
            PixelData::LinearF32(values) => values
                .chunks_exact(4)
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
        };
        Picture {
            width: image.width,
            height: image.height,
            rgb,
        }
    }

    /// Bilinear sample at `uv` (0..1 over the picture, v down); texel centres at half-integers.
    /// Outside the picture the edge texels continue, or horizontally the picture repeats when
    /// `wrap_u` (a latitude-longitude map).
    pub fn bilinear(&self, uv: Vec2, wrap_u: bool) -> Vec3 {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let column = |i: i64| {
            if wrap_u {
                i.rem_euclid(w)
            } else {
                i.clamp(0, w - 1)
            }
        };
        let at = |i: i64, j: i64| self.rgb[(j.clamp(0, h - 1) * w + column(i)) as usize];
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = at(x0, y0).lerp(at(x0 + 1, y0), fx);
        let bottom = at(x0, y0 + 1).lerp(at(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

/// A registered real plane: its photo on the unit square `[-0.5, 0.5]^2` (z = 0, local +y the
/// photo's top) of `world_from_plane`.
#[derive(Clone, Debug)]
pub struct Surface {
    world_from_plane: Mat4,
    plane_from_world: Mat4,
    photo: Picture,
}

impl Surface {
    /// The plane that `world_from_plane` maps the unit square to, showing `photo`.
    pub fn new(world_from_plane: Mat4, photo: Picture) -> Surface {
        Surface {
            world_from_plane,
            plane_from_world: world_from_plane.inverse(),
            photo,
        }
    }

    /// A scene's floor or background.
    pub fn of(plane: &RealPlane) -> Surface {
        Surface::new(plane.world_from_plane(), Picture::of(&plane.photo))
    }

    /// Maps the unit square onto the plane in the world.
    pub fn world_from_plane(&self) -> Mat4 {
        self.world_from_plane
    }

    /// Where the ray from `origin` along unit `dir` meets the photo (either side): its
    /// distance and the photo coordinate (u right, v down).
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec2)> {
        let o = self.plane_from_world.transform_point3(origin);
        let d = self.plane_from_world.transform_vector3(dir);
        if d.z.abs() < 1e-12 {
            return None;
        }
        let t = -o.z / d.z;
        let p = o + d * t;
        (t > 0.0 && p.x.abs() <= 0.5 && p.y.abs() <= 0.5)
            .then(|| (t, Vec2::new(p.x + 0.5, 0.5 - p.y)))
    }

    /// The photo's linear radiance at `uv`.
    pub fn radiance(&self, uv: Vec2) -> Vec3 {
        self.photo.bilinear(uv, false)
    }

    /// The world point of photo coordinate `uv`.
    pub fn point(&self, uv: Vec2) -> Vec3 {
        self.world_from_plane
            .transform_point3(Vec3::new(uv.x - 0.5, 0.5 - uv.y, 0.0))
    }

    /// The world unit normal of the plane's visible side (local +z).
    pub fn normal(&self) -> Vec3 {
        self.world_from_plane
            .inverse()
            .transpose()
            .transform_vector3(Vec3::Z)
            .normalize()
    }

    /// World area of one unit of photo coordinates squared (the plane's width times height).
    pub fn area_m2(&self) -> f32 {
        let x = self.world_from_plane.transform_vector3(Vec3::X);
        let y = self.world_from_plane.transform_vector3(Vec3::Y);
        x.cross(y).length()
    }
}

/// The shape of a glass object.
#[derive(Clone)]
pub enum Shape {
    /// An analytic ball (a mesh that is a ball stands for it exactly).
    Ball(Ball),
    /// A closed triangle mesh with interpolated shading normals, in world metres.
    Mesh(Arc<MeshBody>),
}

impl Body for Shape {
    fn enter(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        match self {
            Shape::Ball(b) => b.enter(origin_m, dir),
            Shape::Mesh(m) => m.enter(origin_m, dir),
        }
    }

    fn leave(&self, origin_m: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        match self {
            Shape::Ball(b) => b.leave(origin_m, dir),
            Shape::Mesh(m) => m.leave(origin_m, dir),
        }
    }
}

/// A real glass object.
#[derive(Clone)]
pub struct Glass {
    /// Its surface.
    pub shape: Shape,
    /// Refractive index relative to air.
    pub ior: f32,
    /// Absorption inside.
    pub attenuation: Attenuation,
    /// Centre of a sphere that holds it, metres.
    pub bound_center_m: Vec3,
    /// Radius of that sphere, metres.
    pub bound_radius_m: f32,
}

impl Glass {
    /// A clear or tinted glass ball.
    pub fn ball(center_m: Vec3, radius_m: f32, ior: f32, attenuation: Attenuation) -> Glass {
        Glass {
            shape: Shape::Ball(Ball { center_m, radius_m }),
            ior,
            attenuation,
            bound_center_m: center_m,
            bound_radius_m: radius_m,
        }
    }

    /// A closed mesh (world metres, outward unit vertex normals, triangle list) of glass.
    pub fn mesh(
        positions_m: &[Vec3],
        normals: &[Vec3],
        indices: &[u32],
        ior: f32,
        attenuation: Attenuation,
    ) -> Result<Glass, SolidError> {
        let body = MeshBody::new(positions_m, normals, indices)?;
        let lo = positions_m.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
        let hi = positions_m
            .iter()
            .fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
        let center = (lo + hi) * 0.5;
        let radius = positions_m
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0, f32::max);
        Ok(Glass {
            shape: Shape::Mesh(Arc::new(body)),
            ior,
            attenuation,
            bound_center_m: center,
            bound_radius_m: radius * 1.0001,
        })
    }

    /// The scene's object at `placement`: its analytic ball when the mesh is one, else its
    /// closed mesh placed in the world.
    pub fn of(scene: &Scene, placement: &Placement) -> Result<Glass, SolidError> {
        let object = &scene.object;
        if object.is_ball() {
            return Ok(Glass::ball(
                placement.object_position_m,
                object.radius_m,
                object.ior,
                object.attenuation,
            ));
        }
        let m = object.world_from_model_at(placement.object_position_m, placement.object_rotation);
        let normal_from = glam::Mat3::from_mat4(m).inverse().transpose();
        let mesh = &object.mesh;
        let positions: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| m.transform_point3(p))
            .collect();
        let normals: Vec<Vec3> = mesh
            .normals
            .iter()
            .map(|&n| (normal_from * n).normalize_or_zero())
            .collect();
        Glass::mesh(
            &positions,
            &normals,
            &mesh.indices,
            object.ior,
            object.attenuation,
        )
    }
}

/// The real world of a scene, with or without the glass object.
#[derive(Clone)]
pub struct World {
    /// The registered real floor.
    pub floor: Option<Surface>,
    /// The registered real background (the wall).
    pub background: Option<Surface>,
    /// Latitude-longitude map of what a ray leaving the glass sees where it meets neither
    /// photo (u = 0.5 down -z, v = 0 straight up); black without one.
    pub environment: Option<Picture>,
    /// The glass object; `None`: the world as the eye sees it with nothing there.
    pub glass: Option<Glass>,
    /// The point light, metres.
    pub light_m: Vec3,
    /// The share of the floor's light that comes from the point light (0..=1).
    pub light_share: f32,
    /// The floor's light from the point light with the object there ([`FloorLight::trace`]);
    /// `None`: the floor as photographed.
    pub floor_light: Option<FloorLight>,
}

impl World {
    /// The scene's world with its object at `placement` (floor light not yet traced).
    pub fn of(scene: &Scene, placement: &Placement) -> Result<World, SolidError> {
        Ok(World {
            floor: Some(Surface::of(&scene.floor)),
            background: Some(Surface::of(&scene.background)),
            environment: Some(Picture::of(&scene.environment.latlong)),
            glass: Some(Glass::of(scene, placement)?),
            light_m: placement.light_position_m,
            light_share: scene.light.share,
            floor_light: None,
        })
    }

    /// The same world with nothing placed in it: what the eye sees with nothing drawn.
    pub fn without_object(&self) -> World {
        World {
            glass: None,
            floor_light: None,
            ..self.clone()
        }
    }

    /// The nearest photo along the ray from `origin` along unit `dir`, and its distance.
    pub fn photo_hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, PhotoHit)> {
        let floor = self
            .floor
            .as_ref()
            .and_then(|f| f.hit(origin, dir))
            .map(|(t, uv)| (t, PhotoHit::Floor(uv)));
        let wall = self
            .background
            .as_ref()
            .and_then(|b| b.hit(origin, dir))
            .map(|(t, uv)| (t, PhotoHit::Background(uv)));
        match (floor, wall) {
            (Some(f), Some(w)) => Some(if f.0 <= w.0 { f } else { w }),
            (f, w) => f.or(w),
        }
    }

    /// The environment's radiance in the unit direction `dir`.
    pub fn environment_radiance(&self, dir: Vec3) -> Vec3 {
        let Some(map) = &self.environment else {
            return Vec3::ZERO;
        };
        let u = dir.x.atan2(-dir.z) / TAU + 0.5;
        let v = dir.y.clamp(-1.0, 1.0).acos() / PI;
        map.bilinear(Vec2::new(u, v), true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_sampling_interpolates_between_texel_centres() {
        let p = Picture::from_fn(2, 1, |x, _| Vec3::splat(x as f32));
        assert_eq!(p.bilinear(Vec2::new(0.25, 0.5), false), Vec3::ZERO);
        assert_eq!(p.bilinear(Vec2::new(0.75, 0.5), false), Vec3::ONE);
        assert!((p.bilinear(Vec2::new(0.5, 0.5), false).x - 0.5).abs() < 1e-6);
        // Clamped at the edge, wrapped when asked.
        assert_eq!(p.bilinear(Vec2::new(0.0, 0.5), false), Vec3::ZERO);
        assert!((p.bilinear(Vec2::new(0.0, 0.5), true).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_plane_is_hit_on_its_photo_only() {
        let s = Surface::new(
            Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0)) * Mat4::from_scale(Vec3::splat(2.0)),
            Picture::from_fn(1, 1, |_, _| Vec3::ONE),
        );
        let (t, uv) = s.hit(Vec3::ZERO, -Vec3::Z).unwrap();
        assert!((t - 2.0).abs() < 1e-6 && (uv - Vec2::splat(0.5)).length() < 1e-6);
        let (_, uv) = s.hit(Vec3::new(0.5, 0.5, 0.0), -Vec3::Z).unwrap();
        assert!((uv - Vec2::new(0.75, 0.25)).length() < 1e-6, "{uv}");
        assert!(s.hit(Vec3::new(1.1, 0.0, 0.0), -Vec3::Z).is_none());
        assert!(s.hit(Vec3::ZERO, Vec3::Z).is_none());
        assert!((s.area_m2() - 4.0).abs() < 1e-5);
        assert!((s.normal() - Vec3::Z).length() < 1e-6);
        assert!((s.point(Vec2::new(1.0, 0.0)) - Vec3::new(1.0, 1.0, -2.0)).length() < 1e-6);
    }

    #[test]
    fn the_environment_is_looked_up_as_the_renderer_maps_it() {
        // Left half of the map 0, right half 1: -z is the middle column, +x to the right.
        let world = World {
            floor: None,
            background: None,
            environment: Some(Picture::from_fn(64, 32, |x, _| {
                Vec3::splat(if x < 32 { 0.0 } else { 1.0 })
            })),
            glass: None,
            light_m: Vec3::Y,
            light_share: 1.0,
            floor_light: None,
        };
        assert_eq!(
            world.environment_radiance(Vec3::new(0.7, 0.0, -0.7).normalize()),
            Vec3::ONE
        );
        assert_eq!(
            world.environment_radiance(Vec3::new(-0.7, 0.0, -0.7).normalize()),
            Vec3::ZERO
        );
    }
}
