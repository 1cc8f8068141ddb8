//! Blur stacks: each defocused image (background photo, surface texture) blurred once per
//! scene on the CPU by eq. 10-12 at evenly spaced K_g, uploaded as a 3-D texture the renderer
//! samples with one trilinear fetch, so per-pixel cost does not grow with K_g.

use rayon::prelude::*;

use crate::defocus_model::DefocusModel;
use vitreous_gaze::GazeImage;
use vitreous_gaze::blur::{PUPIL_MAX_MM, gaussian_kernel};
use vitreous_scene::{Image, PixelData, Scene};

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
            ..model.clone()
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
            blurred
                .iter()
                .map(|&c| vitreous_optics::srgb::from_linear(c))
                .collect()
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
///
/// Each pass adds whole rows scaled by one weight at a time (`acc += w_k * row`), taps in
/// ascending order as the convolution sums them: the inner loop is one multiply-add per float
/// over contiguous memory, which stays fast in unoptimised builds, where a scene's stacks
/// are blurred at every start.
pub fn blur_separable(rgba: &[f32], width: usize, height: usize, k_g_px: f32) -> Vec<f32> {
    let kernel = gaussian_kernel(k_g_px);
    let r = kernel.radius_px;
    if r == 0 || width == 0 || height == 0 {
        return rgba.to_vec();
    }
    let weights = &kernel.weights_1d;
    let row_len = width * 4;
    // Horizontal: each row padded by its edge pixels, then one shifted window per tap.
    let mut horizontal = vec![0.0f32; rgba.len()];
    horizontal
        .par_chunks_mut(row_len)
        .zip(rgba.par_chunks(row_len))
        .for_each(|(out, src)| {
            let mut padded = Vec::with_capacity(row_len + 8 * r);
            for _ in 0..r {
                padded.extend_from_slice(&src[..4]);
            }
            padded.extend_from_slice(src);
            for _ in 0..r {
                padded.extend_from_slice(&src[row_len - 4..]);
            }
            for (k, &w) in weights.iter().enumerate() {
                add_scaled(out, &padded[k * 4..k * 4 + row_len], w);
            }
        });
    // Vertical: each output row the weighted sum of the rows above and below, clamped.
    let mut out = vec![0.0f32; rgba.len()];
    out.par_chunks_mut(row_len)
        .enumerate()
        .for_each(|(y, row)| {
            for (k, &w) in weights.iter().enumerate() {
                let sy = (y + k).saturating_sub(r).min(height - 1);
                add_scaled(row, &horizontal[sy * row_len..(sy + 1) * row_len], w);
            }
        });
    out
}

/// `acc[i] += w * src[i]` over two slices of one length, written as an index loop so that
/// unoptimised builds do not call an iterator per element.
fn add_scaled(acc: &mut [f32], src: &[f32], w: f32) {
    let n = acc.len().min(src.len());
    let (acc, src) = (&mut acc[..n], &src[..n]);
    let mut i = 0;
    while i < n {
        acc[i] += w * src[i];
        i += 1;
    }
}

/// An sRGB image as linear RGBA floats.
pub fn to_linear(image: &Image) -> Vec<f32> {
    match &image.data {
        PixelData::Srgb8(bytes) => bytes
            .chunks_exact(4)
            .flat_map(|p| {
                [
                    vitreous_optics::srgb::to_linear(p[0]),
                    vitreous_optics::srgb::to_linear(p[1]),
                    vitreous_optics::srgb::to_linear(p[2]),
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
    use vitreous_gaze::blur::blur_reference;

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

    #[test]
    fn separable_blur_clamps_kernels_wider_than_the_image() {
        // Radius 10 on a 3 x 2 image: every tap beyond the edge reads the edge pixel.
        let (w, h) = (3usize, 2usize);
        let gray = [0.1f32, 0.5, 0.9, 0.3, 0.7, 0.2];
        let rgba: Vec<f32> = gray.iter().flat_map(|&g| [g, g, g, 1.0]).collect();
        let fast = blur_separable(&rgba, w, h, 21.0);
        let literal = blur_reference(&gray, w, h, 21.0);
        for (i, l) in literal.iter().enumerate() {
            assert!(
                (fast[i * 4] - l).abs() < 1e-5,
                "at {i}: {} vs {l}",
                fast[i * 4]
            );
            assert!((fast[i * 4 + 3] - 1.0).abs() < 1e-5, "alpha at {i}");
        }
    }
}
