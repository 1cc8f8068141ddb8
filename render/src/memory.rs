//! Buffers and images backed by the context's allocator, and texture uploads.

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};

/// A buffer and its memory. Free it with [`Buffer::destroy`].
pub struct Buffer {
    /// The Vulkan buffer.
    pub buffer: vk::Buffer,
    /// Its memory; `None` once destroyed.
    allocation: Option<Allocation>,
}

impl Buffer {
    /// Creates a buffer of `size` bytes in `location`.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let device = &ctx.device;
        let info = vk::BufferCreateInfo::default()
            .size(size.max(4))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
        let allocation = ctx
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| {
                unsafe { device.destroy_buffer(buffer, None) };
                RenderError::Allocation {
                    what: name.to_owned(),
                    source,
                }
            })?;
        if let Err(e) =
            unsafe { device.bind_buffer_memory(buffer, allocation.memory(), allocation.offset()) }
        {
            let _ = ctx.allocator().free(allocation);
            unsafe { device.destroy_buffer(buffer, None) };
            return Err(e).vk("vkBindBufferMemory");
        }
        Ok(Buffer {
            buffer,
            allocation: Some(allocation),
        })
    }

    /// A host-visible buffer filled with `bytes`.
    pub fn with_data(
        ctx: &GpuContext,
        name: &str,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Buffer> {
        let mut buffer = Buffer::new(
            ctx,
            name,
            bytes.len() as u64,
            usage,
            MemoryLocation::CpuToGpu,
        )?;
        buffer.mapped_mut()[..bytes.len()].copy_from_slice(bytes);
        Ok(buffer)
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&self) -> &[u8] {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .expect("buffer is host visible")
    }

    /// The mapped bytes of a host-visible buffer, writable.
    pub fn mapped_mut(&mut self) -> &mut [u8] {
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .expect("buffer is host visible")
    }

    /// Frees the buffer.
    ///
    /// # Safety
    /// The GPU must no longer use it.
    pub unsafe fn destroy(&mut self, ctx: &GpuContext) {
        if let Some(allocation) = self.allocation.take() {
            unsafe { ctx.device.destroy_buffer(self.buffer, None) };
            let _ = ctx.allocator().free(allocation);
        }
    }
}

/// An image, its memory and a view of all its layers.
pub struct Image {
    /// The Vulkan image.
    pub image: vk::Image,
    /// A view of the whole image (2-D, or 2-D array when it has several layers).
    pub view: vk::ImageView,
    /// Its memory; `None` once destroyed.
    allocation: Option<Allocation>,
    /// Texel format.
    pub format: vk::Format,
}

impl Image {
    /// Creates a device-local 2-D image (array when `layers > 1`).
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        layers: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Image> {
        Image::with_depth(ctx, name, format, extent, 1, layers, usage)
    }

