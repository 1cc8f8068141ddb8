//! The nearest shadow texel of every texel of the fields' region (shaders/inducer_distance.wgsl):
//! an exact Euclidean distance transform of the shadow mask, separable, in two compute passes
//! (one invocation per column of the region, then one per row), into a buffer from which
//! `fs_distance` finds the distance d to the shadow edge for a read back (`edge_distance_m`
//! in [`super::reference`] on the CPU). The row pass also writes the inducer's gain k alpha(d)
//! (eq. 2 and 4) as half floats, which [`DistanceTransform::record_gain_copy`] copies into the
//! gain texture: no fragment pass runs after a move. Each texel of the mask is read twice,
//! where a jump flood reads nine seeds per texel and pass.
//!
//! Also the index of the floor pass's full-screen pipeline.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::fields::TexelRect;
use crate::context::GpuContext;
use crate::descriptors;
use crate::error::Result;
use crate::memory::{Buffer, layout_barrier, memory_barrier, subresource_range};
use crate::owned::Owned;
use crate::pipeline;
use crate::shaders;

/// Index of the distance field's pipeline among the floor pass's full-screen pipelines.
pub(crate) const DIST: usize = 0;

/// Texels per row of [`DistanceTransform::nearest`] (and per column of the column pass's
/// rows) for fields of side `size`: a multiple of 4, as the passes move four at a time.
pub(crate) fn pitch(size: u32) -> u32 {
    size.next_multiple_of(4)
}

/// Push constants of the two passes, as `Transform` in inducer_distance.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TransformPush {
    /// The region, texels (`[x0, y0, x1, y1]`, ends excluded).
    region: [i32; 4],
    /// The area the gain is written in, texels (the region and where the last computation
    /// wrote).
    area: [i32; 4],
    /// (ty / tx)^2 of the floor metres per texel along x and y.
    aspect2: f32,
    /// Side of the fields, texels.
    size: i32,
    /// Words per column of the column rows and per row of `nearest`: [`pitch`].
    pitch: i32,
    /// D of eq. 2, metres.
    ramp_width_m: f32,
    /// Floor metres per texel along x and y.
    texel_m: [f32; 2],
    /// k of eq. 4.
    k: f32,
    /// Padding to the block's 16-byte size.
    _pad: f32,
}

/// What the row pass needs for the inducer's gain (eq. 2 and 4).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ramp {
    /// k of eq. 4.
    pub k: f32,
    /// D of eq. 2, metres.
    pub width_m: f32,
    /// Floor metres per texel along x and y.
    pub texel_m: glam::Vec2,
}

/// The transform's pipelines and buffers; freed on drop.
pub(crate) struct DistanceTransform {
    /// Per column.
    columns: Owned<vk::Pipeline>,
    /// Per row.
    rows: Owned<vk::Pipeline>,
    /// Layout of both.
    layout: Owned<vk::PipelineLayout>,
    /// Pool of the set.
    _pool: Owned<vk::DescriptorPool>,
    /// Layout of the set.
    _set_layout: Owned<vk::DescriptorSetLayout>,
    /// The set: mask, column rows, envelope, starts, nearest, gains.
    set: vk::DescriptorSet,
    /// Scratch: the nearest shadow row per texel in its column, the rows' envelopes.
    _scratch: [Buffer; 3],
    /// The nearest shadow texel per texel, x | y << 16, rows [`pitch`] texels apart (read by
    /// `fs_distance`).
    pub nearest: Buffer,
    /// The gain per texel as half floats, rows [`pitch`] texels apart (copied into the gain
    /// texture).
    gains: Buffer,
    /// Side of the fields, texels.
    size: u32,
    /// (ty / tx)^2.
    aspect2: f32,
    /// The gain's parameters.
    ramp: Ramp,
}

