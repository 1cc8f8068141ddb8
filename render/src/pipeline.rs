//! Shared pieces of graphics pipeline creation.

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::shaders;

/// How a pipeline draws.
pub struct PipelineDesc<'a> {
    /// Vertex shader SPIR-V.
    pub vertex: &'a [u8],
    /// Fragment shader SPIR-V.
    pub fragment: &'a [u8],
    /// Vertex buffer bindings.
    pub bindings: &'a [vk::VertexInputBindingDescription],
    /// Vertex attributes.
    pub attributes: &'a [vk::VertexInputAttributeDescription],
    /// Which faces to cull.
    pub cull: vk::CullModeFlags,
}

/// Creates a pipeline for subpass 0 of `render_pass` with depth test and write, no blending
/// (each layer owns its pixels), and dynamic viewport and scissor.
pub fn create(
    ctx: &GpuContext,
    render_pass: vk::RenderPass,
    layout: vk::PipelineLayout,
    desc: &PipelineDesc,
) -> Result<vk::Pipeline> {
    let device = &ctx.device;
    let vs = module(ctx, desc.vertex)?;
    let fs = match module(ctx, desc.fragment) {
        Ok(fs) => fs,
        Err(e) => {
            unsafe { device.destroy_shader_module(vs, None) };
            return Err(e);
        }
    };
    let stages = [
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vs)
            .name(c"vs_main"),
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(fs)
            .name(c"fs_main"),
    ];
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(desc.bindings)
        .vertex_attribute_descriptions(desc.attributes);
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
        .cull_mode(desc.cull)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(true)
        .depth_write_enable(true)
        .depth_compare_op(vk::CompareOp::LESS);
    let blend_attachments = [vk::PipelineColorBlendAttachmentState::default()
        .blend_enable(false)
        .color_write_mask(vk::ColorComponentFlags::RGBA)];
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
        .layout(layout)
        .render_pass(render_pass)
        .subpass(0);
    let result =
        unsafe { device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    unsafe {
        device.destroy_shader_module(vs, None);
        device.destroy_shader_module(fs, None);
    }
    result
        .map(|p| p[0])
        .map_err(|(_, e)| e)
        .vk("vkCreateGraphicsPipelines")
}

fn module(ctx: &GpuContext, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words = shaders::words(spirv);
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    unsafe { ctx.device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")
}

/// A descriptor set layout from (binding, type, stages) triples.
pub fn set_layout(
    ctx: &GpuContext,
    bindings: &[(u32, vk::DescriptorType, vk::ShaderStageFlags)],
) -> Result<vk::DescriptorSetLayout> {
    let bindings: Vec<_> = bindings
        .iter()
        .map(|&(binding, ty, stages)| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(binding)
                .descriptor_type(ty)
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect();
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
    unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
        .vk("vkCreateDescriptorSetLayout")
}

/// A pipeline layout with one set layout and push constants of `push_size` bytes.
pub fn layout(
    ctx: &GpuContext,
    set_layout: vk::DescriptorSetLayout,
    push_stages: vk::ShaderStageFlags,
    push_size: u32,
) -> Result<vk::PipelineLayout> {
    let set_layouts = [set_layout];
    let ranges = [vk::PushConstantRange {
        stage_flags: push_stages,
        offset: 0,
        size: push_size,
    }];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(&set_layouts)
        .push_constant_ranges(&ranges);
    unsafe { ctx.device.create_pipeline_layout(&info, None) }.vk("vkCreatePipelineLayout")
}

/// A descriptor pool for `sets` sets with the given descriptor counts.
pub fn pool(
    ctx: &GpuContext,
    sets: u32,
    sizes: &[(vk::DescriptorType, u32)],
) -> Result<vk::DescriptorPool> {
    let sizes: Vec<_> = sizes
        .iter()
        .map(|&(ty, descriptor_count)| vk::DescriptorPoolSize {
            ty,
            descriptor_count,
        })
        .collect();
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(sets)
        .pool_sizes(&sizes);
    unsafe { ctx.device.create_descriptor_pool(&info, None) }.vk("vkCreateDescriptorPool")
}

/// Allocates one set of `layout` from `pool`.
pub fn allocate_set(
    ctx: &GpuContext,
    pool: vk::DescriptorPool,
    layout: vk::DescriptorSetLayout,
) -> Result<vk::DescriptorSet> {
    let layouts = [layout];
    let info = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    Ok(unsafe { ctx.device.allocate_descriptor_sets(&info) }.vk("vkAllocateDescriptorSets")?[0])
}

/// Points a sampled-image binding and a sampler binding of `set` at `view` and `sampler`.
pub fn write_texture(
    ctx: &GpuContext,
    set: vk::DescriptorSet,
    image_binding: u32,
    sampler_binding: u32,
    view: vk::ImageView,
    sampler: vk::Sampler,
) {
    let image_info = [vk::DescriptorImageInfo {
        sampler: vk::Sampler::null(),
        image_view: view,
        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    }];
    let sampler_info = [vk::DescriptorImageInfo {
        sampler,
        image_view: vk::ImageView::null(),
        image_layout: vk::ImageLayout::UNDEFINED,
    }];
    let writes = [
        vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(image_binding)
            .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
            .image_info(&image_info),
        vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(sampler_binding)
            .descriptor_type(vk::DescriptorType::SAMPLER)
            .image_info(&sampler_info),
    ];
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
}

/// Points a sampled-image binding of `set` at `view`.
pub fn write_image(ctx: &GpuContext, set: vk::DescriptorSet, binding: u32, view: vk::ImageView) {
    let image_info = [vk::DescriptorImageInfo {
        sampler: vk::Sampler::null(),
        image_view: view,
        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    }];
    let writes = [vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(binding)
        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
        .image_info(&image_info)];
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
}
