//! The real world (floor and background photos on their registered planes), drawn only for the
//! see-through preview, never into an eye image (shaders/world.wgsl).

use ash::vk;
use glam::Mat4;

use crate::camera::EyeParams;
use crate::context::GpuContext;
use crate::descriptors::{self, TextureSets};
use crate::error::Result;
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, PipelineSpec};
use crate::scene::GpuScene;
use crate::shaders;

/// Push constants: one plane seen by one eye.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PlanePush {
    clip_from_world: [f32; 16],
    world_from_plane: [f32; 16],
}

/// The real-world pipeline and one descriptor set per plane, freed on drop.
pub struct WorldPass {
    /// The pipeline.
    pipeline: Owned<vk::Pipeline>,
    /// Pipeline layout.
    layout: Owned<vk::PipelineLayout>,
    /// The photos' sets: floor then background.
    sets: TextureSets<2>,
    /// Floor then background plane transforms.
    planes: [Mat4; 2],
}

impl WorldPass {
    /// Builds the pass for the scene's two planes.
    pub fn new(
        ctx: &GpuContext,
        render_pass: vk::RenderPass,
        scene: &GpuScene,
        planes: [Mat4; 2],
    ) -> Result<WorldPass> {
        let photos = descriptors::texture_sets(
            ctx,
            vk::ShaderStageFlags::FRAGMENT,
            [scene.photos[0].view, scene.photos[1].view],
            scene.photo_sampler(),
        )?;
        let layout = pipeline::layout(
            ctx,
            Some(photos.layout.raw()),
            vk::ShaderStageFlags::VERTEX,
            size_of::<PlanePush>() as u32,
        )?;
        let pipeline = pipeline::create(
            ctx,
            &PipelineSpec {
                render_pass,
                layout: layout.raw(),
                vertex: (shaders::WORLD_VS, c"vs_main"),
                fragment: (shaders::WORLD_FS, c"fs_main"),
                bindings: &[],
                attributes: &[],
                cull: vk::CullModeFlags::NONE,
                depth: Depth::Nearest,
                blend: Blend::ReplaceColor,
            },
        )?;
        Ok(WorldPass {
            pipeline,
            layout,
            sets: photos,
            planes,
        })
    }

    /// Records both planes for one eye, inside that eye's render pass.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with this pass.
    pub unsafe fn record(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, eye: &EyeParams) {
        let d = &ctx.device;
        // SAFETY: the caller's contract (recording inside a compatible render pass); the
        // pipeline and sets are live for as long as the renderer that records them, which
        // waits for its frames before dropping them.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline.raw());
            for (set, plane) in self.sets.sets.iter().zip(&self.planes) {
                let push = PlanePush {
                    clip_from_world: eye.clip_from_world().to_cols_array(),
                    world_from_plane: plane.to_cols_array(),
                };
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    self.layout.raw(),
                    0,
                    &[*set],
                    &[],
                );
                d.cmd_push_constants(
                    cmd,
                    self.layout.raw(),
                    vk::ShaderStageFlags::VERTEX,
                    0,
                    bytemuck::bytes_of(&push),
                );
                d.cmd_draw(cmd, 6, 1, 0, 0);
                ctx.work.upload(std::mem::size_of::<PlanePush>());
                ctx.work.draw(6);
            }
        }
    }
}
