//! Absorption inside the glass (Beer-Lambert), beyond the paper: glTF's `KHR_materials_volume`
//! describes a tinted or cloudy medium by the colour white light turns into after travelling an
//! attenuation distance inside it. Light that travels L inside keeps
//! T = attenuation_color^(L / attenuation_distance) of each channel. Only two-surface
//! refraction has a path inside the glass; the paper's model has none, and ignores it.

use glam::Vec3;

/// Largest absorption coefficient handed to the shader, per metre: stands for the infinite
/// one of a black attenuation colour, so that e^(-sigma L) is 0 for any path inside, and 1 (not
/// NaN) for an empty one.
const MAX_COEFFICIENT_PER_M: f32 = 1.0e30;

/// The medium of the glass: what white light turns into after `distance_m` inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    /// Linear RGB that white light turns into after `distance_m` inside, each in 0..=1.
    pub color: Vec3,
    /// The attenuation distance, world metres (> 0; infinite: the medium absorbs nothing).
    pub distance_m: f32,
}

impl Attenuation {
    /// Clear glass: nothing absorbed (glTF's defaults, and a model without the extension).
    pub const NONE: Attenuation = Attenuation {
        color: Vec3::ONE,
        distance_m: f32::INFINITY,
    };

    /// Beer-Lambert: the fraction of each channel left after `path_m` metres inside,
    /// `color^(path_m / distance_m)`; exactly 1 for clear glass.
    pub fn transmittance(&self, path_m: f32) -> Vec3 {
        let depth = path_m / self.distance_m;
        Vec3::new(
            self.color.x.powf(depth),
            self.color.y.powf(depth),
            self.color.z.powf(depth),
        )
    }

    /// The absorption coefficient per metre of each channel, `-ln(color) / distance_m`, so
    /// that the transmittance is `e^(-coefficient L)` (the shader's form): exactly 0 for a
    /// channel that absorbs nothing, large but finite for a black one.
    pub fn coefficient_per_m(&self) -> Vec3 {
        let per_channel = |c: f32| {
            if c >= 1.0 || self.distance_m.is_infinite() {
                0.0
            } else {
                (-c.ln() / self.distance_m).min(MAX_COEFFICIENT_PER_M)
            }
        };
        Vec3::new(
            per_channel(self.color.x),
            per_channel(self.color.y),
            per_channel(self.color.z),
        )
    }

    /// Whether the medium absorbs nothing at all.
    pub fn is_clear(&self) -> bool {
        self.coefficient_per_m() == Vec3::ZERO
    }
}

impl Default for Attenuation {
    fn default() -> Attenuation {
        Attenuation::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tinted glass: white turns into this after 0.1 m.
    const TINT: Attenuation = Attenuation {
        color: Vec3::new(0.25, 0.5, 0.8),
        distance_m: 0.1,
    };

    #[test]
    fn clear_glass_transmits_exactly_everything_along_any_path() {
        for path_m in [0.0, 1e-6, 0.15, 3.0, 1e6] {
            assert_eq!(Attenuation::NONE.transmittance(path_m), Vec3::ONE);
        }
        assert_eq!(Attenuation::NONE.coefficient_per_m(), Vec3::ZERO);
        assert!(Attenuation::NONE.is_clear());
        // White at a finite distance is clear too: only the colour absorbs.
        let white = Attenuation {
            color: Vec3::ONE,
            distance_m: 0.01,
        };
        assert_eq!(white.transmittance(0.3), Vec3::ONE);
        assert!(white.is_clear());
        assert!(!TINT.is_clear());
    }

    #[test]
    fn white_light_turns_into_the_colour_at_the_distance_and_its_square_at_twice() {
        assert!(TINT.transmittance(0.1).abs_diff_eq(TINT.color, 1e-6));
        assert!(
            TINT.transmittance(0.2)
                .abs_diff_eq(TINT.color * TINT.color, 1e-6)
        );
        assert_eq!(TINT.transmittance(0.0), Vec3::ONE);
    }

    #[test]
    fn the_shaders_exponential_form_is_the_same_transmittance() {
        let sigma = TINT.coefficient_per_m();
        for path_m in [0.0f32, 0.03, 0.15, 0.4] {
            let exponential = (-sigma * path_m).exp();
            assert!(
                exponential.abs_diff_eq(TINT.transmittance(path_m), 1e-6),
                "{path_m} m: {exponential} vs {}",
                TINT.transmittance(path_m)
            );
        }
    }

    #[test]
    fn a_black_channel_absorbs_all_of_any_path_inside_and_nothing_of_none() {
        let black = Attenuation {
            color: Vec3::new(0.0, 1.0, 0.5),
            distance_m: 0.05,
        };
        let sigma = black.coefficient_per_m();
        assert!(sigma.is_finite(), "{sigma}");
        assert_eq!(black.transmittance(1e-4).x, 0.0);
        assert_eq!((-sigma * 1e-4).exp().x, 0.0);
        assert_eq!(black.transmittance(0.0), Vec3::ONE);
        assert_eq!((-sigma * 0.0).exp(), Vec3::ONE);
    }
}
