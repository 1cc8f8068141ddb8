//! The smoothing of the live caustic map (docs/caustics.md, *Smoothing*): which compute
//! passes of shaders/caustics_smooth.wgsl run for a box radius, in what order, with which push
//! constant, and how the map's buffers lay out their rows. The box of 2 r + 1 texels runs
//! three times along the rows, then three times along the columns; radii up to
//! [`SHORT_KERNEL_PX`] apply the resulting 6 r + 1 weights from registers, four texels per
//! access of memory, wider ones stream each line through ring buffers.
//!
//! The short kernel's passes skip the tiles of [`TILE_PX`] texels whose smoothed gains are
//! certain to be stored as 0: each photon's deposit adds its positive share of G to the mass
//! of its cell of 4 x 4 texels, and a pass (`cs_smooth_tiles`) bounds each tile's gains by
//! the masses of the cells within the kernel's reach, weighted by the kernel's largest
//! weight between them, into bits of the tiles to write.

use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Buffer;
use crate::owned::Owned;
use crate::{pipeline, shaders};

/// Fixed-point units per unit of gain in the photons' sums the smoothing reads (`live.rs`
/// splats into them; integer atomics keep the result the same whatever order photons land in).
pub(super) const FIXED_POINT: f32 = 65536.0;
/// Invocations per workgroup of the smoothing's passes.
const SMOOTH_GROUP: u32 = 64;
/// Largest radius the smoothing's short kernel takes (`SHORT_KERNEL_PX` in
/// caustics_smooth.wgsl): its 6 r + 1 = 13 weights fit in registers.
pub(super) const SHORT_KERNEL_PX: u32 = 2;
/// Side of the smoothing's tiles, texels (`TILE` in shaders/shared/caustics_maps.wgsl): a multiple of the
/// four texels a pass moves per access, and at least the short kernel's reach (3 r = 6), so
/// that a tile's gains depend on its own and its neighbours' texels only.
pub(super) const TILE_PX: u32 = 8;
// The passes' tile arithmetic: a tile is two cells of four texels along each axis, and the
// kernel reaches no further than the next tile.
const _: () = assert!(TILE_PX == 8 && 3 * SHORT_KERNEL_PX <= TILE_PX);
/// Flags of a smoothing step (`COLUMNS_STEP`, `FROM_SUMS_STEP`, `LAST_STEP` in
/// caustics_smooth.wgsl): along the columns; reading the photons' sums (no smoothing); the last.
const COLUMNS_STEP: u32 = 0x1;
const FROM_SUMS_STEP: u32 = 0x2;
const LAST_STEP: u32 = 0x100;

/// A smoothing pass's shader (index into `shaders::CAUSTICS_SMOOTH_CS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SmoothPass {
    /// The short kernel along the rows, one row per invocation.
    Rows = 0,
    /// The short kernel along the columns, four columns per invocation.
    Columns = 1,
    /// Ring buffers, one row or column per invocation.
    Wide = 2,
    /// The tiles' bits from the cells' masses, one tile row per invocation.
    Tiles = 3,
}

/// The smoothing's dispatches, in order, for a box of `radius` texels: its pass and push
/// constant. The tiles' bits when the short kernel `skips` tiles, then along the rows, then
/// along the columns (the last); without smoothing one pass along the columns that reads the
/// sums, clamps, zeroes and bounds.
pub(super) fn smooth_steps(radius: u32, skips: bool) -> Vec<(SmoothPass, u32)> {
    let mut steps = match radius {
        0 => vec![(
            SmoothPass::Columns,
            COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP,
        )],
        r if r <= SHORT_KERNEL_PX => vec![
            (SmoothPass::Rows, 0),
            (SmoothPass::Columns, COLUMNS_STEP | LAST_STEP),
        ],
        _ => {
            return vec![
                (SmoothPass::Wide, 0),
                (SmoothPass::Wide, COLUMNS_STEP | LAST_STEP),
            ];
        }
    };
    if skips {
        steps.insert(0, (SmoothPass::Tiles, 0));
    }
    steps
}

