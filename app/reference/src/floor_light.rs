//! The floor's light from the point light with the glass object there: its shadow and its
//! caustic, as the ratio `T` of the floor's irradiance from the light with the object to that
//! without it, traced from the light by photons.
//!
//! Photons leave the light in the cone that just holds the object's bounding sphere (the only
//! light the object can change), on a stratified grid of equal solid angle, each cell jittered.
//! Every photon is followed twice: through the world with the object (every glass interface
//! splits it by Fresnel into a reflected and a transmitted photon, both followed, absorbed along
//! its path inside) and without it (straight to the floor). Both deposit their light on a
//! texel grid over the floor around the object's shadow, each deposit shared bilinearly between
//! the four nearest texel centres, and the wall stops photons as it would light. Then
//!
//! `T = 1 + (with - without) / (E A)`
//!
//! with `E = cos(theta) / r^2` the light's irradiance at the texel's centre for a unit
//! intensity and `A` the texel's area: where the object changes nothing both deposits are the
//! same photons and `T` is exactly 1; the grid's edges and the cone's rim cancel the same way.
//! The photons of even and odd index give two independent half estimates, whose difference
//! measures the noise ([`FloorLight::noise`]).

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use vitreous_optics::optics::{fresnel_reflectance, reflect, refract};
use vitreous_optics::two_surface::Body;

use crate::light_map::FloorLight;
use crate::world::{EPS_M, Glass, MAX_INTERFACES, MIN_WEIGHT, PhotoHit, World};

/// The floor grid covers the floor under a cone this many times wider than the object's, so
/// that the light the object bends sideways lands on it.
const GRID_CONE_FACTOR: f32 = 2.5;

/// Most texels along a side of the floor grid.
pub const MAX_GRID_SIDE: u32 = 4096;

/// Fixed number of parts the photons are traced in (each on its own grid, summed in order), so
/// that the result does not depend on the number of threads.
const PARTS: usize = 16;

/// How the floor's light is traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonParams {
    /// Side of a floor texel, metres.
    pub texel_m: f32,
    /// Photons per texel of unshadowed floor under the object's cone, on average.
    pub photons_per_texel: f32,
    /// Seed of the jitter within each emission cell.
    pub seed: u64,
}

impl Default for PhotonParams {
    fn default() -> Self {
        PhotonParams {
            texel_m: 0.001,
            photons_per_texel: 64.0,
            seed: 0,
        }
    }
}

