//! The segmented dimmer (`[display] model = "dimmer"`, Magic Leap 2's): eye images whose
//! alpha tells the display how much of the real world to take away, and whose light makes up
//! for the panel's soft edge.
//!
//! With a dimmer, the eye passes draw into this pass's own `drawn` images (colour, with the
//! floor's shadow as alpha, and depth), not into the frame's target. Then, outside any render
//! pass, three compute dispatches per eye make the panel (shaders/dimmer_panel.wgsl: what each
//! cell wants, spread one cell or eroded, and the share the eye loses through the blurred
//! panel); then inside the frame's own eye pass one full-screen triangle writes the light and
//! the alpha (shaders/dimmer_resolve.wgsl). The model it assumes is
//! [`vitreous_optics::display::dimmer`]'s, which the see-through preview also applies.

use ash::vk;
use glam::{Vec3, Vec4Swizzles};
use gpu_allocator::MemoryLocation;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::display::dimmer::{DimmerDesc, FINE, Panel};

use crate::compensation::SeenPhotos;
use crate::context::GpuContext;
use crate::descriptors;
use crate::error::Result;
use crate::memory::{Buffer, layout_barrier, memory_barrier, subresource_range};
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, PipelineSpec};
use crate::scene::{GpuScene, SceneDesc};
use crate::shaders;
use crate::target::{self, StereoTarget};

/// Push constants: one eye (shaders/dimmer_panel.wgsl `Dimmer`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DimmerPush {
    world_from_clip: [f32; 16],
    position: [f32; 4],
    size: [f32; 4],
    blur: [f32; 4],
    limits: [f32; 4],
}

/// Stages that read the push constants.
const PUSH_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::COMPUTE.as_raw()
        | vk::ShaderStageFlags::VERTEX.as_raw()
        | vk::ShaderStageFlags::FRAGMENT.as_raw(),
);

/// The pass, freed on drop.
pub(crate) struct DimmerPass {
    /// The three compute pipelines: want, spread, soften.
    compute: [Owned<vk::Pipeline>; 3],
    /// The full-screen resolve into the frame's eye pass.
    resolve: Owned<vk::Pipeline>,
    layout: Owned<vk::PipelineLayout>,
    _pool: Owned<vk::DescriptorPool>,
    _set_layout: Owned<vk::DescriptorSetLayout>,
    set: vk::DescriptorSet,
    /// Per eye: each cell's want (f32 bits), its spread value, the softened grid.
    wanted: Buffer,
    _panel: Buffer,
    _soft: Buffer,
    _seen: SeenPhotos,
    /// What the eye passes draw into.
    drawn: StereoTarget,
    /// The render pass the eye passes draw into `drawn` with (depth stored).
    drawn_pass: Owned<vk::RenderPass>,
    desc: DimmerDesc,
    extent: vk::Extent2D,
}

