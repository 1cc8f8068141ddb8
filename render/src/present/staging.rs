//! A host-visible buffer a picture is written into, and its copy into the window's image.

use ash::vk;

use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use crate::memory::{color_copy_region, layout_barrier, subresource_range};

/// A staging buffer, mapped for as long as it lives. Freed with [`Staging::free`] (it holds
/// no device, so it cannot free itself on drop).
pub(super) struct Staging {
    /// The buffer (null until first sized).
    pub(super) buffer: vk::Buffer,
    /// Its memory.
    memory: vk::DeviceMemory,
    /// The mapped pointer to `memory`.
    mapped: *mut u8,
    /// Bytes in the buffer.
    capacity: u64,
}

impl Staging {
    /// No buffer yet.
    pub(super) const EMPTY: Staging = Staging {
        buffer: vk::Buffer::null(),
        memory: vk::DeviceMemory::null(),
        mapped: std::ptr::null_mut(),
        capacity: 0,
    };

    /// Makes the buffer hold at least `bytes`. No submitted work may use it.
    pub(super) fn ensure(&mut self, ctx: &GpuContext, bytes: u64) -> Result<()> {
        if self.capacity >= bytes {
            return Ok(());
        }
        let d = &ctx.device;
        self.free(d);
        let info = vk::BufferCreateInfo::default()
            .size(bytes)
            .usage(vk::BufferUsageFlags::TRANSFER_SRC)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: a valid create info; stored at once, so `free` releases it on a later error.
        self.buffer = unsafe { d.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        // SAFETY: the buffer is live.
        let needs = unsafe { d.get_buffer_memory_requirements(self.buffer) };
        // SAFETY: the physical device belongs to the context's instance.
        let props = unsafe {
            ctx.instance
                .get_physical_device_memory_properties(ctx.physical)
        };
        let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let type_index = (0..props.memory_type_count)
            .find(|&i| {
                needs.memory_type_bits & (1 << i) != 0
                    && props.memory_types[i as usize]
                        .property_flags
                        .contains(wanted)
            })
            .ok_or_else(|| {
                RenderError::Presentation(
                    "no host-visible coherent memory for the window's staging buffer".into(),
                )
            })?;
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(needs.size)
            .memory_type_index(type_index);
        // SAFETY: a valid allocate info; stored at once; bound to the buffer and mapped whole.
        unsafe {
            self.memory = d.allocate_memory(&alloc, None).vk("vkAllocateMemory")?;
            d.bind_buffer_memory(self.buffer, self.memory, 0)
                .vk("vkBindBufferMemory")?;
            self.mapped = d
                .map_memory(self.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
                .vk("vkMapMemory")?
                .cast();
        }
        self.capacity = bytes;
        Ok(())
    }

    /// The first `bytes` bytes of the mapped buffer.
    ///
    /// # Safety
    /// `bytes` must not exceed what [`Staging::ensure`] was last given, and no submitted work
    /// may read the buffer while the slice lives.
    pub(super) unsafe fn bytes_mut(&mut self, bytes: usize) -> &mut [u8] {
        debug_assert!(bytes as u64 <= self.capacity);
        // SAFETY: the caller's contract: `mapped` points at `capacity` >= `bytes` bytes of
        // host-coherent memory that nothing else uses meanwhile.
        unsafe { std::slice::from_raw_parts_mut(self.mapped, bytes) }
    }

    /// Frees the buffer and its memory, if any; no submitted work may use them.
    pub(super) fn free(&mut self, d: &ash::Device) {
        // SAFETY: the contract above; null handles are ignored by the destroy calls.
        unsafe {
            if self.memory != vk::DeviceMemory::null() {
                d.unmap_memory(self.memory);
            }
            d.destroy_buffer(self.buffer, None);
            d.free_memory(self.memory, None);
        }
        *self = Staging::EMPTY;
    }
}

/// Records the copy of `staging` into the whole `image`, leaving it ready to present.
///
/// # Safety
/// `cmd` must be recording outside a render pass; buffer and image must hold `extent` and
/// outlive the command buffer's execution.
pub(super) unsafe fn record_copy(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    staging: vk::Buffer,
    image: vk::Image,
    extent: vk::Extent2D,
) {
    let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
    let transfer_dst = (
        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        vk::AccessFlags::TRANSFER_WRITE,
    );
    let to_dst = layout_barrier(
        image,
        range,
        (vk::ImageLayout::UNDEFINED, vk::AccessFlags::empty()),
        transfer_dst,
    );
    let region = color_copy_region(0, extent.width, extent.height, 1, 1);
    let to_present = layout_barrier(
        image,
        range,
        transfer_dst,
        (vk::ImageLayout::PRESENT_SRC_KHR, vk::AccessFlags::empty()),
    );
    // SAFETY: the caller's contract.
    unsafe {
        // The acquire semaphore is waited for at TRANSFER, so the layout change happens after
        // the image is available.
        d.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_dst],
        );
        d.cmd_copy_buffer_to_image(
            cmd,
            staging,
            image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
        d.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::BOTTOM_OF_PIPE,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_present],
        );
    }
}