impl DistanceTransform {
    /// Prepares the transform of the `size` x `size` mask seen through `mask_view`, and the
    /// gain of `ramp` (whose texels are `ramp.texel_m` metres along x and y).
    pub fn new(
        ctx: &GpuContext,
        mask_view: vk::ImageView,
        size: u32,
        ramp: Ramp,
    ) -> Result<DistanceTransform> {
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        // Column by column, and row by row, four texels per entry.
        let texels = u64::from(size) * u64::from(pitch(size));
        let rows = u64::from(size) * (u64::from(size) + 1);
        let buffer = |name: &str, words: u64| {
            Buffer::new(ctx, name, words * 4, storage, MemoryLocation::GpuOnly)
        };
        let scratch = [
            buffer("inducer column rows", texels)?,
            buffer("inducer envelope", rows)?,
            // A start and a height per parabola.
            buffer("inducer envelope starts", 2 * rows)?,
        ];
        let nearest = buffer("inducer nearest shadow texels", texels)?;
        // Two half floats per word.
        let gains = Buffer::new(
            ctx,
            "inducer gains",
            texels * 2,
            storage | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut bindings = vec![(0, vk::DescriptorType::SAMPLED_IMAGE, compute)];
        bindings.extend((1..=5).map(|b| (b, vk::DescriptorType::STORAGE_BUFFER, compute)));
        let set_layout = descriptors::set_layout(ctx, &bindings)?;
        let layout = pipeline::layout(
            ctx,
            Some(set_layout.raw()),
            compute,
            size_of::<TransformPush>() as u32,
        )?;
        let columns = pipeline::compute(ctx, layout.raw(), shaders::COLUMNS_CS, c"cs_columns")?;
        let rows_pipeline = pipeline::compute(ctx, layout.raw(), shaders::ROWS_CS, c"cs_rows")?;
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::SAMPLED_IMAGE, 1),
                (vk::DescriptorType::STORAGE_BUFFER, 5),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        descriptors::write_image(ctx, set, 0, mask_view);
        let buffers = [
            scratch[0].buffer,
            scratch[1].buffer,
            scratch[2].buffer,
            nearest.buffer,
            gains.buffer,
        ];
        for (binding, buffer) in (1..).zip(buffers) {
            descriptors::write_storage_buffer(ctx, set, binding, buffer);
        }
        Ok(DistanceTransform {
            columns,
            rows: rows_pipeline,
            layout,
            _pool: pool,
            _set_layout: set_layout,
            set,
            _scratch: scratch,
            nearest,
            gains,
            size,
            aspect2: (ramp.texel_m.y / ramp.texel_m.x).powi(2),
            ramp,
        })
    }