impl FloorLight {
    /// Traces the light of `world`'s point light onto its floor with its glass object there.
    /// `None` when the world has no floor or no object, or the light is inside the object's
    /// bounding sphere.
    pub fn trace(world: &World, params: &PhotonParams) -> Option<FloorLight> {
        let floor = world.floor.as_ref()?;
        let glass = world.glass.as_ref()?;
        let light = world.light_m;
        let to_object = glass.bound_center_m - light;
        let distance = to_object.length();
        let radius = glass.bound_radius_m * 1.01;
        if distance <= radius {
            return None;
        }
        let axis = to_object / distance;
        let cos_cone = (1.0 - (radius / distance).powi(2)).sqrt();
        let frame = Frame::around(axis);

        // The floor grid: the floor under a wider cone, within the photo.
        let half_angle = cos_cone.acos() * GRID_CONE_FACTOR;
        let (mut lo, mut hi) = (Vec2::splat(1.0), Vec2::splat(0.0));
        for k in 0..64 {
            let phi = k as f32 / 64.0 * TAU;
            for angle in [half_angle, half_angle * 0.5, 0.0] {
                let dir = frame.direction(angle.cos(), phi);
                match floor.hit(light, dir) {
                    Some((_, uv)) => {
                        lo = lo.min(uv);
                        hi = hi.max(uv);
                    }
                    // The cone reaches past the floor's edge or horizon: the whole photo.
                    None if angle > 0.0 => {
                        lo = Vec2::ZERO;
                        hi = Vec2::ONE;
                    }
                    None => {}
                }
            }
        }
        if hi.x <= lo.x || hi.y <= lo.y {
            return None;
        }
        let size_m = {
            let w = floor.world_from_plane();
            Vec2::new(
                w.transform_vector3(Vec3::X).length(),
                w.transform_vector3(Vec3::Y).length(),
            )
        };
        let texels = ((hi - lo) * size_m / params.texel_m)
            .ceil()
            .clamp(Vec2::ONE, Vec2::splat(MAX_GRID_SIDE as f32));
        let (width, height) = (texels.x as u32, texels.y as u32);
        let texel_uv = (hi - lo) / texels;
        let grid = Grid {
            origin_uv: lo,
            texel_uv,
            width,
            height,
        };
        let texel_area_m2 = texel_uv.x * texel_uv.y * floor.area_m2();

        // Photons: enough that the floor under the object's cone gets the asked density.
        let normal = floor.normal();
        let irradiance = |uv: Vec2| {
            let to_light = light - floor.point(uv);
            let r2 = to_light.length_squared();
            (normal.dot(to_light) / r2.sqrt()).abs() / r2
        };
        let cone_solid_angle = TAU * (1.0 - cos_cone);
        let footprint_m2 = {
            let axis_hit = floor.hit(light, axis).map(|(t, uv)| (t, irradiance(uv)));
            match axis_hit {
                // Solid angle times r^2 over cos: the cone's area on the floor.
                Some((_, e)) if e > 0.0 => cone_solid_angle / e,
                _ => cone_solid_angle * distance * distance,
            }
        };
        let wanted = (params.photons_per_texel as f64 * footprint_m2 as f64 / texel_area_m2 as f64)
            .clamp(1e4, 4e9);
        let side = (wanted.sqrt().ceil() as u64).max(2);
        let photon_flux = cone_solid_angle / (side * side) as f32;

        let rows_per_part = side.div_ceil(PARTS as u64);
        let parts: Vec<Deposits> = (0..PARTS as u64)
            .into_par_iter()
            .map(|part| {
                let mut d = Deposits::new(&grid);
                let rows = part * rows_per_part..((part + 1) * rows_per_part).min(side);
                for i in rows {
                    for j in 0..side {
                        let index = i * side + j;
                        let (a, b) = jitter(params.seed, index);
                        let cos_theta = 1.0 - (1.0 - cos_cone) * ((i as f32 + a) / side as f32);
                        let phi = TAU * ((j as f32 + b) / side as f32);
                        let dir = frame.direction(cos_theta, phi);
                        let half = (index % 2) as usize;
                        if let Some((_, PhotoHit::Floor(uv))) = world.photo_hit(light, dir) {
                            d.add(&grid, half, false, uv, Vec3::splat(photon_flux));
                        }
                        let photon = Photon {
                            world,
                            glass,
                            grid: &grid,
                            half,
                            flux: photon_flux,
                        };
                        photon.outside(&mut d, light, dir, Vec3::ONE, 0);
                    }
                }
                d
            })
            .collect();
        let mut total = Deposits::new(&grid);
        for part in &parts {
            total.absorb(part);
        }

        let mut ratio = Vec::with_capacity((width * height) as usize);
        let (mut noise_sum, mut noise_count) = (0.0f64, 0u64);
        for y in 0..height {
            for x in 0..width {
                let i = (y * width + x) as usize;
                let uv = grid.origin_uv + (Vec2::new(x as f32, y as f32) + 0.5) * texel_uv;
                let expected = irradiance(uv) * texel_area_m2;
                let change =
                    |half: usize| total.with[half][i] - Vec3::splat(total.without[half][i]);
                if expected <= 0.0 {
                    ratio.push(Vec3::ONE);
                    continue;
                }
                let t = Vec3::ONE + (change(0) + change(1)) / expected;
                ratio.push(t.max(Vec3::ZERO));
                if (t - Vec3::ONE).abs().max_element() > 1e-3 {
                    // Half estimates: each half's change, doubled.
                    let difference = (change(0) - change(1)) * 2.0 / expected;
                    noise_sum += (difference.length_squared() / 3.0) as f64;
                    noise_count += 1;
                }
            }
        }
        let noise = if noise_count > 0 {
            // The two halves differ by twice the standard error of their mean.
            ((noise_sum / noise_count as f64).sqrt() / 2.0) as f32
        } else {
            0.0
        };
        Some(FloorLight {
            origin_uv: grid.origin_uv,
            texel_uv,
            width,
            height,
            ratio,
            noise,
            photons: side * side,
        })
    }
}

/// An orthonormal frame about the cone's axis.
struct Frame {
    axis: Vec3,
    x: Vec3,
    y: Vec3,
}

impl Frame {
    fn around(axis: Vec3) -> Frame {
        let (x, y) = axis.any_orthonormal_pair();
        Frame { axis, x, y }
    }

    /// The unit direction at polar cosine `cos_theta` from the axis and azimuth `phi`.
    fn direction(&self, cos_theta: f32, phi: f32) -> Vec3 {
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        (self.axis * cos_theta + (self.x * phi.cos() + self.y * phi.sin()) * sin_theta).normalize()
    }
}

