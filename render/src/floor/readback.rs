//! Copying the floor fields back to the CPU, for tests and debugging.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::fields::{DISTANCE, GAIN, InducerFields, MASK, READBACK_BYTES_PER_TEXEL};
use super::pass::InducerPass;
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Buffer, layout_barrier, subresource_range};
use crate::scene::GpuScene;

impl InducerPass {
    /// Computes the fields if no submitted work has, draws the distance field (frames do not:
    /// [`InducerPass::record_distance`]), then copies the mask, the distance field and the
    /// gain back to the CPU. Waits for the GPU (at most the fence timeout).
    pub fn read_back(&mut self, ctx: &GpuContext, scene: &GpuScene) -> Result<InducerFields> {
        let n = self.desc.resolution_px;
        let texels = u64::from(n) * u64::from(n);
        // Distance (4 bytes), gain (2), mask (1) per texel, one after another: each copy
        // starts at a multiple of its texel's size, whatever the side.
        let offsets = [(DISTANCE, 0), (GAIN, 4 * texels), (MASK, 6 * texels)];
        let buffer = Buffer::new(
            ctx,
            "inducer readback",
            READBACK_BYTES_PER_TEXEL * texels,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let mut prepared = self.progress.plan();
        let this = &*self;
        let d = &ctx.device;
        // SAFETY: one_shot records outside a render pass and waits for the work (on a timeout
        // the buffer is leaked below); the images are in SHADER_READ_ONLY_OPTIMAL after their
        // render passes (or the fields' recording just before), and are put back there.
        let result = ctx.one_shot(|cmd| unsafe {
            if prepared.fields {
                // The live caustic map with them: the pose's work counts as done after this.
                prepared.fields_within = this.record_pose_work(ctx, cmd, scene, None);
            }
            this.record_distance(ctx, cmd);
            this.record_copies(d, cmd, &offsets, &buffer);
        });
        if let Err(e) = result {
            if e.gpu_may_still_run() {
                std::mem::forget(buffer);
            }
            return Err(e);
        }
        self.submitted(prepared);
        self.finished(prepared, true);
        Ok(InducerFields::decode(
            buffer.mapped()?,
            n,
            self.texel_m,
            self.rect,
        ))
    }

    /// Records the copies of the fields at `offsets` into `buffer`, made visible to the host.
    ///
    /// # Safety
    /// `cmd` must be recording outside a render pass, after every write of the fields, which
    /// must be in SHADER_READ_ONLY_OPTIMAL; `buffer` must hold the copies and outlive the
    /// execution.
    unsafe fn record_copies(
        &self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        offsets: &[(usize, u64)],
        buffer: &Buffer,
    ) {
        let n = self.desc.resolution_px;
        let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
        let barrier = |image: usize, old, new, src_access, dst_access| {
            let image = self.targets[image].image.image;
            layout_barrier(image, range, (old, src_access), (new, dst_access))
        };
        let to_copy: Vec<_> = offsets
            .iter()
            .map(|&(image, _)| {
                barrier(
                    image,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                    vk::AccessFlags::TRANSFER_READ,
                )
            })
            .collect();
        let back: Vec<_> = offsets
            .iter()
            .map(|&(image, _)| {
                barrier(
                    image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::AccessFlags::empty(),
                    vk::AccessFlags::SHADER_READ,
                )
            })
            .collect();
        let to_host = [vk::BufferMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(buffer.buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE)];
        // SAFETY: the caller's contract; the barriers move exactly the copied images from and
        // back to the layout they are in, and the regions lie inside images and buffer.
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::FRAGMENT_SHADER,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &to_copy,
            );
            for &(image, offset) in offsets {
                let region = crate::memory::color_copy_region(offset, n, n, 1, 1);
                d.cmd_copy_image_to_buffer(
                    cmd,
                    self.targets[image].image.image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.buffer,
                    &[region],
                );
            }
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[],
                &to_host,
                &back,
            );
        }
    }
}