impl DimmerPass {
    /// Builds the pass for `desc`'s dimmer (which it must have) at `extent` per eye; the
    /// resolve draws in `eye_render_pass` (or any render pass compatible with it).
    pub fn new(
        ctx: &GpuContext,
        eye_render_pass: vk::RenderPass,
        scene: &GpuScene,
        desc: &SceneDesc,
        dimmer: DimmerDesc,
        extent: vk::Extent2D,
    ) -> Result<DimmerPass> {
        let both = vk::ShaderStageFlags::COMPUTE | vk::ShaderStageFlags::FRAGMENT;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let (image, storage) = (
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::DescriptorType::STORAGE_BUFFER,
        );
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::UNIFORM_BUFFER, both),
                (1, image, both),
                (2, vk::DescriptorType::SAMPLER, both),
                (3, image, both),
                (4, image, both),
                (5, storage, compute),
                (6, storage, both),
                (7, storage, both),
            ],
        )?;
        let layout = pipeline::layout(
            ctx,
            Some(set_layout.raw()),
            PUSH_STAGES,
            size_of::<DimmerPush>() as u32,
        )?;
        let compute = [
            (shaders::DIMMER_WANT_CS, c"want"),
            (shaders::DIMMER_SPREAD_CS, c"spread"),
            (shaders::DIMMER_SOFTEN_CS, c"soften"),
        ]
        .map(|(spirv, entry)| pipeline::compute(ctx, layout.raw(), spirv, entry));
        let [want, spread, soften] = compute;
        let compute = [want?, spread?, soften?];
        let resolve = pipeline::create(
            ctx,
            &PipelineSpec {
                render_pass: eye_render_pass,
                layout: layout.raw(),
                vertex: (shaders::DIMMER_RESOLVE_VS, c"vs_main"),
                fragment: (shaders::DIMMER_RESOLVE_FS, c"fs_main"),
                bindings: &[],
                attributes: &[],
                cull: vk::CullModeFlags::NONE,
                // The glass's depth, for an OpenXR depth swapchain.
                depth: Depth::Copy,
                blend: Blend::Replace,
            },
        )?;
        let cells = u64::from(dimmer.cells[0]) * u64::from(dimmer.cells[1]);
        let storage_buffer = |name: &str, count: u64| {
            Buffer::new(
                ctx,
                name,
                2 * count * 4,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )
        };
        let wanted = storage_buffer("dimmer wants", cells)?;
        let panel = storage_buffer("dimmer panel", cells)?;
        let soft = storage_buffer("dimmer softened", cells * u64::from(FINE * FINE))?;
        let seen = SeenPhotos::new(ctx, desc)?;
        let drawn_pass = target::create_render_pass_storing_depth(
            ctx,
            target::COLOR_FORMAT,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            true,
        )?;
        let drawn = StereoTarget::with_usage(
            ctx,
            "dimmer's drawn eyes",
            drawn_pass.raw(),
            extent,
            vk::ImageUsageFlags::SAMPLED,
        )?;
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::UNIFORM_BUFFER, 1),
                (image, 3),
                (vk::DescriptorType::SAMPLER, 1),
                (storage, 3),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        seen.write(ctx, set, scene);
        descriptors::write_image(ctx, set, 3, drawn.color.view);
        descriptors::write_image(ctx, set, 4, drawn.depth.view);
        for (binding, buffer) in [(5, &wanted), (6, &panel), (7, &soft)] {
            descriptors::write_storage_buffer(ctx, set, binding, buffer.buffer);
        }
        Ok(DimmerPass {
            compute,
            resolve,
            layout,
            _pool: pool,
            _set_layout: set_layout,
            set,
            wanted,
            _panel: panel,
            _soft: soft,
            _seen: seen,
            drawn,
            drawn_pass,
            desc: dimmer,
            extent,
        })
    }

    /// The render pass and framebuffers the eye passes draw into when the dimmer is on
    /// (compatible with the renderer's eye render pass).
    pub fn drawn_target(&self) -> (vk::RenderPass, [vk::Framebuffer; 2]) {
        (self.drawn_pass.raw(), self.drawn.framebuffers())
    }

    /// Records, before the eye passes draw into [`DimmerPass::drawn_target`], that the
    /// previous frame's reads of it (this pass's shaders) finish before they write.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass.
    pub unsafe fn record_before_drawing(&self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        // SAFETY: the caller's contract; an execution dependency holds no handles.
        unsafe {
            ctx.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
                    | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[],
            );
        }
    }

    /// `pipeline` bound with this pass's layout and set.
    fn binding(&self, point: vk::PipelineBindPoint, pipeline: vk::Pipeline) -> pipeline::Binding {
        pipeline::Binding {
            point,
            pipeline,
            layout: self.layout.raw(),
            set: self.set,
            push_stages: PUSH_STAGES,
        }
    }

    /// The panel of `eye`'s view.
    fn panel_of(&self, eye: &EyeParams) -> Panel {
        Panel::new(&self.desc, fov_deg(eye))
    }

    /// The push constants of eye `index`.
    fn push(&self, eye: &EyeParams, index: usize) -> DimmerPush {
        let panel = self.panel_of(eye);
        let spread = panel.spread as f32;
        let [cx, cy] = self.desc.cells;
        DimmerPush {
            world_from_clip: eye.clip_from_world().inverse().to_cols_array(),
            position: eye.position_m.extend(index as f32).to_array(),
            size: [
                self.extent.width as f32,
                self.extent.height as f32,
                cx as f32,
                cy as f32,
            ],
            blur: [panel.sigma[0], panel.sigma[1], spread, spread],
            limits: [self.desc.max, FINE as f32, 0.0, 0.0],
        }
    }

    /// Records, after both eye passes drew into [`DimmerPass::drawn_target`], the panel of
    /// both eyes: their wants, spread, and softened.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, after both eye passes into the drawn
    /// target; `self` must outlive its execution.
    pub unsafe fn record_panel(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eyes: &[EyeParams; 2],
    ) {
        let d = &ctx.device;
        let read = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let transitions = [
            layout_barrier(
                self.drawn.color.image,
                subresource_range(vk::ImageAspectFlags::COLOR, 0, 2),
                (
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                ),
                (read, vk::AccessFlags::SHADER_READ),
            ),
            layout_barrier(
                self.drawn.depth.image,
                subresource_range(vk::ImageAspectFlags::DEPTH, 0, 2),
                (
                    vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                    vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE,
                ),
                (read, vk::AccessFlags::SHADER_READ),
            ),
        ];
        let shaders =
            vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER;
        // SAFETY: the caller's contract; the images and buffers are this pass's, alive until
        // the renderer waited for its frames; every dispatch's push constants match the layout.
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS,
                shaders,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &transitions,
            );
            // The previous frame's reads of the buffers are done before they are cleared.
            memory_barrier(
                d,
                cmd,
                (shaders, vk::AccessFlags::SHADER_READ),
                (
                    vk::PipelineStageFlags::TRANSFER,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
            );
            d.cmd_fill_buffer(cmd, self.wanted.buffer, 0, vk::WHOLE_SIZE, 0);
            memory_barrier(
                d,
                cmd,
                (
                    vk::PipelineStageFlags::TRANSFER,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
                (
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                ),
            );
            let [cx, cy] = self.desc.cells;
            let groups = [
                [
                    self.extent.width.div_ceil(8),
                    self.extent.height.div_ceil(8),
                ],
                [(cx * cy).div_ceil(64), 1],
                [(cx * cy * FINE * FINE).div_ceil(64), 1],
            ];
            for (stage, pipeline) in self.compute.iter().enumerate() {
                for (index, eye) in eyes.iter().enumerate() {
                    let push = self.push(eye, index);
                    self.binding(vk::PipelineBindPoint::COMPUTE, pipeline.raw())
                        .record(d, cmd, bytemuck::bytes_of(&push));
                    let [x, y] = groups[stage];
                    d.cmd_dispatch(cmd, x, y, 1);
                    ctx.work.dispatch(x, y, 1);
                    ctx.work.upload(size_of::<DimmerPush>());
                }
                let next = if stage + 1 < self.compute.len() {
                    vk::PipelineStageFlags::COMPUTE_SHADER
                } else {
                    vk::PipelineStageFlags::FRAGMENT_SHADER
                };
                memory_barrier(
                    d,
                    cmd,
                    (
                        vk::PipelineStageFlags::COMPUTE_SHADER,
                        vk::AccessFlags::SHADER_WRITE,
                    ),
                    (next, vk::AccessFlags::SHADER_READ),
                );
            }
        }
    }

    /// Records the resolve of eye `index` inside the frame's eye pass for that eye (begun
    /// clearing): every pixel's light and alpha.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with the one given to
    /// [`DimmerPass::new`], after [`DimmerPass::record_panel`] was recorded into it; `self`
    /// must outlive its execution.
    pub unsafe fn record_resolve(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eye: &EyeParams,
        index: usize,
    ) {
        let d = &ctx.device;
        let push = self.push(eye, index);
        // SAFETY: the caller's contract; the push constants match the layout.
        unsafe {
            self.binding(vk::PipelineBindPoint::GRAPHICS, self.resolve.raw())
                .record(d, cmd, bytemuck::bytes_of(&push));
            d.cmd_draw(cmd, 3, 1, 0, 0);
        }
        ctx.work.upload(size_of::<DimmerPush>());
        ctx.work.draw(3);
    }
}

/// The width and height of `eye`'s view in degrees (between the middles of opposite edges).
pub fn fov_deg(eye: &EyeParams) -> [f32; 2] {
    let view_from_clip = eye.clip_from_view.inverse();
    let dir = |x: f32, y: f32| {
        let p = view_from_clip * glam::Vec4::new(x, y, 1.0, 1.0);
        (p.xyz() / p.w).normalize()
    };
    let angle = |a: Vec3, b: Vec3| a.angle_between(b).to_degrees();
    [
        angle(dir(-1.0, 0.0), dir(1.0, 0.0)),
        angle(dir(0.0, -1.0), dir(0.0, 1.0)),
    ]
}
