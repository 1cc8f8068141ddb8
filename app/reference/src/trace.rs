//! Radiance along a ray of the real world: the photos, the environment, and the glass, whose
//! every interface splits the light by Fresnel into a reflected and a transmitted branch.

use glam::{Vec2, Vec3};
use vitreous_optics::optics::{fresnel_reflectance, reflect, refract};
use vitreous_optics::two_surface::Body;

use crate::world::{EPS_M, Glass, MAX_INTERFACES, MIN_WEIGHT, PhotoHit, World};

impl World {
    /// Linear radiance that reaches `origin` along the unit `dir` (the eye looking along
    /// `dir`). Where the ray meets neither photo nor glass, black: the real world beyond the
    /// registered photos is not known (as in the see-through preview). Rays that left the glass
    /// see the environment map there instead.
    pub fn radiance(&self, origin: Vec3, dir: Vec3) -> Vec3 {
        self.outside(origin, dir, 1.0, 0, false)
    }

    /// The floor's radiance at photo coordinate `uv`: the photo's, with the point light's share
    /// of it scaled by the traced ratio of the light that reaches it.
    pub fn floor_radiance(&self, uv: Vec2) -> Vec3 {
        let Some(floor) = &self.floor else {
            return Vec3::ZERO;
        };
        let photo = floor.radiance(uv);
        match &self.floor_light {
            Some(light) => {
                let s = self.light_share;
                photo * ((1.0 - s) + s * light.ratio(uv))
            }
            None => photo,
        }
    }

    /// A ray in air: `weight` is the fraction of the eye's light it carries, `interfaces` the
    /// glass surfaces met so far, `left_glass` whether it has met the glass.
    fn outside(
        &self,
        origin: Vec3,
        dir: Vec3,
        weight: f32,
        interfaces: u32,
        left_glass: bool,
    ) -> Vec3 {
        let photo = self.photo_hit(origin, dir);
        if let Some(glass) = &self.glass
            && interfaces < MAX_INTERFACES
            && weight >= MIN_WEIGHT
            && let Some((t, normal)) = glass.shape.enter(origin, dir)
            && photo.is_none_or(|(t_photo, _)| t < t_photo)
        {
            return self.enter(glass, origin + dir * t, dir, normal, weight, interfaces);
        }
        match photo {
            Some((_, PhotoHit::Floor(uv))) => self.floor_radiance(uv),
            Some((_, PhotoHit::Background(uv))) => self
                .background
                .as_ref()
                .map_or(Vec3::ZERO, |b| b.radiance(uv)),
            None if left_glass => self.environment_radiance(dir),
            None => Vec3::ZERO,
        }
    }

    /// A ray from air meeting the glass at `at`, with outward normal `normal` there.
    fn enter(
        &self,
        glass: &Glass,
        at: Vec3,
        dir: Vec3,
        normal: Vec3,
        weight: f32,
        interfaces: u32,
    ) -> Vec3 {
        // A shading normal may face away from a grazing ray: split about the side it meets.
        let facing = if dir.dot(normal) < 0.0 {
            normal
        } else {
            -normal
        };
        let f = fresnel_reflectance(-dir.dot(facing), 1.0 / glass.ior);
        let reflected = self.outside(
            at + facing * EPS_M,
            reflect(dir, facing),
            weight * f,
            interfaces + 1,
            true,
        );
        let transmitted = refract(dir, facing, 1.0 / glass.ior).map_or(Vec3::ZERO, |inward| {
            self.inside(
                glass,
                at - facing * EPS_M,
                inward,
                weight * (1.0 - f),
                interfaces + 1,
            )
        });
        reflected * f + transmitted * (1.0 - f)
    }

