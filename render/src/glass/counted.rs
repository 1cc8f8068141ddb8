//! The positions inside its pixels that the glass shades, counted on the device: where it shades
//! a ball's light in the room in two parts, each over as many positions as it needs (the
//! environment looks of a ball in the room over several positions per pixel:
//! shaders/shared/glass_positions.wgsl), the frames that count their work draw with the same
//! pipelines compiled with `COUNTED`, whose fragments add their positions and themselves to the
//! frame slot's counters with integer atomics. Ordinary frames draw with the pipelines without
//! them, which neither pay for the atomics nor read the buffer.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::{GlassPass, Pick};
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Buffer, memory_barrier};
use crate::renderer::PIPELINE_DEPTH;
use crate::shaders;
use crate::work::GlassPositions;

/// Bytes of one frame slot's counters: the positions of the rest of the light, those of the
/// first image, the pixels that shaded them, and a word unused (`u32` each).
const SLOT_BYTES: u64 = 16;

/// The counters, four words per frame slot, in memory the host reads once the frame finished.
pub(super) struct PositionCounter {
    buffer: Buffer,
}

impl PositionCounter {
    pub(super) fn new(ctx: &GpuContext) -> Result<PositionCounter> {
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let buffer = Buffer::new(
            ctx,
            "glass positions' counters",
            SLOT_BYTES * PIPELINE_DEPTH as u64,
            usage,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(PositionCounter { buffer })
    }

    pub(super) fn buffer(&self) -> vk::Buffer {
        self.buffer.buffer
    }
}

impl GlassPass {
    /// From now on, draws the pipelines that shade a ball's light in two parts with their
    /// counting twins (made here, once), so that [`GlassPass::read_positions`] reads what a
    /// frame shaded. Nothing to do for a scene without such pipelines or on a device whose
    /// fragment shaders cannot use atomics.
    pub fn count_positions(&mut self, ctx: &GpuContext) -> Result<()> {
        let (Some(row), true) = (self.counted_row, ctx.fragment_atomics) else {
            return Ok(());
        };
        if !self.counted_pipelines.is_empty() {
            return Ok(());
        }
        // The environment looks (the background looks shade every position whole), fresnel then
        // Phong, then with compensation the same two again.
        let compensated: &[usize] = if self.compensation.is_some() {
            &[0, 1]
        } else {
            &[0]
        };
        self.counted_pipelines = compensated
            .iter()
            .flat_map(|&c| (0..2).map(move |phong| (c, phong)))
            .map(|(c, phong)| self.create_pipeline(ctx, shaders::GLASS_FS_COUNTED[c][row][phong]))
            .collect::<Result<Vec<_>>>()?;
        Ok(())
    }

    /// The counting pipeline that draws `pick` in place of its own, where the frames count.
    pub(super) fn counted_pipeline(&self, pick: Pick) -> Option<vk::Pipeline> {
        let compensated = pick.compensated && self.compensation.is_some();
        let index = usize::from(compensated) * 2 + usize::from(pick.variant.phong);
        (!pick.covered && !pick.variant.background && !self.counted_pipelines.is_empty())
            .then(|| self.counted_pipelines[index].raw())
    }

    /// What a frame that draws `pick` counts, where a counting pipeline draws it: the static
    /// costs of a whole position and of a first image ([`GlassPositions`]), the counts 0 until
    /// [`GlassPass::read_positions`].
    pub fn counted_positions(&self, pick: Pick) -> Option<GlassPositions> {
        let row = self.counted_row?;
        self.counted_pipeline(pick).map(|_| GlassPositions {
            each: shaders::GLASS_PART_COST[row][1 + usize::from(pick.variant.phong)],
            each_first_image: shaders::GLASS_PART_COST[row][0],
            ..GlassPositions::default()
        })
    }

    /// Records, before a frame's eye passes, the clearing of slot `slot`'s counters (where the
    /// frames count).
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; the slot's previous frame finished.
    pub unsafe fn record_clear(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, slot: usize) {
        if self.counted_pipelines.is_empty() {
            return;
        }
        let d = &ctx.device;
        // SAFETY: the caller's contract (outside a render pass); the range lies in the buffer,
        // made with TRANSFER_DST, its offset and size multiples of 4.
        unsafe {
            d.cmd_fill_buffer(
                cmd,
                self.counter.buffer(),
                slot as u64 * SLOT_BYTES,
                SLOT_BYTES,
                0,
            );
            memory_barrier(
                d,
                cmd,
                (
                    vk::PipelineStageFlags::TRANSFER,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
                (
                    vk::PipelineStageFlags::FRAGMENT_SHADER,
                    vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                ),
            );
        }
    }

    /// Records, after a frame's eye passes, what makes its counts visible to the host (where
    /// the frames count).
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass.
    pub unsafe fn record_counted(&self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        if self.counted_pipelines.is_empty() {
            return;
        }
        // SAFETY: the caller's contract (outside a render pass).
        unsafe {
            memory_barrier(
                &ctx.device,
                cmd,
                (
                    vk::PipelineStageFlags::FRAGMENT_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
        }
    }

    /// What the frame of slot `slot` shaded with a counting pipeline, once it finished:
    /// `counted` ([`GlassPass::counted_positions`]) with the device's counts.
    pub fn read_positions(&self, slot: usize, counted: GlassPositions) -> Result<GlassPositions> {
        let bytes = self.counter.buffer.mapped()?;
        let at = slot * SLOT_BYTES as usize;
        let word = |i: usize| {
            let w = &bytes[at + 4 * i..at + 4 * i + 4];
            u64::from(u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        };
        Ok(GlassPositions {
            shaded: word(0),
            first_images: word(1),
            pixels: word(2),
            ..counted
        })
    }
}
