//! Gaze-dependent defocus, the CPU side of METHOD.md section 4 (paper eq. 10-14): how large
//! the blur of the image NOT looked at is, and the Gaussian it is blurred with.
//!
//! Chain: eq. 14 gives the blur-circle diameter `D_b` on the image plane from the pupil, the
//! image distance and the focus distance; eq. 13 turns it into a kernel width `K_g` in the
//! photo's own pixels; eq. 11 gives the Gaussian's variance `sigma^2 = K_g / 2` (in pixels^2,
//! as the paper writes it); eq. 12 bounds the taps to offsets within `+-K_g / 2`; eq. 10 is
//! the weighted sum, with the weights normalised to sum to 1 (METHOD.md: the printed
//! `1 / (2 pi sigma^2)` does not do that on a truncated discrete kernel).
//!
//! Applying eq. 14 to both images with the focus distance `d_f` of the gaze image gives the
//! focused image `D_b = 0` and the other one its blur: the refracted image is blurred while the
//! gaze is on the surface and the other way round. While the gaze image is unknown no image is
//! blurred ([`image_blur`] returns zeros).
//!
//! [`blur_reference`] evaluates eq. 10-12 literally, pixel by pixel, as the reference the GPU
//! blur is tested against.

use thiserror::Error;

use super::image::{GazeImage, ImageDistances};

/// Smallest accepted pupil diameter, millimetres.
pub const PUPIL_MIN_MM: f32 = 1.0;
/// Largest accepted pupil diameter, millimetres.
pub const PUPIL_MAX_MM: f32 = 9.0;
/// The paper's pupil diameter, millimetres.
pub const PUPIL_DEFAULT_MM: f32 = 6.0;

/// Defocus inputs that make no sense.
#[derive(Debug, Error, PartialEq)]
pub enum DefocusError {
    /// The pupil diameter is outside the human range accepted.
    #[error(
        "pupil diameter {pupil_diameter_mm} mm is outside {PUPIL_MIN_MM}..={PUPIL_MAX_MM} mm \
         (human pupils are about 2-8 mm; the paper used {PUPIL_DEFAULT_MM} mm)"
    )]
    PupilOutOfRange {
        /// The value given, millimetres.
        pupil_diameter_mm: f32,
    },
}

/// Checks a pupil diameter given in metres against 1-9 mm; returns it unchanged.
pub fn check_pupil_diameter_m(pupil_diameter_m: f32) -> Result<f32, DefocusError> {
    let mm = pupil_diameter_m * 1000.0;
    // Small slack so that 0.001 m and 0.009 m, which are not exact in f32, pass.
    if mm.is_finite() && (PUPIL_MIN_MM - 1e-4..=PUPIL_MAX_MM + 1e-4).contains(&mm) {
        Ok(pupil_diameter_m)
    } else {
        Err(DefocusError::PupilOutOfRange {
            pupil_diameter_mm: mm,
        })
    }
}

/// eq. 14: blur-circle diameter on the image plane, `D_b = A_p * |d_b - d_f| / d_f`, metres.
/// `pupil_diameter_m` is A_p, `image_distance_m` is d_b (eye to the image being blurred),
/// `focus_distance_m` is d_f (eye to the focused image, > 0).
pub fn blur_circle_diameter_m(
    pupil_diameter_m: f32,
    image_distance_m: f32,
    focus_distance_m: f32,
) -> f32 {
    pupil_diameter_m * (image_distance_m - focus_distance_m).abs() / focus_distance_m
}

/// eq. 13: kernel width in the photo's pixels, `K_g = (W_p / W_l) * D_b`, where
/// `px_per_m` is W_p / W_l: the photo is W_p pixels across W_l metres of its image
/// ([`px_per_m`]). The only place eq. 13 is evaluated.
pub fn kernel_width_px(px_per_m: f32, blur_circle_m: f32) -> f32 {
    px_per_m * blur_circle_m
}

/// eq. 13's W_p / W_l: pixels of a photo per metre of the image it is laid on, for a photo
/// `photo_width_px` (W_p) pixels across `photo_width_m` (W_l) metres.
pub fn px_per_m(photo_width_px: f32, photo_width_m: f32) -> f32 {
    photo_width_px / photo_width_m
}

/// eq. 11: variance of the Gaussian, `sigma^2 = K_g / 2` (pixels^2).
pub fn gaussian_variance_px2(kernel_width_px: f32) -> f32 {
    kernel_width_px / 2.0
}

/// eq. 12: the taps are at whole-pixel offsets `u` with `-K_g/2 <= u <= K_g/2`; returns the
/// largest offset, `floor(K_g / 2)` (0 for `K_g < 2`: a single tap, no blur).
pub fn kernel_radius_px(kernel_width_px: f32) -> usize {
    if kernel_width_px.is_finite() && kernel_width_px > 0.0 {
        (kernel_width_px / 2.0).floor() as usize
    } else {
        0
    }
}

