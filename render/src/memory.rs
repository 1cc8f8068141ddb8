//! Buffers and images backed by the context's allocator, and texture uploads.
//!
//! A [`Buffer`] or [`Image`] owns its Vulkan object and its memory and frees both on drop,
//! so a constructor that fails part way gives back what it made by returning early. The
//! memory keeps a shared handle to the allocator; the context drops its own handle (and with
//! it, normally, the allocator) just before the device.

use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};

use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use crate::owned::Owned;

/// Memory of a buffer or image, handed back to the context's allocator on drop.
struct Memory {
    /// The allocator it came from (shared with the context, which frees it before the
    /// device).
    allocator: Arc<Mutex<Allocator>>,
    /// The allocation; `None` only during drop.
    allocation: Option<Allocation>,
}

impl Memory {
    /// Allocates memory for `requirements` in `location`.
    fn new(
        ctx: &GpuContext,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Memory> {
        ctx.check_injected_failure(name)?;
        let allocator = ctx.shared_allocator();
        let allocation = lock(&allocator)
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| RenderError::Allocation {
                what: name.to_owned(),
                source,
            })?;
        Ok(Memory {
            allocator,
            allocation: Some(allocation),
        })
    }

    /// The allocation.
    fn get(&self) -> &Allocation {
        self.allocation
            .as_ref()
            .expect("allocation lives until drop")
    }

    /// The allocation, writable.
    fn get_mut(&mut self) -> &mut Allocation {
        self.allocation
            .as_mut()
            .expect("allocation lives until drop")
    }
}

impl Drop for Memory {
    fn drop(&mut self) {
        if let Some(allocation) = self.allocation.take() {
            // Freeing only fails for an allocation the allocator does not know, which cannot
            // happen for one it handed out; nothing useful to do about it in a drop.
            let _ = lock(&self.allocator).free(allocation);
        }
    }
}

/// Locks the allocator, recovering from a poisoned lock (the allocator's state stays
/// consistent: a panic inside it would already have aborted the allocation).
fn lock(allocator: &Mutex<Allocator>) -> std::sync::MutexGuard<'_, Allocator> {
    allocator
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A buffer and its memory, both freed on drop.
pub struct Buffer {
    /// The Vulkan buffer.
    pub buffer: vk::Buffer,
    /// Its memory, freed right after the buffer is destroyed; `None` until bound.
    memory: Option<Memory>,
    /// The device the buffer was made on.
    device: ash::Device,
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
        // SAFETY: `info` is a valid create info; the buffer is owned by the `Buffer` below
        // from the next statement on, whose drop destroys it.
        let buffer = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let mut owned = Buffer {
            buffer,
            memory: None,
            device: device.clone(),
        };
        // SAFETY: `buffer` is a live buffer of `device`.
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
        let memory = Memory::new(ctx, name, requirements, location, true)?;
        let a = memory.get();
        // SAFETY: the memory was allocated for this buffer's requirements and is not bound
        // to anything else; the buffer has no memory bound yet.
        unsafe { device.bind_buffer_memory(buffer, a.memory(), a.offset()) }
            .vk("vkBindBufferMemory")?;
        owned.memory = Some(memory);
        Ok(owned)
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
        buffer.mapped_mut()?[..bytes.len()].copy_from_slice(bytes);
        Ok(buffer)
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&self) -> Result<&[u8]> {
        self.memory
            .as_ref()
            .and_then(|m| m.get().mapped_slice())
            .ok_or_else(|| not_mapped("read"))
    }

    /// The mapped bytes of a host-visible buffer, writable.
    pub fn mapped_mut(&mut self) -> Result<&mut [u8]> {
        self.memory
            .as_mut()
            .and_then(|m| m.get_mut().mapped_slice_mut())
            .ok_or_else(|| not_mapped("written"))
    }
}

/// The error for a buffer that is not host visible (an internal mistake, reported rather
/// than panicking).
fn not_mapped(how: &str) -> RenderError {
    RenderError::InvalidInput(format!(
        "a GPU-only buffer was {how} from the CPU; it must be host visible"
    ))
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the buffer was made on `device`; its owner drops it only when no GPU work
        // uses it any more (see crate::owned), and before the context's device. The memory is
        // freed afterwards, when `memory` drops.
        unsafe { self.device.destroy_buffer(self.buffer, None) };
        self.memory.take();
    }
}