impl SmoothPass {
    /// The passes' pipelines, indexed by [`SmoothPass`], in `layout` (the live caustics' set,
    /// the step as push constant).
    pub fn pipelines(
        ctx: &GpuContext,
        layout: vk::PipelineLayout,
    ) -> Result<[Owned<vk::Pipeline>; 4]> {
        let entries = [
            c"cs_smooth_rows",
            c"cs_smooth_columns",
            c"cs_smooth_wide",
            c"cs_smooth_tiles",
        ];
        let mut pipelines = Vec::with_capacity(entries.len());
        for (spirv, entry) in shaders::CAUSTICS_SMOOTH_CS.into_iter().zip(entries) {
            pipelines.push(pipeline::compute(ctx, layout, spirv, entry)?);
        }
        Ok(pipelines
            .try_into()
            .unwrap_or_else(|_| unreachable!("four entries")))
    }

    /// Invocations of this pass with push constant `step` on a `size` map: one per row, per
    /// vector of four columns, per column, or per tile row.
    fn invocations(self, step: u32, size: [u32; 2]) -> u32 {
        let [w, h] = size;
        match self {
            SmoothPass::Tiles => tile_layout(w, h)[1],
            SmoothPass::Rows => h,
            SmoothPass::Columns => row_pitch(w) / 4,
            SmoothPass::Wide if step & COLUMNS_STEP != 0 => w,
            SmoothPass::Wide => h,
        }
    }
}

/// Records the smoothing's `steps` ([`smooth_steps`]) on a `size` map with `pipelines`
/// ([`SmoothPass::pipelines`]), each after a barrier that orders it after the writes of the
/// pass before (the first, the photons' sums).
///
/// # Safety
/// `cmd` must be recording outside a render pass with the live caustics' set bound in
/// `layout`; the pipelines and everything the set holds must outlive its execution.
pub(super) unsafe fn record_smoothing(
    ctx: &GpuContext,
    cmd: vk::CommandBuffer,
    layout: vk::PipelineLayout,
    pipelines: &[Owned<vk::Pipeline>; 4],
    steps: &[(SmoothPass, u32)],
    size: [u32; 2],
) {
    let d = &ctx.device;
    let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
    let written = [vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::SHADER_WRITE)
        .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE)];
    for &(pass, step) in steps {
        // SAFETY: the caller's contract; the barrier orders the pass after the one before.
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                compute,
                compute,
                vk::DependencyFlags::empty(),
                &written,
                &[],
                &[],
            );
            d.cmd_bind_pipeline(
                cmd,
                vk::PipelineBindPoint::COMPUTE,
                pipelines[pass as usize].raw(),
            );
            d.cmd_push_constants(
                cmd,
                layout,
                vk::ShaderStageFlags::COMPUTE,
                0,
                &step.to_le_bytes(),
            );
            let groups = pass.invocations(step, size).div_ceil(SMOOTH_GROUP);
            d.cmd_dispatch(cmd, groups, 1, 1);
            ctx.work.upload(std::mem::size_of_val(&step));
            ctx.work.dispatch(groups, 1, 1);
        }
    }
}

/// Texels from one row of the map's buffers to the next: the width rounded up to whole
/// vectors of four (`row_pitch` in shaders/shared/caustics_maps.wgsl).
pub(super) fn row_pitch(width: u32) -> u32 {
    width.next_multiple_of(4)
}

/// The tiles of a `width` x `height` map's buffers: across, down, and words of bits per tile
/// row (`tiles.xyz` in shaders/shared/caustics_maps.wgsl).
pub(super) fn tile_layout(width: u32, height: u32) -> [u32; 3] {
    let across = row_pitch(width).div_ceil(TILE_PX);
    [across, height.div_ceil(TILE_PX), across.div_ceil(32)]
}

/// The buffers of the smoothing's tiles: per cell of 4 x 4 texels the positive shares of G
/// deposited in it (the trace adds them, `cs_smooth_tiles` reads them), and per tile row the
/// bits of the tiles the passes write. Freed on drop.
pub(super) struct SmoothTiles {
    /// Cell masses, two cells per tile along each axis, rows padded to whole vectors of four
    /// cells; zeroed before each computation that skips tiles.
    cell_mass: Buffer,
    /// The bits; all set when the smoothing skips none. Host-visible ([`SmoothTiles::written`]).
    bits: Buffer,
    /// [`tile_layout`] of the map.
    layout: [u32; 3],
}

