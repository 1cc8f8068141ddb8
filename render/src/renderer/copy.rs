//! Copying a frame's layered images into its host-visible readback buffer.

use ash::vk;

/// Records copies of both layers of each `(image, offset)` (in TRANSFER_SRC_OPTIMAL,
/// `extent` per layer, RGBA8) to `offset` bytes into `buffer`, one layer after the other,
/// and makes the copies visible to host reads.
///
/// # Safety
/// `cmd` must be recording outside any render pass; the images must be in
/// TRANSFER_SRC_OPTIMAL when the copies execute, and they and `buffer` (large enough) must
/// outlive the execution.
pub(super) unsafe fn record_readback(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    copies: &[(vk::Image, u64)],
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    // SAFETY: the caller's contract.
    unsafe {
        for &(image, offset) in copies {
            let region =
                crate::memory::color_copy_region(offset, extent.width, extent.height, 1, 2);
            d.cmd_copy_image_to_buffer(
                cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer,
                &[region],
            );
        }
        let to_host = vk::BufferMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE);
        d.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[],
            &[to_host],
            &[],
        );
    }
}
