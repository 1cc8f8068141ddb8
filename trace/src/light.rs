//! The room's light as a headset estimates it (XR_ML_light_estimation): the main light's
//! direction and colour and the ambient light's spherical harmonics, and what the scene takes
//! from them: where its point light goes, and the light's share of the floor's light.
//!
//! The spherical harmonics are the 9 real coefficients (l <= 2) of the ambient radiance per
//! colour channel, in the order l = 0; l = 1: m = -1, 0, 1; l = 2: m = -2..2, over the axes of
//! the frame the estimate is in. The irradiance they give a surface is Ramamoorthi and
//! Hanrahan's (2001, "An efficient representation for irradiance environment maps"):
//! the radiance convolved with the clamped cosine, which keeps bands 0-2 exactly.

use glam::{Quat, Vec3};

/// Smallest change of the estimated direction that moves the scene's light, degrees: a
/// turn this small moves a shadow 1 m away by under 2 mm, and steadier estimates do not
/// recompute the shadow and caustics every time.
pub const MIN_TURN_DEG: f32 = 0.25;

/// One estimate of the room's light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightEstimate {
    /// The way the main light travels (unit), from the light into the room.
    pub direction: Vec3,
    /// The main light's colour: the irradiance (linear RGB) it gives a surface facing it.
    pub color: Vec3,
    /// The ambient light's spherical-harmonic coefficients (see the module's order).
    pub ambient_sh: [Vec3; 9],
    /// When the runtime estimated it, nanoseconds on the runtime's clock.
    pub time_ns: i64,
}

/// The real spherical harmonics of l <= 2 at the unit direction `d`, in the module's order.
pub fn sh_basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

impl LightEstimate {
    /// The same estimate in another frame: `rotation` takes this estimate's axes into it.
    pub fn rotated(&self, rotation: Quat) -> LightEstimate {
        LightEstimate {
            direction: (rotation * self.direction).normalize_or_zero(),
            ambient_sh: rotate_sh(&self.ambient_sh, rotation),
            ..*self
        }
    }

    /// The irradiance (linear RGB) the ambient light gives a surface facing `normal` (unit).
    pub fn ambient_irradiance(&self, normal: Vec3) -> Vec3 {
        const C1: f32 = 0.429_043;
        const C2: f32 = 0.511_664;
        const C3: f32 = 0.743_125;
        const C4: f32 = 0.886_227;
        const C5: f32 = 0.247_708;
        let l = &self.ambient_sh;
        let (x, y, z) = (normal.x, normal.y, normal.z);
        l[8] * (C1 * (x * x - y * y)) + l[6] * (C3 * z * z) + l[0] * C4 - l[6] * C5
            + (l[4] * (x * y) + l[7] * (x * z) + l[5] * (y * z)) * (2.0 * C1)
            + (l[3] * x + l[1] * y + l[2] * z) * (2.0 * C2)
    }

    /// The irradiance (linear RGB) the main light gives a surface facing `normal` (unit).
    pub fn main_irradiance(&self, normal: Vec3) -> Vec3 {
        self.color * (-self.direction.dot(normal)).max(0.0)
    }

    /// The main light's share of the light on a surface facing `normal`, by luminance
    /// (Rec. 709 weights): what `[light] share` says of the floor. `None` when neither light
    /// reaches it.
    pub fn share_on(&self, normal: Vec3) -> Option<f32> {
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722)).max(0.0);
        let main = luminance(self.main_irradiance(normal));
        let ambient = luminance(self.ambient_irradiance(normal));
        let total = main + ambient;
        (total > 0.0 && total.is_finite()).then(|| (main / total).clamp(0.0, 1.0))
    }

    /// Whether the estimate can be used: a unit-length finite direction, finite colours.
    pub fn is_usable(&self) -> bool {
        self.direction.is_finite()
            && (self.direction.length() - 1.0).abs() < 1e-3
            && self.color.is_finite()
            && self.ambient_sh.iter().all(|c| c.is_finite())
    }
}

/// Where a point light goes to shine along `direction` onto `center` from as far as
/// `current` is: the scene's light turned about the object to the estimated direction.
pub fn light_position_along(center: Vec3, current: Vec3, direction: Vec3) -> Vec3 {
    center - direction.normalize() * current.distance(center)
}

