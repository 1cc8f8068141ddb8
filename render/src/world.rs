//! The real world (floor and background photos on their registered planes), drawn for the
//! see-through preview and behind the glass on an opaque display (shaders/world.wgsl): each
//! pixel at its centre, or, when the scene takes several positions per glass pixel, over its
//! footprint from the photos' ripmaps, the world eq. 6 over the glass takes away.

use std::sync::Arc;
use vitreous_optics::camera::EyeParams;

use ash::vk;
use glam::Mat4;

use crate::context::GpuContext;
use crate::descriptors::{self, TextureSets};
use crate::error::Result;
use crate::footprint::Footprint;
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
    /// Over each pixel's footprint: the ripmaps' set (set 1).
    footprint: Option<FootprintSet>,
}

/// The photos' ripmaps and where their reductions lie, as the world's set 1; freed on drop.
struct FootprintSet {
    _pool: Owned<vk::DescriptorPool>,
    set_layout: Owned<vk::DescriptorSetLayout>,
    set: vk::DescriptorSet,
    _footprint: Arc<Footprint>,
}

impl FootprintSet {
    fn new(ctx: &GpuContext, footprint: Arc<Footprint>) -> Result<FootprintSet> {
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::UNIFORM_BUFFER, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
            ],
        )?;
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::UNIFORM_BUFFER, 1),
                (vk::DescriptorType::SAMPLED_IMAGE, 1),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        descriptors::write_uniform_buffer(ctx, set, 0, footprint.levels.buffer);
        descriptors::write_image(ctx, set, 1, footprint.atlas.view);
        Ok(FootprintSet {
            _pool: pool,
            set_layout,
            set,
            _footprint: footprint,
        })
    }
}

impl WorldPass {
    /// Builds the pass for the scene's two planes, sampling each pixel over its footprint
    /// when given the photos' ripmaps (`footprint`), else at its centre.
    pub(crate) fn new(
        ctx: &GpuContext,
        render_pass: vk::RenderPass,
        scene: &GpuScene,
        planes: [Mat4; 2],
        footprint: Option<Arc<Footprint>>,
    ) -> Result<WorldPass> {
        let photos = descriptors::texture_sets(
            ctx,
            vk::ShaderStageFlags::FRAGMENT,
            [scene.photos[0].view, scene.photos[1].view],
            scene.photo_sampler(),
        )?;
        let footprint = footprint.map(|f| FootprintSet::new(ctx, f)).transpose()?;
        let mut set_layouts = vec![photos.layout.raw()];
        set_layouts.extend(footprint.as_ref().map(|f| f.set_layout.raw()));
        let layout = pipeline::layout_of_sets(
            ctx,
            &set_layouts,
            vk::ShaderStageFlags::VERTEX,
            size_of::<PlanePush>() as u32,
        )?;
        let fragment = match footprint {
            Some(_) => (shaders::WORLD_FOOTPRINT_FS, c"fs_footprint"),
            None => (shaders::WORLD_FS, c"fs_main"),
        };
        let pipeline = pipeline::create(
            ctx,
            &PipelineSpec {
                render_pass,
                layout: layout.raw(),
                vertex: (shaders::WORLD_VS, c"vs_main"),
                fragment,
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
            footprint,
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
            if let Some(footprint) = &self.footprint {
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    self.layout.raw(),
                    1,
                    &[footprint.set],
                    &[],
                );
            }
            // The draw's instance names the plane's photo (0 the floor, 1 the background).
            for (instance, (set, plane)) in self.sets.sets.iter().zip(&self.planes).enumerate() {
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
                d.cmd_draw(cmd, 6, 1, 0, instance as u32);
                ctx.work.upload(std::mem::size_of::<PlanePush>());
                ctx.work.draw(6);
            }
        }
    }
}
