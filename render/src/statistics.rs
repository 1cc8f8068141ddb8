//! The pipeline-statistics queries behind [`PassInvocations`]: one pool per frame slot, a query
//! per floor stage, one for the blur's blends and three per eye (before the glass, the glass
//! with the environment's lookup, the glass without it),
//! and the frame's invocations read from their results.

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::floor::FIELD_STAMPS;
use crate::owned::Owned;
use crate::work::{Invocations, PassInvocations};

/// The statistics the queries count, in the order the results come back.
const STATISTICS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);

/// Queries per frame: one per floor stage ([`FIELD_STAMPS`], in their order), the blur's
/// blends ([`BLUR_QUERY`]), then for each eye one before the glass, one for the glass with
/// the environment's lookup and one for the glass without it.
pub(crate) const STATISTICS_QUERIES: u32 = FIELD_STAMPS + 7;

/// The query of the blur's blends (`blur_blend.rs`).
pub(crate) const BLUR_QUERY: u32 = FIELD_STAMPS;

/// The query of eye `eye`'s part before the glass; the glass's with the lookup is the next,
/// then the glass's without it.
pub(crate) fn eye_query(eye: usize) -> u32 {
    BLUR_QUERY + 1 + 3 * eye as u32
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
        eye_glass_covered: eyes(2),
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