    /// A ray inside the glass: to the surface, absorbed on the way, then split into the part
    /// that leaves and the part reflected back inside.
    fn inside(&self, glass: &Glass, origin: Vec3, dir: Vec3, weight: f32, interfaces: u32) -> Vec3 {
        if interfaces >= MAX_INTERFACES || weight < MIN_WEIGHT {
            return Vec3::ZERO;
        }
        let Some((t, normal)) = glass.shape.leave(origin, dir) else {
            return Vec3::ZERO;
        };
        let absorbed = glass.attenuation.transmittance(t);
        let at = origin + dir * t;
        // The normal facing back into the glass, the side the ray comes from.
        let facing = if dir.dot(normal) > 0.0 {
            -normal
        } else {
            normal
        };
        let f = fresnel_reflectance(-dir.dot(facing), glass.ior);
        let weight = weight * absorbed.max_element();
        let out = refract(dir, facing, glass.ior).map_or(Vec3::ZERO, |outward| {
            self.outside(
                at - facing * EPS_M,
                outward,
                weight * (1.0 - f),
                interfaces + 1,
                true,
            )
        });
        let back = self.inside(
            glass,
            at + facing * EPS_M,
            reflect(dir, facing),
            weight * f,
            interfaces + 1,
        );
        absorbed * (out * (1.0 - f) + back * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Picture, Surface};
    use glam::Mat4;
    use vitreous_optics::absorption::Attenuation;

    fn grey_world(glass: Option<Glass>) -> World {
        World {
            floor: None,
            background: None,
            environment: Some(Picture::from_fn(8, 4, |_, _| Vec3::splat(0.5))),
            glass,
            light_m: Vec3::Y,
            light_share: 1.0,
            floor_light: None,
        }
    }

    #[test]
    fn clear_glass_in_a_uniform_environment_returns_all_of_its_light() {
        // Energy is conserved: whatever the path, every branch ends in the same grey.
        let world = grey_world(Some(Glass::ball(
            Vec3::new(0.0, 0.0, -1.0),
            0.1,
            1.5,
            Attenuation::NONE,
        )));
        for x in [0.0, 0.03, 0.06, 0.09, 0.099] {
            let dir = Vec3::new(x, 0.0, -1.0).normalize();
            let l = world.radiance(Vec3::ZERO, dir);
            assert!((l.x - 0.5).abs() < 2e-3, "at {x}: {l}");
        }
        // Nothing behind the eye's ray: black.
        assert_eq!(world.radiance(Vec3::ZERO, Vec3::Z), Vec3::ZERO);
    }

    #[test]
    fn tinted_glass_absorbs_along_the_path_inside() {
        // Straight through the centre: 0.2 m of glass; Fresnel at normal incidence twice.
        let attenuation = Attenuation {
            color: Vec3::new(0.5, 1.0, 1.0),
            distance_m: 0.2,
        };
        let world = grey_world(Some(Glass::ball(
            Vec3::new(0.0, 0.0, -1.0),
            0.1,
            1.5,
            attenuation,
        )));
        let l = world.radiance(Vec3::ZERO, -Vec3::Z);
        let r = ((1.5f32 - 1.0) / (1.5 + 1.0)).powi(2);
        // Red: the straight path (0.5 of it absorbed) and the light reflected straight back.
        let straight = (1.0 - r) * (1.0 - r) * 0.5;
        assert!(
            l.x > 0.5 * (straight + r) && l.x < 0.5 * (straight + r + 0.01),
            "{l}"
        );
        assert!((l.y - 0.5).abs() < 2e-3, "{l}");
    }

    #[test]
    fn the_floor_takes_the_light_share_of_the_traced_ratio() {
        let floor = Surface::new(
            Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Picture::from_fn(1, 1, |_, _| Vec3::splat(0.4)),
        );
        let mut world = grey_world(None);
        world.floor = Some(floor);
        world.light_share = 0.25;
        let uv = Vec2::splat(0.5);
        assert_eq!(world.floor_radiance(uv), Vec3::splat(0.4));
        world.floor_light = Some(crate::light_map::FloorLight::uniform(0.0));
        // The light's quarter gone: three quarters left.
        assert!((world.floor_radiance(uv).x - 0.3).abs() < 1e-6);
    }
}
