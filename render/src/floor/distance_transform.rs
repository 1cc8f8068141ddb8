//! The nearest shadow texel of every texel of the fields' region (shaders/inducer_distance.wgsl):
//! an exact Euclidean distance transform of the shadow mask, separable, in two compute passes
//! (one invocation per column of the region, then one per row), into a buffer from which
//! `fs_ramp` (and `fs_distance`, for a read back) find the distance d to the shadow edge
//! (`edge_distance_m` in [`super::reference`] on the CPU). Each texel of the mask is read twice, where a jump flood
//! reads nine seeds per texel and pass.
//!
//! Also the indices of the floor pass's full-screen pipelines.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::fields::TexelRect;
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Buffer;
use crate::owned::Owned;
use crate::pipeline;
use crate::shaders;

/// Indices into the floor pass's full-screen pipelines.
pub(crate) const DIST: usize = 0;
pub(crate) const RAMP: usize = 1;

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
    /// (ty / tx)^2 of the floor metres per texel along x and y.
    aspect2: f32,
    /// Side of the fields, texels.
    size: i32,
    /// Words per column of the column rows and per row of `nearest`: [`pitch`].
    pitch: i32,
    /// Padding to the block's 16-byte size.
    _pad: i32,
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
    /// The set: mask, column rows, envelope, starts, nearest.
    set: vk::DescriptorSet,
    /// Scratch: the nearest shadow row per texel in its column, the rows' envelopes.
    _scratch: [Buffer; 3],
    /// The nearest shadow texel per texel, x | y << 16, rows [`pitch`] texels apart (read by
    /// `fs_ramp` and `fs_distance`).
    pub nearest: Buffer,
    /// Side of the fields, texels.
    size: u32,
    /// (ty / tx)^2.
    aspect2: f32,
}

impl DistanceTransform {
    /// Prepares the transform of the `size` x `size` mask seen through `mask_view`, with
    /// texels `texel_m` metres along x and y.
    pub fn new(
        ctx: &GpuContext,
        mask_view: vk::ImageView,
        size: u32,
        texel_m: glam::Vec2,
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
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut bindings = vec![(0, vk::DescriptorType::SAMPLED_IMAGE, compute)];
        bindings.extend((1..=4).map(|b| (b, vk::DescriptorType::STORAGE_BUFFER, compute)));
        let set_layout = pipeline::set_layout(ctx, &bindings)?;
        let layout = pipeline::layout(
            ctx,
            Some(set_layout.raw()),
            compute,
            size_of::<TransformPush>() as u32,
        )?;
        let columns = pipeline::compute(ctx, layout.raw(), shaders::COLUMNS_CS, c"cs_columns")?;
        let rows_pipeline = pipeline::compute(ctx, layout.raw(), shaders::ROWS_CS, c"cs_rows")?;
        let pool = pipeline::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::SAMPLED_IMAGE, 1),
                (vk::DescriptorType::STORAGE_BUFFER, 4),
            ],
        )?;
        let set = pipeline::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        pipeline::write_image(ctx, set, 0, mask_view);
        let buffers = [
            scratch[0].buffer,
            scratch[1].buffer,
            scratch[2].buffer,
            nearest.buffer,
        ];
        for (binding, buffer) in (1..).zip(buffers) {
            pipeline::write_storage_buffer(ctx, set, binding, buffer);
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
            size,
            aspect2: (texel_m.y / texel_m.x).powi(2),
        })
    }

    /// Records the transform over `region`, after the mask's render pass (whose image is in
    /// SHADER_READ_ONLY_OPTIMAL) and before the fragment passes that read the result.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; `self` must outlive its execution.
    pub unsafe fn record(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, region: TexelRect) {
        let d = &ctx.device;
        let [x0, y0, x1, y1] = region;
        let push = TransformPush {
            region: region.map(|v| v as i32),
            aspect2: self.aspect2,
            size: self.size as i32,
            pitch: pitch(self.size) as i32,
            _pad: 0,
        };
        let barrier = |src_stage, src, dst| {
            let memory = [vk::MemoryBarrier::default()
                .src_access_mask(src)
                .dst_access_mask(dst)];
            // SAFETY: the caller's contract (recording outside a render pass).
            unsafe {
                d.cmd_pipeline_barrier(
                    cmd,
                    src_stage,
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::DependencyFlags::empty(),
                    &memory,
                    &[],
                    &[],
                )
            };
        };
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let groups = |n: u32| n.div_ceil(64);
        // The mask just drawn (and earlier work's reads of the buffers) before the columns.
        barrier(
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                | vk::PipelineStageFlags::FRAGMENT_SHADER
                | compute,
            vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::SHADER_READ,
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
        barrier(
            compute,
            vk::AccessFlags::SHADER_WRITE,
            vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
        );
        // SAFETY: as above.
        unsafe {
            d.cmd_bind_pipeline(cmd, bind, self.rows.raw());
            d.cmd_dispatch(cmd, groups(y1 - y0), 1, 1);
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
}
