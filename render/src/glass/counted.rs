//! The positions inside its pixels that the glass shades, counted on the device: where it shades
//! a ball's light in the room in two parts, each over as many positions as it needs (the
//! environment looks of a ball in the room over several positions per pixel:
//! shaders/shared/glass_positions.wgsl), the frames that count their work draw with the same
//! pipelines compiled with `COUNTED`, whose fragments add their positions and themselves to the
//! frame slot's counters with integer atomics. Ordinary frames draw with the pipelines without
//! them, which neither pay for the atomics nor read the buffer. The same for an object whose exit
//! is searched among its triangles (any look of a mesh that is neither a ball nor a convex gem):
//! its counting pipelines add the nodes and triangles its searches visited and tested
//! (shaders/glass.wgsl `mesh_hit`) and the fragment.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::{GlassPass, Pick};
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Buffer, memory_barrier};
use crate::renderer::PIPELINE_DEPTH;
use crate::shaders;
use crate::work::{GlassPositions, MeshSearch};

/// Bytes of one frame slot's counters: the positions of the rest of the light, those of the
/// first image, the pixels that shaded them, and a word unused (`u32` each); for a mesh, the
/// nodes visited, the triangles tested, the fragments, and the positions they shaded.
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
    /// From now on, draws the pipelines that shade a ball's light in two parts, or that search a
    /// mesh's triangles, with their counting twins (made here, once), so that
    /// [`GlassPass::read_positions`] and [`GlassPass::read_mesh`] read what a frame shaded.
    /// Nothing to do for a scene without such pipelines or on a device whose fragment shaders
    /// cannot use atomics.
    pub fn count_positions(&mut self, ctx: &GpuContext) -> Result<()> {
        if !ctx.fragment_atomics || !self.counted_pipelines.is_empty() {
            return Ok(());
        }
        let compensated: &[usize] = if self.compensation.is_some() {
            &[0, 1]
        } else {
            &[0]
        };
        let entries: Vec<shaders::GlassEntry> = match (self.counted_row, self.mesh_row) {
            // A ball's environment looks (the background looks shade every position whole),
            // fresnel then Phong, then with compensation the same two again.
            (Some(row), _) => compensated
                .iter()
                .flat_map(|&c| (0..2).map(move |phong| shaders::GLASS_FS_COUNTED[c][row][phong]))
                .collect(),
            // A mesh's every look, then with compensation the same four again.
            (None, Some(row)) => compensated
                .iter()
                .flat_map(|&c| shaders::GLASS_FS_MESH_COUNTED[c][row])
                .collect(),
            (None, None) => return Ok(()),
        };
        self.counted_pipelines = entries
            .into_iter()
            .map(|entry| self.create_pipeline(ctx, entry, self.proxy.is_some()))
            .collect::<Result<Vec<_>>>()?;
        Ok(())
    }

    /// The counting pipeline that draws `pick` in place of its own, where the frames count.
    pub(super) fn counted_pipeline(&self, pick: Pick) -> Option<vk::Pipeline> {
        if self.counted_pipelines.is_empty() || pick.covered {
            return None;
        }
        let compensated = usize::from(pick.compensated && self.compensation.is_some());
        if self.mesh_row.is_some() {
            let index = compensated * 4 + pick.variant.index();
            return Some(self.counted_pipelines[index].raw());
        }
        let index = compensated * 2 + usize::from(pick.variant.phong);
        (!pick.variant.background).then(|| self.counted_pipelines[index].raw())
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

    /// What a frame that draws `pick` counts of a mesh's searches, where a counting pipeline
    /// draws it: the static costs of a node and a triangle ([`MeshSearch`]), the counts 0 until
    /// [`GlassPass::read_mesh`].
    pub fn counted_mesh(&self, pick: Pick) -> Option<MeshSearch> {
        self.mesh_row?;
        self.counted_pipeline(pick).map(|_| MeshSearch {
            each_node: shaders::GLASS_MESH_COST[0],
            each_triangle: shaders::GLASS_MESH_COST[1],
            ..MeshSearch::default()
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
        let [shaded, first_images, pixels, _] = self.read_slot(slot)?;
        Ok(GlassPositions {
            shaded,
            first_images,
            pixels,
            ..counted
        })
    }

    /// What the frame of slot `slot` searched with a counting pipeline, once it finished:
    /// `counted` ([`GlassPass::counted_mesh`]) with the device's counts.
    pub fn read_mesh(&self, slot: usize, counted: MeshSearch) -> Result<MeshSearch> {
        let [nodes, triangles, fragments, positions] = self.read_slot(slot)?;
        Ok(MeshSearch {
            nodes,
            triangles,
            fragments,
            positions,
            ..counted
        })
    }

    /// The four counters of slot `slot`.
    fn read_slot(&self, slot: usize) -> Result<[u64; 4]> {
        let bytes = self.counter.buffer.mapped()?;
        let at = slot * SLOT_BYTES as usize;
        let word = |i: usize| {
            let w = &bytes[at + 4 * i..at + 4 * i + 4];
            u64::from(u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        };
        Ok([word(0), word(1), word(2), word(3)])
    }
}
