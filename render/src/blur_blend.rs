//! The frame's blur (eq. 10-14): each blur stack's two slices around the frame's K_g, blended
//! into a 2-D image before the eye passes (shaders/blur_blend.wgsl), which the glass pass then
//! reads with one bilinear fetch per pixel instead of a trilinear fetch of the 3-D stack.
//!
//! The blur is the same for both eyes and changes only with the gaze image, the pupil and the
//! image distances, so a blend is recorded only when its stack coordinate differs from the one
//! last recorded: one fragment per texel of a slice, against the glass's pixels times two eyes
//! for every frame. The blended texel is the stack's own filtering along its depth, re-encoded
//! as sRGB; on a slice's centre (no defocus, or K_g on a slice) it is the slice's texel itself.

use std::cell::Cell;

use ash::vk;

use crate::context::GpuContext;
use crate::descriptors::{self, TextureSets};
use crate::error::Result;
use crate::floor::FieldTarget;
use crate::look::Look;
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, FieldStart, PipelineSpec};
use crate::scene::GpuScene;
use crate::shaders;

/// The blended images' format: the stacks' own.
const FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;

/// The coordinates along the background's and the surface's stacks (`slices` slices,
/// `k_g_steps` pixels apart) of `look`'s blur.
pub fn depths(look: &Look, slices: [u32; 2], k_g_steps: [f32; 2]) -> [f32; 2] {
    let defocus = look.defocus.unwrap_or_default();
    [
        stack_coordinate(defocus.refracted_k_g_px, k_g_steps[0], slices[0]),
        stack_coordinate(defocus.surface_k_g_px, k_g_steps[1], slices[1]),
    ]
}

/// The texture coordinate along a blur stack of `slices` slices, `step` K_g apart, that blends
/// the two slices around `k_g` (clamped to the stack): slice centres sit at (i + 0.5) / slices.
pub fn stack_coordinate(k_g: f32, step: f32, slices: u32) -> f32 {
    let position = if step > 0.0 {
        (k_g / step).clamp(0.0, (slices - 1) as f32)
    } else {
        0.0
    };
    (position + 0.5) / slices as f32
}

/// The blends of the background photo's and the surface texture's stacks.
pub(crate) struct BlurBlend {
    /// The blended images: the background photo, then the surface texture.
    targets: [FieldTarget; 2],
    /// The full-screen pipeline sampling a stack at one depth.
    pipeline: Owned<vk::Pipeline>,
    /// Its layout (one set, the depth as a push constant).
    layout: Owned<vk::PipelineLayout>,
    /// One set per stack, in `targets`' order.
    stacks: TextureSets<2>,
    /// The stack coordinate each image's last recorded blend used (NaN: none, or one that may
    /// not have run).
    recorded: Cell<[f32; 2]>,
}

impl BlurBlend {
    /// The blends of `scene`'s stacks, each into an image of the size of its slices.
    pub fn new(ctx: &GpuContext, scene: &GpuScene) -> Result<BlurBlend> {
        let [background, surface] = scene.stack_extents;
        let targets = [
            FieldTarget::new(ctx, "blurred background", FORMAT, background)?,
            FieldTarget::new(ctx, "blurred surface", FORMAT, surface)?,
        ];
        let stacks = descriptors::texture_sets(
            ctx,
            vk::ShaderStageFlags::FRAGMENT,
            [scene.background_stack.view, scene.surface.view],
            scene.photo_sampler(),
        )?;
        let layout = pipeline::layout(
            ctx,
            Some(stacks.layout.raw()),
            vk::ShaderStageFlags::FRAGMENT,
            size_of::<f32>() as u32,
        )?;
        let pipeline = pipeline::create(
            ctx,
            &PipelineSpec {
                render_pass: targets[0].render_pass(),
                layout: layout.raw(),
                vertex: (shaders::BLUR_BLEND_VS, c"vs_main"),
                fragment: (shaders::BLUR_BLEND_FS, c"fs_main"),
                bindings: &[],
                attributes: &[],
                cull: vk::CullModeFlags::NONE,
                depth: Depth::Off,
                blend: Blend::ReplaceColor,
            },
        )?;
        Ok(BlurBlend {
            targets,
            pipeline,
            layout,
            stacks,
            recorded: Cell::new([f32::NAN; 2]),
        })
    }

    /// The blended background photo and surface texture, for the glass pass to sample (in
    /// SHADER_READ_ONLY_OPTIMAL once a frame's blends ran).
    pub fn views(&self) -> [vk::ImageView; 2] {
        [self.targets[0].image.view, self.targets[1].image.view]
    }

    /// Records the blend of each stack at its coordinate along its depth (`depths`:
    /// background, surface), where it differs from the one recorded last.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, and `self` and the stacks must outlive
    /// its execution; a command buffer that is then not submitted needs
    /// [`BlurBlend::forget`].
    pub unsafe fn record(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, depths: [f32; 2]) {
        let mut recorded = self.recorded.get();
        for (i, target) in self.targets.iter().enumerate() {
            if recorded[i] == depths[i] {
                continue;
            }
            let extent = target.extent;
            let whole = [0, 0, extent.width, extent.height];
            let d = &ctx.device;
            // SAFETY: the caller's contract; the render pass discards the image's earlier
            // texels and its dependencies order the draw after earlier frames' reads; the
            // pipeline, layout and set are this pass's.
            unsafe {
                target.begin(ctx, cmd, FieldStart::Discard, whole, 0.0, whole);
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline.raw());
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    self.layout.raw(),
                    0,
                    &[self.stacks.sets[i]],
                    &[],
                );
                d.cmd_push_constants(
                    cmd,
                    self.layout.raw(),
                    vk::ShaderStageFlags::FRAGMENT,
                    0,
                    &depths[i].to_le_bytes(),
                );
                d.cmd_draw(cmd, 3, 1, 0, 0);
                d.cmd_end_render_pass(cmd);
            }
            ctx.work.upload(size_of::<f32>());
            ctx.work.draw(3);
            recorded[i] = depths[i];
        }
        self.recorded.set(recorded);
    }

    /// Forgets what was recorded: the next frame blends both images again (after a command
    /// buffer holding blends was not submitted).
    pub fn forget(&self) {
        self.recorded.set([f32::NAN; 2]);
    }
}