/// A normalised discrete Gaussian kernel of eq. 10-12.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianKernel {
    /// Largest tap offset, pixels (eq. 12); the kernel is `2 r + 1` taps wide.
    pub radius_px: usize,
    /// Variance, pixels^2 (eq. 11).
    pub variance_px2: f32,
    /// 2-D weights, row-major `(2r+1) x (2r+1)`, offset `(-r, -r)` first; sum to 1.
    pub weights_2d: Vec<f32>,
    /// The separable 1-D factor (sums to 1): `weights_2d[j][i] = w[j] * w[i]`.
    pub weights_1d: Vec<f32>,
}

/// eq. 10: the weights `exp(-(u^2 + v^2) / (2 sigma^2))` over the taps of eq. 12 with the
/// variance of eq. 11, normalised to sum to 1 (replacing the printed `1 / (2 pi sigma^2)`).
pub fn gaussian_kernel(kernel_width_px: f32) -> GaussianKernel {
    let radius_px = kernel_radius_px(kernel_width_px);
    let variance_px2 = gaussian_variance_px2(kernel_width_px);
    let r = radius_px as i64;
    if r == 0 {
        return GaussianKernel {
            radius_px,
            variance_px2,
            weights_2d: vec![1.0],
            weights_1d: vec![1.0],
        };
    }
    let two_var = 2.0 * f64::from(variance_px2);
    let raw_1d: Vec<f64> = (-r..=r)
        .map(|u| (-((u * u) as f64) / two_var).exp())
        .collect();
    let mut raw_2d = Vec::with_capacity(raw_1d.len().pow(2));
    for v in -r..=r {
        for u in -r..=r {
            raw_2d.push((-((u * u + v * v) as f64) / two_var).exp());
        }
    }
    let normalise = |w: Vec<f64>| {
        let sum: f64 = w.iter().sum();
        w.into_iter()
            .map(|x| (x / sum) as f32)
            .collect::<Vec<f32>>()
    };
    GaussianKernel {
        radius_px,
        variance_px2,
        weights_2d: normalise(raw_2d),
        weights_1d: normalise(raw_1d),
    }
}

/// eq. 10-12 evaluated literally on a single-channel `width x height` image (row-major):
/// every output pixel is the normalised-Gaussian-weighted sum of the input pixels at offsets
/// within `+-floor(K_g/2)`, a naive 2-D loop with no separation or reuse. Taps outside the
/// image read the nearest edge pixel (clamp to edge, like the GPU sampler).
///
/// # Panics
/// If `image.len() != width * height`.
pub fn blur_reference(image: &[f32], width: usize, height: usize, k_g_px: f32) -> Vec<f32> {
    assert_eq!(image.len(), width * height, "image is not width x height");
    let kernel = gaussian_kernel(k_g_px);
    let r = kernel.radius_px as i64;
    let side = 2 * r + 1;
    let mut out = vec![0.0; image.len()];
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            let mut sum = 0.0f64;
            for v in -r..=r {
                let sy = (y + v).clamp(0, height as i64 - 1) as usize;
                for u in -r..=r {
                    let sx = (x + u).clamp(0, width as i64 - 1) as usize;
                    let w = kernel.weights_2d[((v + r) * side + (u + r)) as usize];
                    sum += f64::from(w) * f64::from(image[sy * width + sx]);
                }
            }
            out[y as usize * width + x as usize] = sum as f32;
        }
    }
    out
}

/// Blur of each image of the glass for one eye, in the photos' pixels.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ImageBlur {
    /// Blur-circle diameter of the surface image (eq. 14), metres.
    pub surface_blur_circle_m: f32,
    /// Blur-circle diameter of the refracted image (eq. 14), metres.
    pub refracted_blur_circle_m: f32,
    /// Kernel width for the surface texture (eq. 13), pixels of that texture.
    pub surface_k_g_px: f32,
    /// Kernel width for the background photo (eq. 13), pixels of that photo.
    pub refracted_k_g_px: f32,
}

