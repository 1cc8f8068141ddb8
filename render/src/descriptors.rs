//! Descriptor sets: their layouts, pools and writes, and the sets of a pass that draws with one
//! texture at a time ([`TextureSets`]).

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::owned::Owned;

/// One descriptor set per texture, each holding the texture's view (binding 0) and a sampler
/// (binding 1) for `stages`, with their layout and the pool they live in: for a pass that
/// draws with one texture at a time.
pub struct TextureSets<const N: usize> {
    /// The sets, in the order of the views given.
    pub sets: [vk::DescriptorSet; N],
    /// Their layout.
    pub layout: Owned<vk::DescriptorSetLayout>,
    /// The pool they live in (freed with it).
    _pool: Owned<vk::DescriptorPool>,
}

/// [`TextureSets`] of `views`, each sampled with `sampler`.
pub fn texture_sets<const N: usize>(
    ctx: &GpuContext,
    stages: vk::ShaderStageFlags,
    views: [vk::ImageView; N],
    sampler: vk::Sampler,
) -> Result<TextureSets<N>> {
    let layout = set_layout(
        ctx,
        &[
            (0, vk::DescriptorType::SAMPLED_IMAGE, stages),
            (1, vk::DescriptorType::SAMPLER, stages),
        ],
    )?;
    let n = N as u32;
    let pool = pool(
        ctx,
        n,
        &[
            (vk::DescriptorType::SAMPLED_IMAGE, n),
            (vk::DescriptorType::SAMPLER, n),
        ],
    )?;
    let mut sets = [vk::DescriptorSet::null(); N];
    for (set, view) in sets.iter_mut().zip(views) {
        *set = allocate_set(ctx, pool.raw(), layout.raw())?;
        write_texture(ctx, *set, 0, 1, view, sampler);
    }
    Ok(TextureSets {
        sets,
        layout,
        _pool: pool,
    })
}

/// A descriptor set layout from (binding, type, stages) triples.
pub fn set_layout(
    ctx: &GpuContext,
    bindings: &[(u32, vk::DescriptorType, vk::ShaderStageFlags)],
) -> Result<Owned<vk::DescriptorSetLayout>> {
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
    // SAFETY: `info` and its bindings are valid for the call.
    let layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
        .vk("vkCreateDescriptorSetLayout")?;
    Ok(Owned::new(ctx, layout))
}

/// A descriptor pool for `sets` sets with the given descriptor counts.
pub fn pool(
    ctx: &GpuContext,
    sets: u32,
    sizes: &[(vk::DescriptorType, u32)],
) -> Result<Owned<vk::DescriptorPool>> {
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
    // SAFETY: `info` and its sizes are valid for the call.
    let pool =
        unsafe { ctx.device.create_descriptor_pool(&info, None) }.vk("vkCreateDescriptorPool")?;
    Ok(Owned::new(ctx, pool))
}

/// Allocates one set of `layout` from `pool` (freed with the pool).
pub fn allocate_set(
    ctx: &GpuContext,
    pool: vk::DescriptorPool,
    layout: vk::DescriptorSetLayout,
) -> Result<vk::DescriptorSet> {
    let layouts = [layout];
    let info = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    // SAFETY: the pool and layout are live; the pool is only used from the thread building
    // the pass that owns it.
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
    // SAFETY: the set is not in use by pending GPU work (it is written while its pass is
    // built), and the view and sampler are live.
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
}

/// Points a storage-buffer binding of `set` at the whole of `buffer`.
pub fn write_storage_buffer(
    ctx: &GpuContext,
    set: vk::DescriptorSet,
    binding: u32,
    buffer: vk::Buffer,
) {
    write_buffer(
        ctx,
        set,
        binding,
        vk::DescriptorType::STORAGE_BUFFER,
        buffer,
    );
}

/// Points a uniform-buffer binding of `set` at the whole of `buffer`.
pub fn write_uniform_buffer(
    ctx: &GpuContext,
    set: vk::DescriptorSet,
    binding: u32,
    buffer: vk::Buffer,
) {
    write_buffer(
        ctx,
        set,
        binding,
        vk::DescriptorType::UNIFORM_BUFFER,
        buffer,
    );
}

/// Points a buffer binding of `set`, of `kind`, at the whole of `buffer`.
fn write_buffer(
    ctx: &GpuContext,
    set: vk::DescriptorSet,
    binding: u32,
    kind: vk::DescriptorType,
    buffer: vk::Buffer,
) {
    let info = [vk::DescriptorBufferInfo {
        buffer,
        offset: 0,
        range: vk::WHOLE_SIZE,
    }];
    let writes = [vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(binding)
        .descriptor_type(kind)
        .buffer_info(&info)];
    // SAFETY: as in `write_texture`: the set is idle and the buffer live.
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
    // SAFETY: as in `write_texture`: the set is idle and the view live.
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
}
