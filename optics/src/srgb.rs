//! The sRGB transfer function (IEC 61966-2-1) between 8-bit encoded values and linear light,
//! for every conversion on the CPU: photos decoded for the reference and the seen images, the
//! photos' ripmaps, the wearer's see-through preview. The GPU's sRGB formats do the same in
//! hardware.

/// An sRGB-encoded byte as linear light in 0..=1.
pub fn to_linear(v: u8) -> f32 {
    let c = f32::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light (clamped to 0..=1) as the nearest sRGB-encoded byte.
pub fn from_linear(l: f32) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_comes_back_and_the_curve_is_the_standard_one() {
        for v in 0..=255u8 {
            assert_eq!(from_linear(to_linear(v)), v);
        }
        // The standard's values: mid-grey 0.5 encoded is about 0.214 linear; the linear
        // segment's end.
        assert!((to_linear(128) - 0.2158605).abs() < 1e-6);
        assert!((to_linear(10) - 10.0 / 255.0 / 12.92).abs() < 1e-7);
        assert_eq!(from_linear(-1.0), 0);
        assert_eq!(from_linear(2.0), 255);
    }
}
