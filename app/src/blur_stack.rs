//! Blur stacks: each defocused image (background photo, surface texture) blurred once per
//! scene on the CPU by eq. 10-12 at evenly spaced K_g, uploaded as a 3-D texture the renderer
//! samples with one trilinear fetch, so per-pixel cost does not grow with K_g.

use rayon::prelude::*;

use crate::gaze::GazeImage;
use crate::gaze::blur::{PUPIL_MAX_MM, gaussian_kernel};
use crate::look::DefocusModel;
use crate::output::{linear_to_srgb, srgb_to_linear};
use crate::scene::{Image, PixelData, Scene};

/// Slices of each blur stack (K_g = 0 included).
pub const STACK_SLICES: u32 = 16;

/// Smallest K_g step between slices, pixels (finer steps add nothing visible).
const MIN_STEP_PX: f32 = 0.25;

/// One image blurred by K_g = i * `step_px` for slice i.
#[derive(Clone, Debug)]
pub struct BlurStack {
    /// Slice width, texels.
    pub width: u32,
    /// Slice height, texels.
    pub height: u32,
    /// Number of slices.
    pub slices: u32,
    /// K_g between slices, pixels.
    pub step_px: f32,
    /// sRGB RGBA8 texels, slice after slice.
    pub srgb8: Vec<u8>,
}

impl BlurStack {
    /// The renderer's view of the stack.
    pub fn desc(&self) -> vitreous_render::BlurStackDesc<'_> {
        vitreous_render::BlurStackDesc {
            width: self.width,
            height: self.height,
            slices: self.slices,
            k_g_step_px: self.step_px,
            srgb8: &self.srgb8,
        }
    }
}

/// A scene's defocus model and the blur stacks the renderer samples.
#[derive(Clone, Debug)]
pub struct DefocusSetup {
    /// The numbers of eq. 13-14.
    pub model: DefocusModel,
    /// The background photo's blur stack.
    pub background: BlurStack,
    /// The surface texture's blur stack, when the object has one.
    pub surface: Option<BlurStack>,
}

impl DefocusSetup {
    /// Builds the stacks for `scene`, deep enough for the largest pupil allowed (9 mm), so the
    /// pupil can change without rebuilding them.
    pub fn new(scene: &Scene, pupil_m: f32) -> DefocusSetup {
        let model = DefocusModel::new(scene, pupil_m);
        // The deepest blur of each image: the other image in focus, at the largest pupil.
        let deepest = DefocusModel {
            pupil_m: PUPIL_MAX_MM / 1000.0,
            ..model
        };
        let max_background_k = deepest
            .defocus(GazeImage::Surface)
            .map_or(0.0, |d| d.refracted_k_g_px);
        let max_surface_k = deepest
            .defocus(GazeImage::Refracted)
            .map_or(0.0, |d| d.surface_k_g_px);
        let (background, surface) = rayon::join(
            || build_stack(&scene.background.photo, max_background_k),
            || {
                scene
                    .object
                    .surface_texture
                    .as_ref()
                    .map(|t| build_stack(t, max_surface_k))
            },
        );
        DefocusSetup {
            model,
            background,
            surface,
        }
    }
}

/// Blurs `image` (sRGB) in linear light at K_g = i * step for `STACK_SLICES` slices reaching
/// `max_k_g_px`.
pub fn build_stack(image: &Image, max_k_g_px: f32) -> BlurStack {
    let step_px = (max_k_g_px / (STACK_SLICES - 1) as f32).max(MIN_STEP_PX);
    let (w, h) = (image.width as usize, image.height as usize);
    let linear = to_linear(image);
    let slices: Vec<Vec<u8>> = (0..STACK_SLICES)
        .into_par_iter()
        .map(|i| {
            let blurred = blur_separable(&linear, w, h, i as f32 * step_px);
            blurred.iter().map(|&c| linear_to_srgb(c)).collect()
        })
        .collect();
    BlurStack {
        width: image.width,
        height: image.height,
        slices: STACK_SLICES,
        step_px,
        srgb8: slices.concat(),
    }
}

/// eq. 10-12 as a separable convolution (the normalised 2-D weights are the product of the
/// normalised 1-D ones), clamp to edge, on RGBA linear floats.
pub fn blur_separable(rgba: &[f32], width: usize, height: usize, k_g_px: f32) -> Vec<f32> {
    let kernel = gaussian_kernel(k_g_px);
    let r = kernel.radius_px as isize;
    if r == 0 {
        return rgba.to_vec();
    }
    let w1 = &kernel.weights_1d;
    let pass = |src: &[f32], horizontal: bool| -> Vec<f32> {
        let mut out = vec![0.0f32; src.len()];
        out.par_chunks_mut(width * 4)
            .enumerate()
            .for_each(|(y, row)| {
                for x in 0..width {
                    let mut acc = [0.0f32; 4];
                    for (k, wk) in w1.iter().enumerate() {
                        let o = k as isize - r;
                        let (sx, sy) = if horizontal {
                            ((x as isize + o).clamp(0, width as isize - 1) as usize, y)
                        } else {
                            (x, (y as isize + o).clamp(0, height as isize - 1) as usize)
                        };
                        let i = (sy * width + sx) * 4;
                        for c in 0..4 {
                            acc[c] += wk * src[i + c];
                        }
                    }
                    row[x * 4..x * 4 + 4].copy_from_slice(&acc);
                }
            });
        out
    };
    let horizontal = pass(rgba, true);
    pass(&horizontal, false)
}

/// An sRGB image as linear RGBA floats.
pub fn to_linear(image: &Image) -> Vec<f32> {
    match &image.data {
        PixelData::Srgb8(bytes) => bytes
            .chunks_exact(4)
            .flat_map(|p| {
                [
                    srgb_to_linear(p[0]),
                    srgb_to_linear(p[1]),
                    srgb_to_linear(p[2]),
                    p[3] as f32 / 255.0,
                ]
            })
            .collect(),
        PixelData::LinearF32(floats) => floats.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gaze::blur::blur_reference;

    #[test]
    fn separable_blur_equals_the_literal_convolution() {
        let (w, h) = (23usize, 17usize);
        let gray: Vec<f32> = (0..w * h)
            .map(|i| ((i * 7919) % 97) as f32 / 97.0)
            .collect();
        let rgba: Vec<f32> = gray.iter().flat_map(|&g| [g, g, g, 1.0]).collect();
        for k_g in [0.0, 1.5, 3.0, 7.2] {
            let fast = blur_separable(&rgba, w, h, k_g);
            let literal = blur_reference(&gray, w, h, k_g);
            for (i, l) in literal.iter().enumerate() {
                assert!((fast[i * 4] - l).abs() < 1e-5, "K_g {k_g} at {i}");
            }
        }
    }
}
