//! Registration error: the display's light and its dimmer's panel landing a little away from
//! where the tracker says the real world is. A [`Misregistration`] is one such error (a shift
//! across and down and a roll about the view's centre, in degrees); it maps each pixel of the
//! real world's image to the point of the display's image that lands on it. The error a scene
//! plans for (`[display] registration_error_deg`) is a spread, not one such error: see
//! [`crate::display::dimmer::spread_cells`].

use glam::Vec2;

/// The largest shift a misregistration may have, degrees (a quarter of a narrow view: beyond
/// it the display's light misses the object altogether).
pub const MAX_SHIFT_DEG: f32 = 10.0;

/// The largest roll, degrees.
pub const MAX_ROLL_DEG: f32 = 45.0;

/// One registration error: where the display's light and panel land against the real world.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Misregistration {
    /// How far the display's image lands from where it belongs, degrees: to the right and
    /// down (the image's axes).
    pub shift_deg: [f32; 2],
    /// How far it is turned about the view's centre, degrees (clockwise as the eye sees it,
    /// the image's y axis pointing down).
    pub roll_deg: f32,
}

/// What is wrong with a misregistration's numbers.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MisregistrationError {
    /// A shift that is not a number or beyond [`MAX_SHIFT_DEG`].
    #[error("a shift of {0} degrees: expected a number from -{MAX_SHIFT_DEG} to {MAX_SHIFT_DEG}")]
    Shift(f32),
    /// A roll that is not a number or beyond [`MAX_ROLL_DEG`].
    #[error("a roll of {0} degrees: expected a number from -{MAX_ROLL_DEG} to {MAX_ROLL_DEG}")]
    Roll(f32),
}

impl Misregistration {
    /// The error `shift_deg` across and down and `roll_deg` about the centre, checked.
    pub fn new(shift_deg: [f32; 2], roll_deg: f32) -> Result<Self, MisregistrationError> {
        for s in shift_deg {
            if !(s.is_finite() && s.abs() <= MAX_SHIFT_DEG) {
                return Err(MisregistrationError::Shift(s));
            }
        }
        if !(roll_deg.is_finite() && roll_deg.abs() <= MAX_ROLL_DEG) {
            return Err(MisregistrationError::Roll(roll_deg));
        }
        Ok(Misregistration {
            shift_deg,
            roll_deg,
        })
    }

    /// Whether the display lands exactly where it belongs.
    pub fn is_none(&self) -> bool {
        self.shift_deg == [0.0, 0.0] && self.roll_deg == 0.0
    }

    /// The point of the display's image (pixel coordinates, pixel centres at `i + 0.5`) that
    /// lands on the real world's point `world` (the same coordinates) of a `size` image at
    /// `ppd` pixels per degree: the inverse of turning by the roll about the centre, then
    /// shifting.
    pub fn display_point(&self, world: Vec2, size: [u32; 2], ppd: f32) -> Vec2 {
        let centre = Vec2::new(size[0] as f32, size[1] as f32) * 0.5;
        let shift = Vec2::from(self.shift_deg) * ppd;
        let (sin, cos) = self.roll_deg.to_radians().sin_cos();
        let q = world - centre - shift;
        // Turning by -roll.
        Vec2::new(cos * q.x + sin * q.y, -sin * q.x + cos * q.y) + centre
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shift_moves_the_display_by_its_angle() {
        let m = Misregistration::new([0.25, -0.125], 0.0).unwrap();
        // At 32 pixels per degree the display lands 8 px right and 4 px up: the world's pixel
        // at (100.5, 50.5) sees the display's (92.5, 54.5).
        let p = m.display_point(Vec2::new(100.5, 50.5), [200, 100], 32.0);
        assert!((p - Vec2::new(92.5, 54.5)).length() < 1e-4, "{p}");
        assert!(Misregistration::default().is_none() && !m.is_none());
    }

    #[test]
    fn a_roll_turns_about_the_centre() {
        let m = Misregistration::new([0.0, 0.0], 45.0).unwrap();
        let size = [200, 200];
        let centre = Vec2::new(100.0, 100.0);
        assert!((m.display_point(centre, size, 10.0) - centre).length() < 1e-4);
        // Turned 45 degrees: the world's point 10 px right of the centre is lit by the
        // display's point 45 degrees back, at equal distance.
        let p = m.display_point(centre + Vec2::new(10.0, 0.0), size, 10.0) - centre;
        assert!((p.length() - 10.0).abs() < 1e-4);
        assert!((p.x - 10.0 / 2f32.sqrt()).abs() < 1e-4 && (p.y + 10.0 / 2f32.sqrt()).abs() < 1e-4);
    }

    #[test]
    fn bad_numbers_are_refused() {
        assert!(Misregistration::new([f32::NAN, 0.0], 0.0).is_err());
        assert!(Misregistration::new([0.0, 11.0], 0.0).is_err());
        assert!(Misregistration::new([0.0, 0.0], f32::INFINITY).is_err());
        assert!(Misregistration::new([0.0, 0.0], -46.0).is_err());
    }
}