/// The blur of both images for a gaze image: eq. 14 with `d_f` the gaze image's distance,
/// then eq. 13 with each image's photo resolution (`*_px_per_m` = W_p / W_l). Zero blur for
/// [`GazeImage::Unknown`] (no defocus while the gaze image is unknown).
pub fn image_blur(
    gaze: GazeImage,
    distances: &ImageDistances,
    pupil_diameter_m: f32,
    surface_px_per_m: f32,
    background_px_per_m: f32,
) -> ImageBlur {
    let Some(focus_m) = distances.of(gaze).filter(|d| *d > 0.0) else {
        return ImageBlur::default();
    };
    let surface_blur_circle_m =
        blur_circle_diameter_m(pupil_diameter_m, distances.surface_m, focus_m);
    let refracted_blur_circle_m =
        blur_circle_diameter_m(pupil_diameter_m, distances.refracted_m, focus_m);
    ImageBlur {
        surface_blur_circle_m,
        refracted_blur_circle_m,
        surface_k_g_px: kernel_width_px(surface_px_per_m, surface_blur_circle_m),
        refracted_k_g_px: kernel_width_px(background_px_per_m, refracted_blur_circle_m),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq14_matches_hand_computed_values() {
        // Paper: A_p = 6 mm, surface at 0.125 m, background at 0.4 m.
        // Focus on the surface: 6 mm * 0.275 / 0.125 = 13.2 mm.
        assert!((blur_circle_diameter_m(0.006, 0.4, 0.125) - 0.0132).abs() < 1e-7);
        // Focus on the background: 6 mm * 0.275 / 0.4 = 4.125 mm.
        assert!((blur_circle_diameter_m(0.006, 0.125, 0.4) - 0.004_125).abs() < 1e-7);
        assert_eq!(blur_circle_diameter_m(0.006, 0.4, 0.4), 0.0);
        // eq. 13: a 2000 px photo 0.5 m wide is 4000 px/m; 4.125 mm -> 16.5 px.
        assert!((kernel_width_px(px_per_m(2000.0, 0.5), 0.004_125) - 16.5).abs() < 1e-4);
        assert_eq!(gaussian_variance_px2(16.5), 8.25);
        assert_eq!(kernel_radius_px(16.5), 8);
    }

    #[test]
    fn weights_sum_to_one_and_are_symmetric() {
        for k in [0.0, 1.9, 2.0, 3.0, 7.5, 16.5, 40.0] {
            let g = gaussian_kernel(k);
            let n = 2 * g.radius_px + 1;
            assert_eq!(g.weights_2d.len(), n * n);
            let s2: f32 = g.weights_2d.iter().sum();
            let s1: f32 = g.weights_1d.iter().sum();
            assert!(
                (s2 - 1.0).abs() < 1e-5 && (s1 - 1.0).abs() < 1e-5,
                "{k}: {s2} {s1}"
            );
            for i in 0..n {
                assert!((g.weights_1d[i] - g.weights_1d[n - 1 - i]).abs() < 1e-7);
                for j in 0..n {
                    let outer = g.weights_1d[j] * g.weights_1d[i];
                    assert!((g.weights_2d[j * n + i] - outer).abs() < 1e-6);
                }
            }
        }
    }

    #[test]
    fn pupil_outside_1_to_9_mm_is_refused() {
        assert!(check_pupil_diameter_m(0.006).is_ok());
        assert!(check_pupil_diameter_m(0.001).is_ok());
        assert!(check_pupil_diameter_m(0.009).is_ok());
        for bad in [0.0009, 0.0095, 0.0, -0.006, f32::NAN, 6.0] {
            let e = check_pupil_diameter_m(bad).unwrap_err();
            assert!(e.to_string().contains("1..=9 mm"), "{e}");
        }
    }

    #[test]
    fn reference_blur_keeps_flat_images_and_spreads_a_dot() {
        let (w, h) = (9, 7);
        let flat = vec![0.25; w * h];
        for v in blur_reference(&flat, w, h, 6.0) {
            assert!((v - 0.25).abs() < 1e-6);
        }
        let mut dot = vec![0.0; w * h];
        dot[3 * w + 4] = 1.0;
        let out = blur_reference(&dot, w, h, 4.0);
        let g = gaussian_kernel(4.0);
        // Away from the edges the response to a dot is the kernel itself.
        assert!((out[3 * w + 4] - g.weights_2d[12]).abs() < 1e-7);
        assert!((out.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        assert_eq!(blur_reference(&dot, w, h, 1.0), dot);
    }

    #[test]
    fn the_image_not_looked_at_is_blurred() {
        let d = ImageDistances {
            surface_m: 0.125,
            refracted_m: 0.4,
        };
        let on_surface = image_blur(GazeImage::Surface, &d, 0.006, 1000.0, 4000.0);
        assert_eq!(on_surface.surface_k_g_px, 0.0);
        assert!((on_surface.refracted_k_g_px - 52.8).abs() < 1e-3);
        let on_refracted = image_blur(GazeImage::Refracted, &d, 0.006, 1000.0, 4000.0);
        assert_eq!(on_refracted.refracted_k_g_px, 0.0);
        assert!((on_refracted.surface_k_g_px - 4.125).abs() < 1e-4);
        assert_eq!(
            image_blur(GazeImage::Unknown, &d, 0.006, 1000.0, 4000.0),
            ImageBlur::default()
        );
    }
}
