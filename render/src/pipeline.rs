//! The one place render builds pipelines, their layouts, render passes and framebuffers
//! (descriptor sets: `descriptors.rs`).
//!
//! Every pass (glass, world, the floor passes) describes its pipeline with a
//! [`PipelineSpec`] and gets it from [`create`]; render passes come from
//! [`eye_render_pass`] (colour + depth, one eye layer) and [`field_render_pass`] (one
//! floor-space colour image); [`begin_render_pass`] starts either with a viewport and scissor
//! covering the target. Everything returned is an [`Owned`] handle that destroys itself.

use std::ffi::CStr;

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::owned::Owned;
use crate::scene::VERTEX_STRIDE;
use crate::shaders;

/// How a pipeline's colour output meets the target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Overwrite (each layer owns its pixels).
    Replace,
    /// Overwrite the colour and keep the target's alpha (the eye passes' alpha is the one
    /// their clear value sets, see [`crate::renderer::Composition`]).
    ReplaceColor,
    /// Overwrite the colour, and lay the output's alpha over the target's (ONE,
    /// ONE_MINUS_SRC_ALPHA): the share of the pixel the glass covers over the share of the
    /// real world the floor beneath takes away (a segmented dimmer's, render/src/dimmer).
    ReplaceColorCoverAlpha,
    /// Add to the target's colour (ONE, ONE) without touching alpha: light added on top.
    Add,
    /// Add to the target's colour and alpha (ONE, ONE): light added on top, and a share of
    /// the real world's light to take away (a segmented dimmer's, render/src/dimmer).
    AddWithAlpha,
}

/// How a pipeline uses the depth attachment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Depth {
    /// Neither tests nor writes it.
    Off,
    /// Draws the nearest surface: tests LESS and writes.
    Nearest,
    /// Writes every fragment's depth (ALWAYS): a full-screen pass handing on depth drawn
    /// elsewhere (the segmented dimmer's resolve).
    Copy,
}

/// Blending the output's colour with the target's by `op` (both weighted one), the target's
/// alpha kept.
fn onto_colour(op: vk::BlendOp) -> vk::PipelineColorBlendAttachmentState {
    vk::PipelineColorBlendAttachmentState::default()
        .blend_enable(true)
        .src_color_blend_factor(vk::BlendFactor::ONE)
        .dst_color_blend_factor(vk::BlendFactor::ONE)
        .color_blend_op(op)
        .src_alpha_blend_factor(vk::BlendFactor::ZERO)
        .dst_alpha_blend_factor(vk::BlendFactor::ONE)
        .alpha_blend_op(vk::BlendOp::ADD)
        .color_write_mask(
            vk::ColorComponentFlags::R | vk::ColorComponentFlags::G | vk::ColorComponentFlags::B,
        )
}

/// How a triangle-list pipeline with dynamic viewport and scissor draws.
pub struct PipelineSpec<'a> {
    /// The render pass (subpass 0) it draws in.
    pub render_pass: vk::RenderPass,
    /// Its layout.
    pub layout: vk::PipelineLayout,
    /// Vertex shader SPIR-V and entry point.
    pub vertex: (&'a [u8], &'a CStr),
    /// Fragment shader SPIR-V and entry point.
    pub fragment: (&'a [u8], &'a CStr),
    /// Vertex buffer bindings (empty: the shader makes its vertices).
    pub bindings: &'a [vk::VertexInputBindingDescription],
    /// Vertex attributes.
    pub attributes: &'a [vk::VertexInputAttributeDescription],
    /// Which faces to cull.
    pub cull: vk::CullModeFlags,
    /// Depth test and write.
    pub depth: Depth,
    /// Colour blending.
    pub blend: Blend,
}

/// The vertex input reading only positions from the scene's interleaved vertex buffer.
pub const MESH_POSITION_BINDING: vk::VertexInputBindingDescription =
    vk::VertexInputBindingDescription {
        binding: 0,
        stride: VERTEX_STRIDE,
        input_rate: vk::VertexInputRate::VERTEX,
    };

/// Location 0: the position (three floats at the vertex's start).
pub const MESH_POSITION_ATTRIBUTE: vk::VertexInputAttributeDescription =
    vk::VertexInputAttributeDescription {
        location: 0,
        binding: 0,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 0,
    };