/// The angle between two directions, degrees.
pub fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    a.normalize()
        .dot(b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// The coefficients of the radiance `sh` describes, turned by `rotation`: the turned function
/// projected again (bands 0-2 rotate among themselves, so nothing is lost but the
/// quadrature's error).
fn rotate_sh(sh: &[Vec3; 9], rotation: Quat) -> [Vec3; 9] {
    if rotation.is_near_identity() {
        return *sh;
    }
    // A Fibonacci sphere of 1024 points: its error on these products of bands <= 2 is far
    // below what the estimate's own accuracy allows (the test checks 2e-3 of the irradiance).
    const N: usize = 1024;
    let inverse = rotation.inverse();
    let mut out = [Vec3::ZERO; 9];
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    for i in 0..N {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / N as f32;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = golden * i as f32;
        let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let source = sh_basis(inverse * d);
        let value: Vec3 = source.iter().zip(sh).map(|(y, c)| *c * *y).sum();
        for (o, y) in out.iter_mut().zip(sh_basis(d)) {
            *o += value * y;
        }
    }
    let weight = 4.0 * std::f32::consts::PI / N as f32;
    out.map(|c| c * weight)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    /// Sums `term(d) dw` over the sphere on a fine latitude-longitude grid (independent of the
    /// Fibonacci quadrature above).
    fn integrate<T: std::iter::Sum<T> + std::ops::Mul<f32, Output = T>>(
        term: impl Fn(Vec3) -> T,
    ) -> T {
        let (nt, np) = (400, 800);
        (0..nt)
            .flat_map(|i| (0..np).map(move |j| (i, j)))
            .map(|(i, j)| {
                let theta = (i as f32 + 0.5) / nt as f32 * PI;
                let phi = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                term(d) * (theta.sin() * (PI / nt as f32) * (2.0 * PI / np as f32))
            })
            .sum()
    }

    /// Coefficients of the radiance `f` by numerical projection.
    fn project(f: impl Fn(Vec3) -> Vec3) -> [Vec3; 9] {
        std::array::from_fn(|k| integrate(|d| f(d) * sh_basis(d)[k]))
    }

    /// The irradiance of the radiance `f` on a surface facing `n`, by direct integration.
    fn irradiance(f: impl Fn(Vec3) -> Vec3, n: Vec3) -> Vec3 {
        integrate(|d| f(d) * d.dot(n).max(0.0))
    }

    fn estimate(sh: [Vec3; 9]) -> LightEstimate {
        LightEstimate {
            direction: Vec3::NEG_Y,
            color: Vec3::ZERO,
            ambient_sh: sh,
            time_ns: 0,
        }
    }

    #[test]
    fn a_uniform_sky_gives_pi_times_its_radiance_on_any_surface() {
        let sh = project(|_| Vec3::new(0.5, 1.0, 2.0));
        for n in [Vec3::Y, Vec3::X, Vec3::new(0.3, -0.8, 0.52).normalize()] {
            let e = estimate(sh).ambient_irradiance(n);
            assert!(
                (e - Vec3::new(0.5, 1.0, 2.0) * PI).abs().max_element() < 2e-3,
                "{n}: {e}"
            );
        }
    }

    #[test]
    fn a_smooth_sky_gives_the_integrated_irradiance() {
        // Brighter overhead and towards +x: bands 0-2 only, so the representation is exact.
        let sky = |d: Vec3| Vec3::splat(1.0 + 0.6 * d.y + 0.3 * d.x * d.y + 0.2 * d.z * d.z);
        let sh = project(sky);
        for n in [
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::new(1.0, 1.0, -0.5).normalize(),
        ] {
            let want = irradiance(sky, n);
            let got = estimate(sh).ambient_irradiance(n);
            assert!(
                (want - got).abs().max_element() < 5e-3,
                "{n}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn the_share_is_the_main_light_over_all_the_light_on_the_floor() {
        // A sky of radiance 1/pi gives irradiance 1 on the floor; a main light of 3 from
        // 60 degrees off the vertical gives 1.5 on it: share 0.6.
        let sh = project(|_| Vec3::splat(1.0 / PI));
        let mut e = estimate(sh);
        e.color = Vec3::splat(3.0);
        e.direction = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
        let share = e.share_on(Vec3::Y).unwrap();
        assert!((share - 0.6).abs() < 1e-3, "{share}");
        // A light under the floor does not light it.
        e.direction = -e.direction;
        assert!(e.share_on(Vec3::Y).unwrap() < 1e-6);
        // Nothing at all: no share.
        assert_eq!(estimate([Vec3::ZERO; 9]).share_on(Vec3::Y), None);
    }

    #[test]
    fn a_rotated_estimate_lights_the_rotated_surface_alike() {
        let sky = |d: Vec3| Vec3::new(1.0 + 0.8 * d.y, 1.0 + 0.5 * d.x, 1.0 + 0.4 * d.x * d.z);
        let e = estimate(project(sky));
        let q = Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 0.2);
        let turned = e.rotated(q);
        for n in [Vec3::Y, Vec3::new(0.2, 0.9, -0.4).normalize()] {
            let a = e.ambient_irradiance(n);
            let b = turned.ambient_irradiance(q * n);
            assert!((a - b).abs().max_element() < 2e-3, "{n}: {a} vs {b}");
        }
        assert!((turned.direction - q * Vec3::NEG_Y).length() < 1e-6);
    }

    #[test]
    fn the_light_turns_about_the_object_at_its_distance() {
        let center = Vec3::new(0.0, -0.26, -1.5);
        let light = center + Vec3::new(0.0, 1.0, 0.5);
        let d = (center - light).normalize();
        let turned = Quat::from_rotation_y(30f32.to_radians()) * d;
        let moved = light_position_along(center, light, turned);
        assert!((moved.distance(center) - light.distance(center)).abs() < 1e-5);
        assert!(((center - moved).normalize() - turned).length() < 1e-5);
        // Turned 30 degrees about the vertical: the way turns by less (it slopes down).
        let horizontal = |v: Vec3| Vec3::new(v.x, 0.0, v.z);
        assert!((angle_deg(horizontal(d), horizontal(turned)) - 30.0).abs() < 1e-3);
        let slope = 2f32.atan().cos(); // cos of the way's angle below the horizontal
        let want = (slope * slope * 30f32.to_radians().cos() + (1.0 - slope * slope)).acos();
        assert!((angle_deg(d, turned) - want.to_degrees()).abs() < 1e-3);
    }
}
