//! The floor's light from the point light with the object there, as a map: the ratio `T` of
//! the floor's irradiance with the object to that without it ([`FloorLight::trace`] makes it).

use glam::{Vec2, Vec3};

/// The ratio `T` of the floor's irradiance from the point light with the object to without it,
/// on a texel grid over part of the floor (1 outside it).
#[derive(Clone, Debug)]
pub struct FloorLight {
    /// The grid's floor photo coordinates: its top-left corner.
    pub(crate) origin_uv: Vec2,
    /// Photo coordinates per texel, u and v.
    pub(crate) texel_uv: Vec2,
    /// Texels along u and v.
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// `T` per texel and channel, row 0 at the smallest v.
    pub(crate) ratio: Vec<Vec3>,
    /// See [`FloorLight::noise`].
    pub(crate) noise: f32,
    /// Photons traced.
    pub(crate) photons: u64,
}

impl FloorLight {
    /// A floor light that scales the light's share by `ratio` everywhere (tests).
    pub fn uniform(ratio: f32) -> FloorLight {
        FloorLight {
            origin_uv: Vec2::ZERO,
            texel_uv: Vec2::ONE,
            width: 1,
            height: 1,
            ratio: vec![Vec3::splat(ratio)],
            noise: 0.0,
            photons: 0,
        }
    }

    /// `T` at floor photo coordinate `uv`, bilinear between texel centres; 1 off the grid.
    pub fn ratio(&self, uv: Vec2) -> Vec3 {
        let p = (uv - self.origin_uv) / self.texel_uv - 0.5;
        let (w, h) = (self.width as f32, self.height as f32);
        if p.x < -0.5 || p.y < -0.5 || p.x > w - 0.5 || p.y > h - 0.5 {
            return Vec3::ONE;
        }
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let at = |x: f32, y: f32| {
            let x = (x as i64).clamp(0, self.width as i64 - 1);
            let y = (y as i64).clamp(0, self.height as i64 - 1);
            self.ratio[(y * self.width as i64 + x) as usize]
        };
        let top = at(x0, y0).lerp(at(x0 + 1.0, y0), fx);
        let bottom = at(x0, y0 + 1.0).lerp(at(x0 + 1.0, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    }

    /// The standard error of `T` (RMS over texels and channels) where the object changes it
    /// by more than 0.001, from the difference of the even and odd photons' estimates.
    pub fn noise(&self) -> f32 {
        self.noise
    }

    /// Photons traced from the light.
    pub fn photons(&self) -> u64 {
        self.photons
    }

    /// The texel of largest `T` (the caustic's peak) and its centre's photo coordinate.
    pub fn peak(&self) -> (Vec2, f32) {
        let (i, t) = self
            .ratio
            .iter()
            .enumerate()
            .map(|(i, t)| (i, t.element_sum() / 3.0))
            .fold((0, f32::MIN), |a, b| if b.1 > a.1 { b } else { a });
        let (x, y) = (
            (i as u32 % self.width) as f32,
            (i as u32 / self.width) as f32,
        );
        (self.origin_uv + (Vec2::new(x, y) + 0.5) * self.texel_uv, t)
    }

    /// Texels of the grid, u and v.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Photo coordinates per texel.
    pub fn texel_uv(&self) -> Vec2 {
        self.texel_uv
    }
}
