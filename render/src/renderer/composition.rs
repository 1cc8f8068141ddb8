//! How the eye images meet the real world on the display, which decides what the eye passes
//! draw behind the glass and the alpha they leave.

/// How a display composes the submitted eye images with the real world (OpenXR's environment
/// blend modes).
///
/// The glass and the real-world photos write colour only; the alpha of every pixel is the eye
/// pass's clear alpha, set here. (In a scene with a segmented dimmer the glass lays the share
/// of each pixel it covers over the alpha, for the dimmer's panel: over 1 it stays 1.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Composition {
    /// The display adds the image's light onto the real world (optical see-through, ADDITIVE):
    /// rendered on black, which adds nothing; alpha 1 (unused by the display).
    #[default]
    Additive,
    /// The display blends the image over the real world by its alpha (ALPHA_BLEND, with the
    /// layer's source-alpha flag): premultiplied colour over alpha 0, so the world shows
    /// through everywhere and the rendered light adds onto it (`C = C_src + (1 - 0) C_world`).
    AlphaBlend,
    /// The display shows only the image (OPAQUE): the scene's real-world photos are drawn
    /// behind the glass; alpha 1.
    Opaque,
}

impl Composition {
    /// Whether the real-world photos are drawn behind the glass.
    pub fn world_behind(self) -> bool {
        self == Composition::Opaque
    }

    /// The alpha the eye passes clear to and keep.
    pub fn clear_alpha(self) -> f32 {
        match self {
            Composition::AlphaBlend => 0.0,
            Composition::Additive | Composition::Opaque => 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_alpha_blend_leaves_alpha_zero_and_only_opaque_draws_the_world() {
        assert_eq!(Composition::AlphaBlend.clear_alpha(), 0.0);
        assert_eq!(Composition::Additive.clear_alpha(), 1.0);
        assert_eq!(Composition::Opaque.clear_alpha(), 1.0);
        assert!(Composition::Opaque.world_behind());
        assert!(!Composition::Additive.world_behind() && !Composition::AlphaBlend.world_behind());
    }
}
