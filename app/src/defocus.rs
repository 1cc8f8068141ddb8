//! Gaze-dependent defocus on the GPU's side of the CPU: the blur stacks the renderer samples
//! (eq. 10-12 at evenly spaced K_g, built once per scene) and, per frame, the kernel widths of
//! eq. 13-14 for the gaze image the gaze pipeline chose.
//!
//! Per-pixel cost does not grow with K_g: each image is one trilinear fetch from its stack.
//! While the gaze image is unknown (no valid gaze yet, or a blink held too long), nothing is
//! blurred.

use rayon::prelude::*;
use vitreous_render::{Defocus, Look};
use vitreous_xr::FrameInput;

use crate::gaze::defocus::{PUPIL_MAX_MM, blur_circle_diameter_m, gaussian_kernel, image_blur};
use crate::gaze::{GazeConfig, GazeImage, GazeOverride, GazePipeline, GazeState, ImageDistances};
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

/// The numbers eq. 13-14 need of a scene: image distances, pixels per metre of each image's
/// photo, and the pupil.
#[derive(Clone, Copy, Debug)]
pub struct DefocusModel {
    /// Distances of the surface and refracted images from the viewing position, metres.
    pub distances: ImageDistances,
    /// Pupil diameter A_p, metres.
    pub pupil_m: f32,
    /// W_p / W_l of the surface texture: texels per metre on the object's surface.
    pub surface_px_per_m: f32,
    /// W_p / W_l of the background photo: pixels per metre on the background plane.
    pub background_px_per_m: f32,
}

impl DefocusModel {
    /// The model of `scene` with pupil diameter `pupil_m`.
    pub fn new(scene: &Scene, pupil_m: f32) -> DefocusModel {
        DefocusModel {
            distances: scene.image_distances(),
            pupil_m,
            background_px_per_m: scene.background.photo.width as f32 / scene.background.size_m.x,
            // u runs once around the object: texels per metre of its circumference.
            surface_px_per_m: scene.object.surface_texture.as_ref().map_or(1.0, |t| {
                t.width as f32 / (std::f32::consts::PI * 2.0 * scene.object.radius_m)
            }),
        }
    }

    /// The blur of both images for a gaze image (eq. 13-14); `None` while it is unknown.
    pub fn defocus(&self, image: GazeImage) -> Option<Defocus> {
        if image == GazeImage::Unknown {
            return None;
        }
        let blur = image_blur(
            image,
            &self.distances,
            self.pupil_m,
            self.surface_px_per_m,
            self.background_px_per_m,
        );
        Some(Defocus {
            refracted_k_g_px: blur.refracted_k_g_px,
            surface_k_g_px: blur.surface_k_g_px,
        })
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
        let (s, r) = (model.distances.surface_m, model.distances.refracted_m);
        let max_pupil_m = PUPIL_MAX_MM / 1000.0;
        let max_background_k =
            model.background_px_per_m * blur_circle_diameter_m(max_pupil_m, r, s);
        let max_surface_k = model.surface_px_per_m * blur_circle_diameter_m(max_pupil_m, s, r);
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

/// Decides each frame's look: the effect set's fixed part, and the defocus that the gaze
/// pipeline (vergence -> depth filter -> gaze image, METHOD.md section 5) asks for.
pub struct LookPlanner {
    /// The effect set's look without defocus amounts.
    base: Look,
    /// Gaze pipeline and defocus model, when defocus is on.
    defocus: Option<(GazePipeline, DefocusModel)>,
}

impl LookPlanner {
    /// A planner for `base` (see `views::look`); with `defocus`, the gaze pipeline runs with
    /// `gaze` as its configuration.
    pub fn new(base: Look, defocus: Option<(GazeConfig, DefocusModel)>) -> LookPlanner {
        LookPlanner {
            base,
            defocus: defocus.map(|(config, model)| (GazePipeline::new(config), model)),
        }
    }

    /// Forces the gaze image (or lets the tracker choose again) from now on; no effect
    /// without defocus. The gaze pipeline keeps its tracking state.
    pub fn set_gaze_override(&mut self, image: GazeOverride) {
        if let Some((pipeline, _)) = &mut self.defocus {
            pipeline.set_override(image);
        }
    }

    /// The forced gaze image; `None` without defocus.
    pub fn gaze_override(&self) -> Option<GazeOverride> {
        self.defocus
            .as_ref()
            .map(|(pipeline, _)| pipeline.config().override_image)
    }

    /// The look of a frame, and the gaze state behind its defocus (when defocus is on).
    pub fn plan(&mut self, input: &FrameInput) -> (Look, Option<GazeState>) {
        match &mut self.defocus {
            None => (self.base, None),
            Some((pipeline, model)) => {
                let state = pipeline.update(input.gaze.as_ref(), input.time_ns);
                let look = Look {
                    defocus: model.defocus(state.image),
                    ..self.base
                };
                (look, Some(state))
            }
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
    use crate::gaze::defocus::blur_reference;

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
