//! Counted work: what each frame asks of the device, counted instead of timed, so that a cost
//! guard is exact on a shared, noisy machine and carries over to a real GPU.
//!
//! Two kinds of count, both per frame:
//! - **recorded** ([`RecordedWork`]): render passes, draws, vertices drawn, compute dispatches
//!   and their workgroups, and bytes the host writes into the command buffer
//!   (`vkCmdUpdateBuffer` and push constants), counted by the renderer as it records them.
//!   The same on every device.
//! - **executed** ([`PassInvocations`]): the vertex, fragment and compute shader invocations of
//!   each pass, from pipeline-statistics queries (Vulkan's `pipelineStatisticsQuery` feature)
//!   once the frame finished: what the device ran. Vulkan leaves some freedom here (a device
//!   may shade helper lanes of a quad, or run a vertex shader again for a reused index), so
//!   these are exact for one driver and comparable across frames and builds on it, not across
//!   drivers; docs/cli.md says which drivers were checked.
//!
//! Recording happens on the thread that calls [`crate::Renderer::submit`]; the tally lives in
//! the context and is taken at the end of each frame's recording.

use std::sync::atomic::{AtomicU64, Ordering};

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::floor::FIELD_STAMPS;
use crate::owned::Owned;

/// The work of one frame, counted (`work.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameWork {
    /// What was recorded into its command buffer: the same on every device.
    pub recorded: RecordedWork,
    /// The shader invocations of each pass as the device ran them; `None` unless
    /// [`crate::Renderer::count_invocations`] turned counting on before the frame (and the device
    /// can).
    pub invocations: Option<PassInvocations>,
    /// The static cost of one fragment of the glass's pipeline, when the glass was drawn.
    pub glass_shader: Option<ShaderCost>,
    /// The static cost of one fragment of the floor overlay's pipeline, when it was drawn.
    pub overlay_shader: Option<ShaderCost>,
}

/// Work recorded into one frame's command buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecordedWork {
    /// Render passes begun.
    pub render_passes: u64,
    /// Draw calls.
    pub draws: u64,
    /// Vertices (or indices) the draws read.
    pub vertices: u64,
    /// Compute dispatches.
    pub dispatches: u64,
    /// Compute workgroups the dispatches launched.
    pub workgroups: u64,
    /// Bytes written by the host into the command buffer: `vkCmdUpdateBuffer` data and push
    /// constants.
    pub uploaded_bytes: u64,
}

/// Counts of work as it is recorded (see [`RecordedWork`]); every count only grows until
/// [`WorkTally::take`].
#[derive(Debug, Default)]
pub(crate) struct WorkTally {
    render_passes: AtomicU64,
    draws: AtomicU64,
    vertices: AtomicU64,
    dispatches: AtomicU64,
    workgroups: AtomicU64,
    uploaded_bytes: AtomicU64,
}

impl WorkTally {
    /// A render pass begun.
    pub fn render_pass(&self) {
        self.render_passes.fetch_add(1, Ordering::Relaxed);
    }

    /// A draw of `vertices` vertices (or indices).
    pub fn draw(&self, vertices: u32) {
        self.draws.fetch_add(1, Ordering::Relaxed);
        self.vertices
            .fetch_add(u64::from(vertices), Ordering::Relaxed);
    }

    /// A dispatch of `x * y * z` workgroups.
    pub fn dispatch(&self, x: u32, y: u32, z: u32) {
        self.dispatches.fetch_add(1, Ordering::Relaxed);
        self.workgroups.fetch_add(
            u64::from(x) * u64::from(y) * u64::from(z),
            Ordering::Relaxed,
        );
    }

    /// `bytes` written from the host into the command buffer.
    pub fn upload(&self, bytes: usize) {
        self.uploaded_bytes
            .fetch_add(bytes as u64, Ordering::Relaxed);
    }

    /// The counts so far, set back to 0.
    pub fn take(&self) -> RecordedWork {
        let take = |count: &AtomicU64| count.swap(0, Ordering::Relaxed);
        RecordedWork {
            render_passes: take(&self.render_passes),
            draws: take(&self.draws),
            vertices: take(&self.vertices),
            dispatches: take(&self.dispatches),
            workgroups: take(&self.workgroups),
            uploaded_bytes: take(&self.uploaded_bytes),
        }
    }
}

/// The static cost of one invocation of a shader entry point, read off its IR at build time
/// (render/build/shader_cost.rs): texture fetches, the texels they filter (4 for a 2-D
/// sample, 8 for a 3-D one, 1 for a load) and instructions. Both sides of a branch count, as
/// on a device that runs them masked (lavapipe; a GPU where a wave's lanes disagree), except
/// where the condition is a constant; a loop's body counts once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShaderCost {
    /// Texture fetches.
    pub fetches: u32,
    /// Texels the fetches read.
    pub texels: u32,
    /// Expressions evaluated, statements and calls.
    pub instructions: u32,
}

/// Shader invocations of one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Invocations {
    /// Vertex shader invocations.
    pub vertex: u64,
    /// Fragment shader invocations.
    pub fragment: u64,
    /// Compute shader invocations.
    pub compute: u64,
}

impl Invocations {
    /// The three counts, in the order the query returns them (the flags' bit order).
    fn from_query([vertex, fragment, compute]: [u64; 3]) -> Invocations {
        Invocations {
            vertex,
            fragment,
            compute,
        }
    }
}

impl std::ops::Add for Invocations {
    type Output = Invocations;