    /// Records the transform over `region` and the gain over `area` (which holds `region`),
    /// after the mask's render pass (whose image is in SHADER_READ_ONLY_OPTIMAL) and before
    /// [`DistanceTransform::record_gain_copy`] and the fragment passes that read the nearest
    /// texels.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; `self` must outlive its execution.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        region: TexelRect,
        area: TexelRect,
    ) {
        let d = &ctx.device;
        let [x0, _, x1, _] = region;
        let push = TransformPush {
            region: region.map(|v| v as i32),
            area: area.map(|v| v as i32),
            aspect2: self.aspect2,
            size: self.size as i32,
            pitch: pitch(self.size) as i32,
            ramp_width_m: self.ramp.width_m,
            texel_m: self.ramp.texel_m.to_array(),
            k: self.ramp.k,
            _pad: 0.0,
        };
        let barrier = |src_stage, src, dst| {
            // SAFETY: the caller's contract (recording outside a render pass).
            unsafe {
                memory_barrier(
                    d,
                    cmd,
                    (src_stage, src),
                    (vk::PipelineStageFlags::COMPUTE_SHADER, dst),
                )
            };
        };
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let groups = |n: u32| n.div_ceil(64);
        // The mask just drawn (and earlier work's reads of the buffers, the gains' copy among
        // them) before the columns.
        barrier(
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                | vk::PipelineStageFlags::FRAGMENT_SHADER
                | vk::PipelineStageFlags::TRANSFER
                | compute,
            vk::AccessFlags::COLOR_ATTACHMENT_WRITE
                | vk::AccessFlags::SHADER_READ
                | vk::AccessFlags::TRANSFER_READ,
            vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
        );
        let bind = vk::PipelineBindPoint::COMPUTE;
        // SAFETY: the caller's contract; the pipelines, layout and set are this transform's.
        unsafe {
            d.cmd_bind_descriptor_sets(cmd, bind, self.layout.raw(), 0, &[self.set], &[]);
            d.cmd_push_constants(
                cmd,
                self.layout.raw(),
                vk::ShaderStageFlags::COMPUTE,
                0,
                bytemuck::bytes_of(&push),
            );
            d.cmd_bind_pipeline(cmd, bind, self.columns.raw());
            d.cmd_dispatch(cmd, groups(x1 - x0), 1, 1);
        }
        ctx.work.upload(std::mem::size_of::<TransformPush>());
        ctx.work.dispatch(groups(x1 - x0), 1, 1);
        barrier(
            compute,
            vk::AccessFlags::SHADER_WRITE,
            vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
        );
        // SAFETY: as above.
        unsafe {
            d.cmd_bind_pipeline(cmd, bind, self.rows.raw());
            d.cmd_dispatch(cmd, groups(area[3] - area[1]), 1, 1);
            ctx.work.dispatch(groups(area[3] - area[1]), 1, 1);
            let memory = [vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                .dst_access_mask(vk::AccessFlags::SHADER_READ)];
            d.cmd_pipeline_barrier(
                cmd,
                compute,
                vk::PipelineStageFlags::FRAGMENT_SHADER,
                vk::DependencyFlags::empty(),
                &memory,
                &[],
                &[],
            );
        }
    }

    /// Records the copy of the gain the last [`DistanceTransform::record`] in `cmd` wrote over
    /// `area` into `gain`, an R16F image of the fields' size, left in SHADER_READ_ONLY_OPTIMAL
    /// for the overlay's fragment reads and read backs. `discard`: its earlier contents do not
    /// matter (`area` is the whole image); otherwise it is in SHADER_READ_ONLY_OPTIMAL and keeps
    /// them outside `area`.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, after `record`; `self` and `gain`
    /// must outlive its execution.
    pub unsafe fn record_gain_copy(
        &self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        gain: vk::Image,
        area: TexelRect,
        discard: bool,
    ) {
        // The row pass writes whole entries of four texels: start the copy at one, so that
        // its offset in the buffer is a multiple of 8 bytes.
        let [x0, y0, x1, y1] = [area[0] & !3, area[1], area[2], area[3]];
        let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
        let read = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let old = if discard {
            vk::ImageLayout::UNDEFINED
        } else {
            read
        };
        let written = [vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::SHADER_WRITE)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ)];
        let to_transfer = [layout_barrier(
            gain,
            range,
            (old, vk::AccessFlags::SHADER_READ),
            (
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::TRANSFER_WRITE,
            ),
        )];
        let to_read = [layout_barrier(
            gain,
            range,
            (
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::TRANSFER_WRITE,
            ),
            (
                read,
                vk::AccessFlags::SHADER_READ | vk::AccessFlags::TRANSFER_READ,
            ),
        )];
        let texel_bytes = 2;
        let offset = u64::from(y0 * pitch(self.size) + x0) * texel_bytes;
        let region = crate::memory::color_copy_region(offset, x1 - x0, y1 - y0, 1, 1)
            .buffer_row_length(pitch(self.size))
            .image_offset(vk::Offset3D {
                x: x0 as i32,
                y: y0 as i32,
                z: 0,
            });
        // SAFETY: the caller's contract; the barriers order the copy after the row pass's
        // writes and earlier reads of the image (the overlay's, a read back's), and later
        // fragment reads and transfers after it; the image goes from and back to the layout
        // it is in (or from UNDEFINED when its contents do not matter).
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER
                    | vk::PipelineStageFlags::FRAGMENT_SHADER
                    | transfer,
                transfer,
                vk::DependencyFlags::empty(),
                &written,
                &[],
                &to_transfer,
            );
            d.cmd_copy_buffer_to_image(
                cmd,
                self.gains.buffer,
                gain,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            d.cmd_pipeline_barrier(
                cmd,
                transfer,
                vk::PipelineStageFlags::FRAGMENT_SHADER | transfer,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &to_read,
            );
        }
    }
}