    /// Creates a device-local image: 3-D when `depth > 1`, else 2-D (array when `layers > 1`).
    pub fn with_depth(
        ctx: &GpuContext,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        depth: u32,
        layers: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Image> {
        let volume = depth > 1;
        let device = &ctx.device;
        let aspect = aspect_of(format);
        let info = vk::ImageCreateInfo::default()
            .image_type(if volume {
                vk::ImageType::TYPE_3D
            } else {
                vk::ImageType::TYPE_2D
            })
            .format(format)
            .extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth,
            })
            .mip_levels(1)
            .array_layers(layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { device.create_image(&info, None) }.vk("vkCreateImage")?;
        let requirements = unsafe { device.get_image_memory_requirements(image) };
        let allocation = ctx
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| {
                unsafe { device.destroy_image(image, None) };
                RenderError::Allocation {
                    what: name.to_owned(),
                    source,
                }
            })?;
        let mut img = Image {
            image,
            view: vk::ImageView::null(),
            allocation: Some(allocation),
            format,
        };
        let bound = {
            let a = img.allocation.as_ref().expect("just allocated");
            unsafe { device.bind_image_memory(image, a.memory(), a.offset()) }
        };
        let view = bound.and_then(|_| {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(if volume {
                    vk::ImageViewType::TYPE_3D
                } else if layers > 1 {
                    vk::ImageViewType::TYPE_2D_ARRAY
                } else {
                    vk::ImageViewType::TYPE_2D
                })
                .format(format)
                .subresource_range(subresource_range(aspect, 0, layers));
            unsafe { device.create_image_view(&view_info, None) }
        });
        match view {
            Ok(view) => {
                img.view = view;
                Ok(img)
            }
            Err(e) => {
                unsafe { img.destroy(ctx) };
                Err(e).vk("vkCreateImageView")
            }
        }
    }

    /// A view of one layer of this image.
    pub fn layer_view(&self, ctx: &GpuContext, layer: u32) -> Result<vk::ImageView> {
        let info = vk::ImageViewCreateInfo::default()
            .image(self.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(self.format)
            .subresource_range(subresource_range(aspect_of(self.format), layer, 1));
        unsafe { ctx.device.create_image_view(&info, None) }.vk("vkCreateImageView")
    }

    /// Frees the image and its view.
    ///
    /// # Safety
    /// The GPU must no longer use it.
    pub unsafe fn destroy(&mut self, ctx: &GpuContext) {
        if let Some(allocation) = self.allocation.take() {
            unsafe {
                if self.view != vk::ImageView::null() {
                    ctx.device.destroy_image_view(self.view, None);
                }
                ctx.device.destroy_image(self.image, None);
            }
            let _ = ctx.allocator().free(allocation);
        }
    }
}

/// Uploads a sampled 2-D texture (one layer, one mip level) and leaves it in
/// SHADER_READ_ONLY_OPTIMAL.
pub fn upload_texture(
    ctx: &GpuContext,
    name: &str,
    format: vk::Format,
    extent: vk::Extent2D,
    bytes: &[u8],
) -> Result<Image> {
    upload_volume(ctx, name, format, extent, 1, bytes)
}

/// Uploads a sampled texture of `depth` slices (3-D when `depth > 1`), slices consecutive in
/// `bytes`, and leaves it in SHADER_READ_ONLY_OPTIMAL.
pub fn upload_volume(
    ctx: &GpuContext,
    name: &str,
    format: vk::Format,
    extent: vk::Extent2D,
    depth: u32,
    bytes: &[u8],
) -> Result<Image> {
    let mut staging = Buffer::with_data(ctx, name, bytes, vk::BufferUsageFlags::TRANSFER_SRC)?;
    let image = Image::with_depth(
        ctx,
        name,
        format,
        extent,
        depth,
        1,
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    );
    let mut image = match image {
        Ok(image) => image,
        Err(e) => {
            unsafe { staging.destroy(ctx) };
            return Err(e);
        }
    };
    let device = &ctx.device;
    let result = ctx.one_shot(|cmd| unsafe {
        let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
        let to_dst = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::empty())
            .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.image)
            .subresource_range(range);
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TOP_OF_PIPE,
            vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_dst],
        );
        let region = vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth,
            });
        device.cmd_copy_buffer_to_image(
            cmd,
            staging.buffer,
            image.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
        let to_read = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::SHADER_READ)
            .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .new_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.image)
            .subresource_range(range);
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::FRAGMENT_SHADER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_read],
        );
    });
    unsafe { staging.destroy(ctx) };
    if let Err(e) = result {
        unsafe { image.destroy(ctx) };
        return Err(e);
    }
    Ok(image)
}

/// The aspect of a format: depth for depth formats, colour otherwise.
pub fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32 => {
            vk::ImageAspectFlags::DEPTH
        }
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// A subresource range of `count` layers from `base`, one mip level.
pub fn subresource_range(
    aspect: vk::ImageAspectFlags,
    base: u32,
    count: u32,
) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: base,
        layer_count: count,
    }
}