/// Creates the pipeline `spec` describes.
pub fn create(ctx: &GpuContext, spec: &PipelineSpec) -> Result<Owned<vk::Pipeline>> {
    // Dropped (destroyed) on return: a pipeline does not need its modules afterwards.
    let vs = module(ctx, spec.vertex.0)?;
    let fs = module(ctx, spec.fragment.0)?;
    let stages = [
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vs.raw())
            .name(spec.vertex.1),
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(fs.raw())
            .name(spec.fragment.1),
    ];
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(spec.bindings)
        .vertex_attribute_descriptions(spec.attributes);
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    // glTF's front faces are counter-clockwise seen from outside. The projection flips y so
    // that the image is upright in Vulkan's y-down framebuffer, and Vulkan's winding rule
    // (the sign of the framebuffer-space area, negated) then sees them counter-clockwise.
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(spec.cull)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth = match spec.depth {
        Depth::Off => vk::PipelineDepthStencilStateCreateInfo::default(),
        Depth::Nearest => vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::LESS),
        Depth::Copy => vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::ALWAYS),
    };
    let blend_attachments = [match spec.blend {
        Blend::Add => onto_colour(vk::BlendOp::ADD),
        Blend::AddWithAlpha => onto_colour(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .color_write_mask(vk::ColorComponentFlags::RGBA),
        Blend::Replace => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(false)
            .color_write_mask(vk::ColorComponentFlags::RGBA),
        Blend::ReplaceColorCoverAlpha => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ZERO)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(vk::ColorComponentFlags::RGBA),
        Blend::ReplaceColor => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(false)
            .color_write_mask(
                vk::ColorComponentFlags::R
                    | vk::ColorComponentFlags::G
                    | vk::ColorComponentFlags::B,
            ),
    }];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(spec.layout)
        .render_pass(spec.render_pass)
        .subpass(0);
    // SAFETY: every handle in `info` (modules, layout, render pass) is live for the call, and
    // the state structs it points to live until it returns.
    let pipelines = unsafe {
        ctx.device
            .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
    }
    .map_err(|(_, e)| e)
    .vk("vkCreateGraphicsPipelines")?;
    Ok(Owned::new(ctx, pipelines[0]))
}

/// A compute pipeline of `entry` in `spirv` with `layout`.
pub fn compute(
    ctx: &GpuContext,
    layout: vk::PipelineLayout,
    spirv: &[u8],
    entry: &std::ffi::CStr,
) -> Result<Owned<vk::Pipeline>> {
    let module = module(ctx, spirv)?;
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module.raw())
        .name(entry);
    let info = vk::ComputePipelineCreateInfo::default()
        .stage(stage)
        .layout(layout);
    // SAFETY: the module and layout are live for the call; the module is SPIR-V naga wrote.
    let pipelines = unsafe {
        ctx.device
            .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
    }
    .map_err(|(_, e)| e)
    .vk("vkCreateComputePipelines")?;
    Ok(Owned::new(ctx, pipelines[0]))
}