/// An image, its memory and a view of all its layers, all freed on drop.
pub struct Image {
    /// The Vulkan image.
    pub image: vk::Image,
    /// A view of the whole image (2-D, or 2-D array when it has several layers).
    pub view: vk::ImageView,
    /// Its memory; `None` until bound.
    memory: Option<Memory>,
    /// Texel format.
    pub format: vk::Format,
    /// The device the image was made on.
    device: ash::Device,
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
        // SAFETY: `info` is a valid create info; the image is owned by the `Image` below from
        // the next statement on, whose drop destroys it.
        let image = unsafe { device.create_image(&info, None) }.vk("vkCreateImage")?;
        let mut owned = Image {
            image,
            view: vk::ImageView::null(),
            memory: None,
            format,
            device: device.clone(),
        };
        // SAFETY: `image` is a live image of `device`.
        let requirements = unsafe { device.get_image_memory_requirements(image) };
        let memory = Memory::new(ctx, name, requirements, MemoryLocation::GpuOnly, false)?;
        let a = memory.get();
        // SAFETY: the memory was allocated for this image's requirements and is bound to
        // nothing else; the image has no memory bound yet.
        unsafe { device.bind_image_memory(image, a.memory(), a.offset()) }
            .vk("vkBindImageMemory")?;
        owned.memory = Some(memory);
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
        // SAFETY: the image is live and bound to memory; the view covers its layers and is
        // destroyed by the image's drop.
        owned.view =
            unsafe { device.create_image_view(&view_info, None) }.vk("vkCreateImageView")?;
        Ok(owned)
    }

    /// A view of one layer of this image, owned by the caller (it must drop before the
    /// image).
    pub(crate) fn layer_view(&self, ctx: &GpuContext, layer: u32) -> Result<Owned<vk::ImageView>> {
        let info = vk::ImageViewCreateInfo::default()
            .image(self.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(self.format)
            .subresource_range(subresource_range(aspect_of(self.format), layer, 1));
        // SAFETY: the image is live and bound to memory; `layer` is checked by validation
        // against its layer count; the view is owned (and destroyed) by the returned value.
        let view = unsafe { ctx.device.create_image_view(&info, None) }.vk("vkCreateImageView")?;
        Ok(Owned::new(ctx, view))
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: the view and image were made on `device`; the owner drops the image only
        // when no GPU work uses it any more (see crate::owned), and before the context's
        // device. Null views (a failed construction) are ignored by Vulkan.
        unsafe {
            self.device.destroy_image_view(self.view, None);
            self.device.destroy_image(self.image, None);
        }
        self.memory.take();
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
    let staging = Buffer::with_data(ctx, name, bytes, vk::BufferUsageFlags::TRANSFER_SRC)?;
    let image = Image::with_depth(
        ctx,
        name,
        format,
        extent,
        depth,
        1,
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    )?;
    let device = &ctx.device;
    // SAFETY: `cmd` is recording outside a render pass (one_shot's contract); the staging
    // buffer and the image are live and outlive the submission (one_shot waits for it, and
    // on a timeout both are leaked below rather than freed under the GPU); the image is in
    // UNDEFINED layout, as the first barrier says.
    let result = ctx.one_shot(|cmd| unsafe {
        let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
        let to_dst = layout_barrier(
            image.image,
            range,
            (vk::ImageLayout::UNDEFINED, vk::AccessFlags::empty()),
            (
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::TRANSFER_WRITE,
            ),
        );
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TOP_OF_PIPE,
            vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_dst],
        );
        let region = color_copy_region(0, extent.width, extent.height, depth, 1);
        device.cmd_copy_buffer_to_image(
            cmd,
            staging.buffer,
            image.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
        let to_read = layout_barrier(
            image.image,
            range,
            (
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::TRANSFER_WRITE,
            ),
            (
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                vk::AccessFlags::SHADER_READ,
            ),
        );
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
    match result {
        Ok(()) => Ok(image),
        Err(e) => {
            if e.gpu_may_still_run() {
                // The copy may still be running: leaking is the only sound choice.
                std::mem::forget(staging);
                std::mem::forget(image);
            }
            Err(e)
        }
    }
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

/// Records a global memory barrier: the accesses `src` of the stages `src_stage` before the
/// accesses `dst` of the stages `dst_stage`.
///
/// # Safety
/// `cmd` must be recording outside any render pass.
pub unsafe fn memory_barrier(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    (src_stage, src): (vk::PipelineStageFlags, vk::AccessFlags),
    (dst_stage, dst): (vk::PipelineStageFlags, vk::AccessFlags),
) {
    let memory = [vk::MemoryBarrier::default()
        .src_access_mask(src)
        .dst_access_mask(dst)];
    // SAFETY: the caller's contract; the barrier holds no handles.
    unsafe {
        d.cmd_pipeline_barrier(
            cmd,
            src_stage,
            dst_stage,
            vk::DependencyFlags::empty(),
            &memory,
            &[],
            &[],
        )
    };
}

/// A layout transition of `range` of `image` for `vkCmdPipelineBarrier`: from `old` after
/// accesses `src` to `new` before accesses `dst`, on one queue (no ownership transfer).
pub fn layout_barrier(
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    (old, src): (vk::ImageLayout, vk::AccessFlags),
    (new, dst): (vk::ImageLayout, vk::AccessFlags),
) -> vk::ImageMemoryBarrier<'static> {
    vk::ImageMemoryBarrier::default()
        .src_access_mask(src)
        .dst_access_mask(dst)
        .old_layout(old)
        .new_layout(new)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(range)
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

/// The copy region between a buffer (from byte `offset`, tightly packed) and the first `layers`
/// array layers of mip 0 of a colour image of `width` x `height` x `depth` texels.
pub fn color_copy_region(
    offset: u64,
    width: u32,
    height: u32,
    depth: u32,
    layers: u32,
) -> vk::BufferImageCopy {
    vk::BufferImageCopy::default()
        .buffer_offset(offset)
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: layers,
        })
        .image_extent(vk::Extent3D {
            width,
            height,
            depth,
        })
}
