//! Copying swapchain images into host memory on the app's own Vulkan device and queue (the
//! session's `XrGraphicsBindingVulkanKHR`), for the record of what the app submits
//! ([`crate::images`]).

use ash::vk::{self, Handle};

/// The Vulkan objects of a session, as the app gave them in `XrGraphicsBindingVulkanKHR`.
#[derive(Clone, Copy, Debug)]
pub struct VulkanBinding {
    /// `VkInstance`.
    pub instance: u64,
    /// `VkPhysicalDevice`.
    pub physical_device: u64,
    /// `VkDevice`.
    pub device: u64,
    /// The queue the app submits on.
    pub queue_family: u32,
    /// Its index in the family.
    pub queue_index: u32,
}

/// Copies swapchain images into host memory on the app's device and queue; its objects are
/// freed on drop.
pub struct Reader {
    device: ash::Device,
    queue: vk::Queue,
    memory_types: vk::PhysicalDeviceMemoryProperties,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// The host-visible buffer the copies go to, and its memory and size.
    staging: Option<(vk::Buffer, vk::DeviceMemory, u64)>,
    /// Keeps the Vulkan library loaded while the function pointers above are used.
    _entry: ash::Entry,
}

impl Reader {
    /// Makes the reader's command pool, command buffer and fence on `binding`'s device.
    ///
    /// # Safety
    /// `binding` must hold the live instance, physical device and device the app created the
    /// session with, the device made with a queue of that family and index.
    pub unsafe fn new(binding: &VulkanBinding) -> Result<Reader, String> {
        // SAFETY: loading the system's Vulkan loader, already loaded by the app.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("loading Vulkan: {e}"))?;
        let instance_handle = vk::Instance::from_raw(binding.instance);
        // SAFETY: the caller's guarantee: a live instance of this loader.
        let instance = unsafe { ash::Instance::load(entry.static_fn(), instance_handle) };
        // SAFETY: a live device of that instance (caller's guarantee).
        let device =
            unsafe { ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(binding.device)) };
        let physical = vk::PhysicalDevice::from_raw(binding.physical_device);
        // SAFETY: the app's physical device of that instance.
        let memory_types = unsafe { instance.get_physical_device_memory_properties(physical) };
        // SAFETY: the device was created with this queue (caller's guarantee).
        let queue = unsafe { device.get_device_queue(binding.queue_family, binding.queue_index) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(binding.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: a valid create info on a live device.
        let pool = unsafe { device.create_command_pool(&pool_info, None) }
            .map_err(|e| format!("vkCreateCommandPool: {e}"))?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool just made; one buffer asked for.
        let cmd = match unsafe { device.allocate_command_buffers(&alloc) } {
            Ok(b) => b[0],
            Err(e) => {
                // SAFETY: the pool just made, unused.
                unsafe { device.destroy_command_pool(pool, None) };
                return Err(format!("vkAllocateCommandBuffers: {e}"));
            }
        };
        // SAFETY: a valid create info on a live device.
        let fence = match unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) } {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: the pool just made, its buffer never submitted.
                unsafe { device.destroy_command_pool(pool, None) };
                return Err(format!("vkCreateFence: {e}"));
            }
        };
        Ok(Reader {
            device,
            queue,
            memory_types,
            pool,
            cmd,
            fence,
            staging: None,
            _entry: entry,
        })
    }

    /// A host-visible, coherent buffer of at least `size` bytes.
    fn staging(&mut self, size: u64) -> Result<(vk::Buffer, vk::DeviceMemory), String> {
        if let Some((buffer, memory, have)) = self.staging
            && have >= size
        {
            return Ok((buffer, memory));
        }
        self.free_staging();
        let d = &self.device;
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(vk::BufferUsageFlags::TRANSFER_DST)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: a valid create info on the live device.
        let buffer =
            unsafe { d.create_buffer(&info, None) }.map_err(|e| format!("vkCreateBuffer: {e}"))?;
        // SAFETY: the buffer just made.
        let needs = unsafe { d.get_buffer_memory_requirements(buffer) };
        let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let types = &self.memory_types;
        let Some(index) = (0..types.memory_type_count).find(|&i| {
            needs.memory_type_bits & (1 << i) != 0
                && types.memory_types[i as usize]
                    .property_flags
                    .contains(wanted)
        }) else {
            // SAFETY: the buffer just made, unbound.
            unsafe { d.destroy_buffer(buffer, None) };
            return Err("no host-visible coherent memory for the readback".into());
        };
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(needs.size)
            .memory_type_index(index);
        // SAFETY: a valid allocation on the live device.
        let memory = match unsafe { d.allocate_memory(&alloc, None) } {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: the buffer just made, unbound.
                unsafe { d.destroy_buffer(buffer, None) };
                return Err(format!("vkAllocateMemory: {e}"));
            }
        };
        // SAFETY: the memory fits the buffer's requirements; neither is bound yet.
        if let Err(e) = unsafe { d.bind_buffer_memory(buffer, memory, 0) } {
            // SAFETY: both just made and unused.
            unsafe {
                d.destroy_buffer(buffer, None);
                d.free_memory(memory, None);
            }
            return Err(format!("vkBindBufferMemory: {e}"));
        }
        self.staging = Some((buffer, memory, size));
        Ok((buffer, memory))
    }

    fn free_staging(&mut self) {
        if let Some((buffer, memory, _)) = self.staging.take() {
            // SAFETY: every copy into it was waited for (`read` waits on its fence).
            unsafe {
                self.device.destroy_buffer(buffer, None);
                self.device.free_memory(memory, None);
            }
        }
    }

    /// Every array layer of `image` (`width` x `height`, 4 bytes a texel), row by row.
    ///
    /// # Safety
    /// `image` must be a live image of the app's device with `layers` array layers, made with
    /// transfer-source usage, in `COLOR_ATTACHMENT_OPTIMAL` (as the app releases it) with the
    /// commands writing it submitted to the binding's queue, which no other thread uses during
    /// the call.
    pub unsafe fn read(
        &mut self,
        image: vk::Image,
        width: u32,
        height: u32,
        layers: u32,
    ) -> Result<Vec<Vec<u8>>, String> {
        let layer_bytes = u64::from(width) * u64::from(height) * 4;
        let (buffer, memory) = self.staging(layer_bytes * u64::from(layers))?;
        let d = &self.device;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: layers,
        };
        let to_source = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ)
            .old_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range);
        let back = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_READ)
            .dst_access_mask(
                vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
            )
            .old_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range);
        let to_host = vk::BufferMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE);
        let regions: Vec<vk::BufferImageCopy> = (0..layers)
            .map(|layer| vk::BufferImageCopy {
                buffer_offset: layer_bytes * u64::from(layer),
                buffer_row_length: 0,
                buffer_image_height: 0,
                image_subresource: vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: layer,
                    layer_count: 1,
                },
                image_offset: vk::Offset3D::default(),
                image_extent: vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                },
            })
            .collect();
        // SAFETY: the command buffer is not pending (every submission of it was waited for);
        // the image is as the caller guarantees, the buffer large enough for every region;
        // the queue is used by this thread alone during the call (caller's guarantee).
        unsafe {
            d.begin_command_buffer(
                self.cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
            .map_err(|e| format!("vkBeginCommandBuffer: {e}"))?;
            d.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[to_source],
            );
            d.cmd_copy_image_to_buffer(
                self.cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer,
                &regions,
            );
            d.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[],
                &[to_host],
                &[back],
            );
            d.end_command_buffer(self.cmd)
                .map_err(|e| format!("vkEndCommandBuffer: {e}"))?;
            let cmds = [self.cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            d.queue_submit(self.queue, &[submit], self.fence)
                .map_err(|e| format!("vkQueueSubmit: {e}"))?;
            d.wait_for_fences(&[self.fence], true, u64::MAX)
                .map_err(|e| format!("vkWaitForFences: {e}"))?;
            d.reset_fences(&[self.fence])
                .map_err(|e| format!("vkResetFences: {e}"))?;
        }
        let total = usize::try_from(layer_bytes * u64::from(layers)).map_err(|e| e.to_string())?;
        // SAFETY: host-visible memory bound to the buffer, not mapped elsewhere; the copy into
        // it finished (fence) and was made visible to the host (barrier).
        let bytes = unsafe {
            let p = d
                .map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
                .map_err(|e| format!("vkMapMemory: {e}"))?;
            let copied = std::slice::from_raw_parts(p as *const u8, total).to_vec();
            d.unmap_memory(memory);
            copied
        };
        Ok(bytes
            .chunks_exact(layer_bytes as usize)
            .map(<[u8]>::to_vec)
            .collect())
    }
}

impl Drop for Reader {
    fn drop(&mut self) {
        self.free_staging();
        // SAFETY: the command buffer's submissions were all waited for; the pool and fence are
        // the reader's own.
        unsafe {
            self.device.destroy_fence(self.fence, None);
            self.device.destroy_command_pool(self.pool, None);
        }
    }
}