impl SmoothTiles {
    /// The buffers for a `size` map.
    pub fn new(ctx: &GpuContext, size: [u32; 2]) -> Result<SmoothTiles> {
        let layout = tile_layout(size[0], size[1]);
        let [across, down, words] = layout;
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let cell_mass = Buffer::new(
            ctx,
            "caustics cell masses",
            u64::from((2 * across).next_multiple_of(4) * 2 * down) * 4,
            usage,
            MemoryLocation::GpuOnly,
        )?;
        let bits = Buffer::new(
            ctx,
            "caustics tile bits",
            u64::from(down * words) * 4,
            // Copied into a counting frame's buffer (`LiveCaustics::photon_work`).
            usage | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(SmoothTiles {
            cell_mass,
            bits,
            layout,
        })
    }

    /// The cell masses' buffer and the bits'.
    pub fn buffers(&self) -> [vk::Buffer; 2] {
        [self.cell_mass.buffer, self.bits.buffer]
    }

    /// Tiles across, tile rows, and words of bits per tile row.
    pub fn layout(&self) -> [u32; 3] {
        self.layout
    }

    /// Records the clearing a computation starts with: the masses when it skips tiles, else
    /// the bits set (every tile written).
    ///
    /// # Safety
    /// `cmd` must be recording outside a render pass, after a barrier that orders earlier
    /// reads of both buffers before transfer writes, and before one that orders these writes
    /// before the passes' reads; `self` must outlive its execution.
    pub unsafe fn record_clear(&self, d: &ash::Device, cmd: vk::CommandBuffer, skipping: bool) {
        let (buffer, value) = if skipping {
            (self.cell_mass.buffer, 0)
        } else {
            (self.bits.buffer, u32::MAX)
        };
        // SAFETY: the caller's contract.
        unsafe { d.cmd_fill_buffer(cmd, buffer, 0, vk::WHOLE_SIZE, value) };
    }

    /// How many tiles the last computation that finished wrote, and how many the map has
    /// (wait for the frame first).
    pub fn written(&self) -> Result<[u32; 2]> {
        let [across, down, _] = self.layout;
        let mut written = 0;
        self.each_written(self.bits.mapped()?, |_, _| written += 1);
        Ok([written, across * down])
    }

    /// The bits' size, bytes.
    pub fn bits_bytes(&self) -> u64 {
        let [_, down, words] = self.layout;
        u64::from(down * words) * 4
    }

    /// Calls `f` with the column and row of each tile that `bits` (a copy of the bits'
    /// buffer) marks written.
    pub fn each_written(&self, bits: &[u8], mut f: impl FnMut(u32, u32)) {
        let [across, down, words] = self.layout;
        for row in 0..down {
            for x in 0..across {
                let at = ((row * words + x / 32) * 4) as usize;
                let word = u32::from_le_bytes([bits[at], bits[at + 1], bits[at + 2], bits[at + 3]]);
                if (word >> (x % 32)) & 1 != 0 {
                    f(x, row);
                }
            }
        }
    }
}

/// Fixed-point units per unit of the smoothing's cell masses (`MASS_UNIT` in
/// shaders/shared/caustics_maps.wgsl).
const MASS_UNIT: f32 = 16.0;

/// Whether the positive shares of G that `photons_per_side`^2 photons in a cone of `cone_sr`
/// steradians from `light` deposit on the floor `world_from_plane` maps (texels of
/// `texel_area`) add up to less than 2^31 units of [`MASS_UNIT`], so that no cell's mass
/// (`cell_mass` in shaders/shared/caustics_maps.wgsl, a u32 sum) can wrap round. A photon's paths split its
/// light, so its shares sum to at most one share at the floor's point where G per unit of
/// light, r^2 / cos theta = r^3 / height, is largest: the corner farthest from the light.
/// Each path's rounding adds at most 3 units, and paths end below `min_path_weight`, so a
/// photon has at most 1 / `min_path_weight` of them. The shipped scenes stay below it by a
/// factor of about 30.
pub(super) fn shares_fit(
    world_from_plane: Mat4,
    light: Vec3,
    cone_sr: f32,
    texel_area: f32,
    photons_per_side: u32,
    min_path_weight: f32,
) -> bool {
    let p = world_from_plane;
    let normal = p.x_axis.truncate().cross(p.y_axis.truncate()).normalize();
    let height = (light - p.w_axis.truncate()).dot(normal);
    if height <= 0.0 {
        // Behind the floor: the photons deposit nothing.
        return true;
    }
    let farthest = [(-0.5, -0.5), (-0.5, 0.5), (0.5, -0.5), (0.5, 0.5)]
        .map(|(x, y)| p.transform_point3(Vec3::new(x, y, 0.0)).distance(light))
        .into_iter()
        .fold(0.0f32, f32::max);
    let photons = photons_per_side as f32 * photons_per_side as f32;
    let most = cone_sr * farthest.powi(3) / (height * texel_area) * FIXED_POINT / MASS_UNIT
        + photons * 3.0 / min_path_weight;
    most < 2f32.powi(31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_optics::live_caustics::MAX_SMOOTHING_PX;

    #[test]
    fn smoothing_runs_along_rows_then_columns_or_once_without_a_box() {
        use SmoothPass::*;
        let once = COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP;
        assert_eq!(smooth_steps(0, false), vec![(Columns, once)]);
        assert_eq!(smooth_steps(0, true), vec![(Tiles, 0), (Columns, once)]);
        let short = vec![(Rows, 0), (Columns, COLUMNS_STEP | LAST_STEP)];
        assert_eq!(smooth_steps(1, false), short);
        assert_eq!(smooth_steps(2, false), short);
        let skipping = vec![(Tiles, 0), (Rows, 0), (Columns, COLUMNS_STEP | LAST_STEP)];
        assert_eq!(smooth_steps(2, true), skipping);
        // Wide boxes skip no tiles.
        let wide = vec![(Wide, 0), (Wide, COLUMNS_STEP | LAST_STEP)];
        assert_eq!(smooth_steps(3, true), wide);
        assert_eq!(smooth_steps(MAX_SMOOTHING_PX, false), wide);
    }

    #[test]
    fn rows_are_padded_to_whole_vectors_of_four() {
        assert_eq!(row_pitch(990), 992);
        assert_eq!(row_pitch(992), 992);
        assert_eq!(row_pitch(1), 4);
    }

    #[test]
    fn tiles_cover_the_padded_rows_with_whole_words_of_bits() {
        assert_eq!(tile_layout(990, 990), [124, 124, 4]);
        assert_eq!(tile_layout(66, 66), [9, 9, 1]);
        assert_eq!(tile_layout(1, 1), [1, 1, 1]);
    }

    #[test]
    fn the_shares_fit_unless_the_light_is_nearly_level_with_the_floor() {
        use vitreous_optics::live_caustics::MIN_WEIGHT;
        // The shipped 1 m floor facing up, 990 x 990 texels, and an 80 mm ball 1.4 m from a
        // light 1 m above it: a cone of about 2.5e-3 sr.
        let floor = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, -0.3, -1.5),
        );
        let texel = 1.0 / (990.0 * 990.0);
        let cone = 2.5e-3;
        let above = Vec3::new(0.0, 0.7, -2.5);
        assert!(shares_fit(floor, above, cone, texel, 128, MIN_WEIGHT));
        // A light as far off, 0.1 m above the floor: G per unit of light at the far corner is
        // six times larger, within the room the mass unit leaves.
        assert!(shares_fit(
            floor,
            Vec3::new(0.0, -0.2, -2.5),
            cone,
            texel,
            128,
            MIN_WEIGHT
        ));
        // 1 mm above the floor's plane: a thousand times larger.
        let level = Vec3::new(0.0, -0.299, -2.5);
        assert!(!shares_fit(floor, level, cone, texel, 128, MIN_WEIGHT));
        // Below it: nothing lands.
        assert!(shares_fit(
            floor,
            Vec3::new(0.0, -1.0, -1.5),
            cone,
            texel,
            128,
            MIN_WEIGHT
        ));
        // Enough photons alone exceed it through their rounding, and fewer when their paths
        // end at a smaller weight.
        assert!(!shares_fit(floor, above, cone, texel, 4096, MIN_WEIGHT));
        assert!(shares_fit(floor, above, cone, texel, 1024, MIN_WEIGHT));
        assert!(!shares_fit(floor, above, cone, texel, 1024, 1e-4));
    }
}