    fn add(self, other: Invocations) -> Invocations {
        Invocations {
            vertex: self.vertex + other.vertex,
            fragment: self.fragment + other.fragment,
            compute: self.compute + other.compute,
        }
    }
}

/// Shader invocations of each of a frame's passes, both eyes together.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassInvocations {
    /// The floor's shadow mask (drawn after a move).
    pub mask: Invocations,
    /// The nearest shadow texels (the distance transform's compute passes).
    pub nearest: Invocations,
    /// The inducer's gain and its copy.
    pub ramp: Invocations,
    /// The live caustic map's photons: clearing, tracing and splatting.
    pub caustic_photons: Invocations,
    /// The live caustic map's smoothing, clamp, bound and copy.
    pub caustic_smoothing: Invocations,
    /// The blur's blends of the background photo and surface texture (when it changed).
    pub blur: Invocations,
    /// In the eye passes, everything before the glass: the real world behind (for a display
    /// that shows none of its own) and the floor overlay.
    pub eye_floor: Invocations,
    /// In the eye passes, the glass object.
    pub eye_glass: Invocations,
}

/// The statistics the queries count, in the order the results come back.
const STATISTICS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);

/// Queries per frame: one per floor stage ([`FIELD_STAMPS`], in their order), the blur's
/// blends ([`BLUR_QUERY`]), then for each eye one before the glass and one for it.
pub(crate) const STATISTICS_QUERIES: u32 = FIELD_STAMPS + 5;

/// The query of the blur's blends (`blur_blend.rs`).
pub(crate) const BLUR_QUERY: u32 = FIELD_STAMPS;

/// The query of eye `eye`'s part before the glass; the glass's is the next.
pub(crate) fn eye_query(eye: usize) -> u32 {
    BLUR_QUERY + 1 + 2 * eye as u32
}

/// A frame's pipeline-statistics queries, when it counts invocations: each call does
/// nothing on `None`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Statistics(pub Option<vk::QueryPool>);

impl Statistics {
    /// Resets the pool and begins the first floor stage's query (each stage's end begins the
    /// next, `floor::Stamps`).
    ///
    /// # Safety
    /// `cmd` must be recording outside a render pass; the pool must hold
    /// [`STATISTICS_QUERIES`] queries and outlive the command buffer's execution.
    pub unsafe fn start(self, device: &ash::Device, cmd: vk::CommandBuffer) {
        if let Some(pool) = self.0 {
            // SAFETY: the caller's contract.
            unsafe {
                device.cmd_reset_query_pool(cmd, pool, 0, STATISTICS_QUERIES);
                device.cmd_begin_query(cmd, pool, 0, vk::QueryControlFlags::empty());
            }
        }
    }

    /// Counts what `record` records into `cmd` in query `query`.
    ///
    /// # Safety
    /// As [`Statistics::start`], after it; `query` not yet begun this frame, and `record`
    /// must end any render pass it begins (or begin none when called inside one).
    pub unsafe fn around(
        self,
        device: &ash::Device,
        cmd: vk::CommandBuffer,
        query: u32,
        record: impl FnOnce(),
    ) {
        if let Some(pool) = self.0 {
            // SAFETY: the caller's contract.
            unsafe { device.cmd_begin_query(cmd, pool, query, vk::QueryControlFlags::empty()) };
        }
        record();
        if let Some(pool) = self.0 {
            // SAFETY: the caller's contract; the query was begun above.
            unsafe { device.cmd_end_query(cmd, pool, query) };
        }
    }
}

/// A pool of [`STATISTICS_QUERIES`] pipeline-statistics queries (the device must have them
/// enabled: [`GpuContext::pipeline_statistics`]).
pub(crate) fn statistics_pool(ctx: &GpuContext) -> Result<Owned<vk::QueryPool>> {
    let info = vk::QueryPoolCreateInfo::default()
        .query_type(vk::QueryType::PIPELINE_STATISTICS)
        .query_count(STATISTICS_QUERIES)
        .pipeline_statistics(STATISTICS);
    // SAFETY: a valid create info for a device with pipeline-statistics queries; owned right
    // away.
    let pool = unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
    Ok(Owned::new(ctx, pool))
}

/// The frame's invocations from its pool's results, as [`read_statistics`] returns them.
pub(crate) fn pass_invocations(
    results: &[[u64; 3]; STATISTICS_QUERIES as usize],
) -> PassInvocations {
    let at = |i: u32| Invocations::from_query(results[i as usize]);
    let eyes = |part: u32| at(eye_query(0) + part) + at(eye_query(1) + part);
    PassInvocations {
        mask: at(0),
        nearest: at(1),
        ramp: at(2),
        caustic_photons: at(3),
        caustic_smoothing: at(4),
        blur: at(BLUR_QUERY),
        eye_floor: eyes(0),
        eye_glass: eyes(1),
    }
}

/// Reads a finished frame's statistics.
///
/// # Safety
/// Every query of `pool` must have been begun and ended by a submitted command buffer whose
/// execution has finished.
pub(crate) unsafe fn read_statistics(
    device: &ash::Device,
    pool: vk::QueryPool,
) -> std::result::Result<PassInvocations, vk::Result> {
    let mut results = [[0u64; 3]; STATISTICS_QUERIES as usize];
    // SAFETY: the caller's contract; each query's three 64-bit results fill one element.
    unsafe {
        device.get_query_pool_results(
            pool,
            0,
            &mut results,
            vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
        )
    }?;
    Ok(pass_invocations(&results))
}