/// A shader module of SPIR-V compiled by build.rs.
fn module(ctx: &GpuContext, spirv: &[u8]) -> Result<Owned<vk::ShaderModule>> {
    let words = shaders::words(spirv);
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: `words` is SPIR-V that naga wrote and validated at build time.
    let module =
        unsafe { ctx.device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")?;
    Ok(Owned::new(ctx, module))
}

/// The render pass of the eye images: a colour attachment of `color_format`, cleared and
/// stored, left in `final_layout`, and a depth attachment, cleared and stored only with
/// `store_depth` (for a depth image someone else reads: an OpenXR depth swapchain). Load and
/// store ops and layouts do not affect render-pass compatibility, so the same pipelines draw
/// in every variant of the same colour format.
pub fn eye_render_pass(
    ctx: &GpuContext,
    color_format: vk::Format,
    depth_format: vk::Format,
    final_layout: vk::ImageLayout,
    store_depth: bool,
) -> Result<Owned<vk::RenderPass>> {
    let attachments = [
        vk::AttachmentDescription::default()
            .format(color_format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(final_layout),
        vk::AttachmentDescription::default()
            .format(depth_format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(if store_depth {
                vk::AttachmentStoreOp::STORE
            } else {
                vk::AttachmentStoreOp::DONT_CARE
            })
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
    ];
    let color_ref = [vk::AttachmentReference {
        attachment: 0,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    }];
    let depth_ref = vk::AttachmentReference {
        attachment: 1,
        layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    };
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color_ref)
        .depth_stencil_attachment(&depth_ref)];
    let attachment_stages = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
        | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
        | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let attachment_writes =
        vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
    let dependencies = [
        // The previous frame's use of the same images (attachment writes, the readback copy)
        // must finish before this pass writes them again.
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(attachment_stages | vk::PipelineStageFlags::TRANSFER)
            .src_access_mask(attachment_writes)
            .dst_stage_mask(attachment_stages)
            .dst_access_mask(attachment_writes | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        // The colour written here is read by the readback copy.
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
    ];
    render_pass(ctx, &attachments, &subpasses, &dependencies)
}

/// How a floor-space field's render pass treats what the image held before. Only the render
/// area is cleared or drawn, so the `Keep` kinds cost nothing outside it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldStart {
    /// The image may be in any layout and its texels outside the render area are lost;
    /// every texel of the render area is drawn, so none is cleared.
    Discard,
    /// As `Discard`, but the render area is cleared first.
    Clear,
    /// The image is in SHADER_READ_ONLY_OPTIMAL and keeps its texels outside the render
    /// area; inside it they are cleared.
    KeepClear,
}

/// A render pass with one colour attachment of `format`, starting as `start` says, left for
/// fragment shaders to read (a floor-space field). Its dependencies order it after earlier
/// reads and writes of the image (by fragment shaders, attachments or transfers) and make its
/// writes visible to later fragment shaders and transfers. The three kinds are compatible:
/// one framebuffer and one pipeline serve them all.
pub fn field_render_pass(
    ctx: &GpuContext,
    format: vk::Format,
    start: FieldStart,
) -> Result<Owned<vk::RenderPass>> {
    let (load, initial) = match start {
        FieldStart::Discard => (vk::AttachmentLoadOp::DONT_CARE, vk::ImageLayout::UNDEFINED),
        FieldStart::Clear => (vk::AttachmentLoadOp::CLEAR, vk::ImageLayout::UNDEFINED),
        FieldStart::KeepClear => (
            vk::AttachmentLoadOp::CLEAR,
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        ),
    };
    let attachments = [vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(initial)
        .final_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)];
    let color_ref = [vk::AttachmentReference {
        attachment: 0,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    }];
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color_ref)];
    let dependencies = [
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(
                vk::PipelineStageFlags::FRAGMENT_SHADER
                    | vk::PipelineStageFlags::COMPUTE_SHADER
                    | vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::TRANSFER,
            )
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .dst_access_mask(
                vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::COLOR_ATTACHMENT_READ,
            ),
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(
                vk::PipelineStageFlags::FRAGMENT_SHADER
                    | vk::PipelineStageFlags::COMPUTE_SHADER
                    | vk::PipelineStageFlags::TRANSFER,
            )
            .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::TRANSFER_READ),
    ];
    render_pass(ctx, &attachments, &subpasses, &dependencies)
}

fn render_pass(
    ctx: &GpuContext,
    attachments: &[vk::AttachmentDescription],
    subpasses: &[vk::SubpassDescription],
    dependencies: &[vk::SubpassDependency],
) -> Result<Owned<vk::RenderPass>> {
    let info = vk::RenderPassCreateInfo::default()
        .attachments(attachments)
        .subpasses(subpasses)
        .dependencies(dependencies);
    // SAFETY: `info` and the arrays it points to are valid for the call.
    let render_pass =
        unsafe { ctx.device.create_render_pass(&info, None) }.vk("vkCreateRenderPass")?;
    Ok(Owned::new(ctx, render_pass))
}

/// A framebuffer of `attachments` (one layer) for `render_pass`.
pub fn framebuffer(
    ctx: &GpuContext,
    render_pass: vk::RenderPass,
    attachments: &[vk::ImageView],
    extent: vk::Extent2D,
) -> Result<Owned<vk::Framebuffer>> {
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(attachments)
        .width(extent.width)
        .height(extent.height)
        .layers(1);
    // SAFETY: the render pass and views are live; the caller keeps the views alive as long
    // as the framebuffer (it owns both).
    let framebuffer =
        unsafe { ctx.device.create_framebuffer(&info, None) }.vk("vkCreateFramebuffer")?;
    Ok(Owned::new(ctx, framebuffer))
}