/// The two jitter offsets (0..1) of emission cell `index`: a counter-based hash, so that every
/// cell's photon is the same whatever thread traces it.
fn jitter(seed: u64, index: u64) -> (f32, f32) {
    let mut z = seed
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(index.wrapping_mul(0xbf58_476d_1ce4_e5b9));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let a = (z >> 40) as f32 / (1u64 << 24) as f32;
    let b = ((z >> 16) & 0xff_ffff) as f32 / (1u64 << 24) as f32;
    (a, b)
}

/// Where the texel grid lies on the floor.
struct Grid {
    origin_uv: Vec2,
    texel_uv: Vec2,
    width: u32,
    height: u32,
}

/// Light deposited on the grid by the even and the odd photons, with and without the object.
struct Deposits {
    with: [Vec<Vec3>; 2],
    without: [Vec<f32>; 2],
}

impl Deposits {
    fn new(grid: &Grid) -> Deposits {
        let n = (grid.width * grid.height) as usize;
        Deposits {
            with: [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]],
            without: [vec![0.0; n], vec![0.0; n]],
        }
    }

    /// Shares `flux` landing at `uv` between the four nearest texel centres.
    fn add(&mut self, grid: &Grid, half: usize, with: bool, uv: Vec2, flux: Vec3) {
        let p = (uv - grid.origin_uv) / grid.texel_uv - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        for (dx, dy, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let (x, y) = (x0 + dx, y0 + dy);
            if x < 0 || y < 0 || x >= grid.width as i64 || y >= grid.height as i64 {
                continue;
            }
            let i = (y * grid.width as i64 + x) as usize;
            if with {
                self.with[half][i] += flux * w;
            } else {
                self.without[half][i] += flux.x * w;
            }
        }
    }

    fn absorb(&mut self, other: &Deposits) {
        for h in 0..2 {
            for (a, b) in self.with[h].iter_mut().zip(&other.with[h]) {
                *a += *b;
            }
            for (a, b) in self.without[h].iter_mut().zip(&other.without[h]) {
                *a += *b;
            }
        }
    }
}

/// One photon's way through the world with the object.
struct Photon<'a> {
    world: &'a World,
    glass: &'a Glass,
    grid: &'a Grid,
    half: usize,
    /// The photon's light as it leaves the lamp (what a weight of 1 deposits).
    flux: f32,
}

impl Photon<'_> {
    /// The photon in air, carrying `weight` of its light per channel.
    fn outside(&self, d: &mut Deposits, origin: Vec3, dir: Vec3, weight: Vec3, interfaces: u32) {
        let photo = self.world.photo_hit(origin, dir);
        if interfaces < MAX_INTERFACES
            && weight.max_element() >= MIN_WEIGHT
            && let Some((t, normal)) = self.glass.shape.enter(origin, dir)
            && photo.is_none_or(|(t_photo, _)| t < t_photo)
        {
            let at = origin + dir * t;
            let facing = if dir.dot(normal) < 0.0 {
                normal
            } else {
                -normal
            };
            let f = fresnel_reflectance(-dir.dot(facing), 1.0 / self.glass.ior);
            self.outside(
                d,
                at + facing * EPS_M,
                reflect(dir, facing),
                weight * f,
                interfaces + 1,
            );
            if let Some(inward) = refract(dir, facing, 1.0 / self.glass.ior) {
                self.inside(
                    d,
                    at - facing * EPS_M,
                    inward,
                    weight * (1.0 - f),
                    interfaces + 1,
                );
            }
            return;
        }
        if let Some((_, PhotoHit::Floor(uv))) = photo {
            d.add(self.grid, self.half, true, uv, weight * self.flux);
        }
    }

    /// The photon inside the glass.
    fn inside(&self, d: &mut Deposits, origin: Vec3, dir: Vec3, weight: Vec3, interfaces: u32) {
        if interfaces >= MAX_INTERFACES || weight.max_element() < MIN_WEIGHT {
            return;
        }
        let Some((t, normal)) = self.glass.shape.leave(origin, dir) else {
            return;
        };
        let weight = weight * self.glass.attenuation.transmittance(t);
        let at = origin + dir * t;
        let facing = if dir.dot(normal) > 0.0 {
            -normal
        } else {
            normal
        };
        let f = fresnel_reflectance(-dir.dot(facing), self.glass.ior);
        if let Some(outward) = refract(dir, facing, self.glass.ior) {
            self.outside(
                d,
                at - facing * EPS_M,
                outward,
                weight * (1.0 - f),
                interfaces + 1,
            );
        }
        self.inside(
            d,
            at + facing * EPS_M,
            reflect(dir, facing),
            weight * f,
            interfaces + 1,
        );
    }
}
