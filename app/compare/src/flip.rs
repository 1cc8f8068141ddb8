//! ꟻLIP itself (NVIDIA's C++ implementation through the `nv-flip` crate), behind the `flip`
//! feature: on by default, off for builds whose target has no C++ compiler here (Android: the
//! headset runs `vitreous run`, not the comparison tools), where the comparisons say so.

use anyhow::Result;

/// ꟻLIP's default pixels per degree (a 0.7 m viewing distance from a 24-inch 4K monitor).
pub const DEFAULT_PIXELS_PER_DEGREE: f32 = 67.0;

/// ꟻLIP's per-pixel error of `test` against `reference` (both sRGB RGB8, `width` x
/// `height`) at `ppd` pixels per degree.
#[cfg(feature = "flip")]
pub fn error_map(
    reference: &[u8],
    test: &[u8],
    (width, height): (u32, u32),
    ppd: f32,
) -> Result<Vec<f32>> {
    Ok(nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, reference),
        nv_flip::FlipImageRgb8::with_data(width, height, test),
        ppd,
    )
    .to_vec())
}

/// An error map in ꟻLIP's magma colour map, RGB8.
#[cfg(feature = "flip")]
pub fn magma(error: &[f32], (width, height): (u32, u32)) -> Vec<u8> {
    nv_flip::FlipImageFloat::with_data(width, height, error)
        .apply_color_lut(&nv_flip::magma_lut())
        .to_vec()
}

/// Without the `flip` feature: the comparison cannot be made.
#[cfg(not(feature = "flip"))]
pub fn error_map(_: &[u8], _: &[u8], _: (u32, u32), _: f32) -> Result<Vec<f32>> {
    anyhow::bail!(
        "this build of vitreous has no ꟻLIP (built without the `flip` feature, which needs a C++ \
         compiler for the target): compare images with a desktop build"
    )
}

/// Without the `flip` feature: never reached (no error map is made).
#[cfg(not(feature = "flip"))]
pub fn magma(error: &[f32], _: (u32, u32)) -> Vec<u8> {
    error.iter().flat_map(|_| [0, 0, 0]).collect()
}

#[cfg(all(test, feature = "flip"))]
mod tests {
    use super::*;

    #[test]
    fn the_default_pixels_per_degree_are_flips_own() {
        assert_eq!(
            DEFAULT_PIXELS_PER_DEGREE,
            nv_flip::DEFAULT_PIXELS_PER_DEGREE
        );
    }
}