/// Begins `render_pass` on `framebuffer` over all of `extent`, clearing to `clear`, with a
/// viewport and scissor covering it.
///
/// # Safety
/// `cmd` must be recording outside any render pass; the render pass and framebuffer must be
/// live, compatible, and outlive the command buffer's execution.
pub unsafe fn begin_render_pass(
    ctx: &GpuContext,
    cmd: vk::CommandBuffer,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    extent: vk::Extent2D,
    clear: &[vk::ClearValue],
) {
    let all = vk::Rect2D {
        offset: vk::Offset2D { x: 0, y: 0 },
        extent,
    };
    let pass = PassBegin {
        render_pass,
        framebuffer,
        extent,
        area: all,
        scissor: all,
    };
    // SAFETY: the caller's contract.
    unsafe { pass.record(ctx, cmd, clear) }
}

/// A render pass begun over part of its framebuffer: `area` is the render area (what it may
/// clear or store), the viewport covers all of `extent` (so that fragment coordinates are
/// texel coordinates) and draws are limited to `scissor`, which must lie in `area`.
pub struct PassBegin {
    /// The render pass.
    pub render_pass: vk::RenderPass,
    /// A framebuffer compatible with it.
    pub framebuffer: vk::Framebuffer,
    /// The framebuffer's size.
    pub extent: vk::Extent2D,
    /// The render area.
    pub area: vk::Rect2D,
    /// The dynamic scissor.
    pub scissor: vk::Rect2D,
}

impl PassBegin {
    /// Begins the render pass, clearing to `clear`, and sets the viewport and scissor.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; the render pass and framebuffer must
    /// be live, compatible, and outlive the command buffer's execution.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        clear: &[vk::ClearValue],
    ) {
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(self.framebuffer)
            .render_area(self.area)
            .clear_values(clear);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: self.extent.width as f32,
            height: self.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        let device = &ctx.device;
        ctx.work.render_pass();
        // SAFETY: the caller's contract: `cmd` records outside a render pass, the handles are
        // live; the pipelines bound inside set viewport and scissor dynamically.
        unsafe {
            device.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            device.cmd_set_viewport(cmd, 0, &[viewport]);
            device.cmd_set_scissor(cmd, 0, &[self.scissor]);
        }
    }
}

/// A pipeline layout with at most one set layout and push constants of `push_size` bytes.
pub fn layout(
    ctx: &GpuContext,
    set_layout: Option<vk::DescriptorSetLayout>,
    push_stages: vk::ShaderStageFlags,
    push_size: u32,
) -> Result<Owned<vk::PipelineLayout>> {
    let set_layouts: Vec<_> = set_layout.into_iter().collect();
    layout_of_sets(ctx, &set_layouts, push_stages, push_size)
}

/// [`layout`] with several descriptor sets, numbered in order.
pub fn layout_of_sets(
    ctx: &GpuContext,
    set_layouts: &[vk::DescriptorSetLayout],
    push_stages: vk::ShaderStageFlags,
    push_size: u32,
) -> Result<Owned<vk::PipelineLayout>> {
    let ranges = [vk::PushConstantRange {
        stage_flags: push_stages,
        offset: 0,
        size: push_size,
    }];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(set_layouts)
        .push_constant_ranges(&ranges);
    // SAFETY: `info` and the set layouts it names are valid for the call.
    let layout =
        unsafe { ctx.device.create_pipeline_layout(&info, None) }.vk("vkCreatePipelineLayout")?;
    Ok(Owned::new(ctx, layout))
}

/// A pipeline with its layout and its one descriptor set, as a pass binds it.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    /// Graphics or compute.
    pub point: vk::PipelineBindPoint,
    /// The pipeline.
    pub pipeline: vk::Pipeline,
    /// Its layout.
    pub layout: vk::PipelineLayout,
    /// The set bound at index 0.
    pub set: vk::DescriptorSet,
    /// The stages of the layout's push-constant range.
    pub push_stages: vk::ShaderStageFlags,
}

impl Binding {
    /// Records the pipeline's and the set's binding and the push constants `push` (from offset
    /// 0).
    ///
    /// # Safety
    /// `cmd` must be recording (inside a render pass for a graphics pipeline compatible with
    /// it); the objects must outlive its execution; `push` must fit the layout's range.
    pub unsafe fn record(&self, d: &ash::Device, cmd: vk::CommandBuffer, push: &[u8]) {
        // SAFETY: the caller's contract.
        unsafe {
            d.cmd_bind_pipeline(cmd, self.point, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, self.point, self.layout, 0, &[self.set], &[]);
            d.cmd_push_constants(cmd, self.layout, self.push_stages, 0, push);
        }
    }
}
