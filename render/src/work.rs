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
//! - **counted by the shaders** ([`PhotonWork`]): the live caustic map's photons traced and
//!   splatted and the texels its smoothing wrote, with integer atomics and the smoothing's tile
//!   bits, once the frame finished; and the positions inside its pixels the glass shaded
//!   ([`GlassPositions`]), with integer atomics. Exact on every device.
//!
//! Recording happens on the thread that calls [`crate::Renderer::submit`]; the tally lives in
//! the context and is taken at the end of each frame's recording. The queries that count the
//! invocations are in [`crate::statistics`]; this module holds only the counts, so the context
//! that keeps the tally depends on nothing else of the renderer through it. [`counts`] names
//! them and takes their mean over frames (`vitreous bench`).

use std::sync::atomic::{AtomicU64, Ordering};

pub mod counts;

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
    /// The same of the glass's pipeline without the environment's lookup, when part of the
    /// glass was drawn with it (where the frame proved every refracted ray reaches the
    /// background photo, `coverage.rs`).
    pub glass_covered_shader: Option<ShaderCost>,
    /// The static cost of one fragment of the floor overlay's pipeline, when it was drawn.
    pub overlay_shader: Option<ShaderCost>,
    /// What the live caustic map's computation did, counted on the device: `None` unless the
    /// frame counted invocations with live caustics on; all 0 on a frame that did not
    /// compute the map.
    pub photons: Option<PhotonWork>,
    /// The positions the glass shaded, counted on the device: `None` unless the frame counted
    /// invocations and drew the glass with a pipeline whose pixels decide how many positions
    /// they shade (shaders/shared/glass_positions.wgsl).
    pub glass_positions: Option<GlassPositions>,
    /// The searches of the object's triangles, counted on the device: `None` unless the frame
    /// counted invocations and drew a mesh whose exit is searched among its triangles
    /// (shaders/glass.wgsl `mesh_hit`).
    pub glass_mesh: Option<MeshSearch>,
}

/// One computation of the live caustic map, counted on the device by the trace that counts
/// (`COUNTED` in shaders/caustics_live.wgsl) and from the smoothing's tile bits. Exact on any
/// device: integer atomics and bits, not a driver's statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PhotonWork {
    /// Photons of the emission grid that met the object and were traced through it.
    pub traced: u64,
    /// Their deposits on the map: each photon's shadow and each path that lands there.
    pub splatted: u64,
    /// Texels of the map the smoothing wrote (its tiles that may hold a gain; every texel
    /// where it skips none).
    pub smoothed_texels: u64,
}

/// The positions inside its pixels that the glass shaded in one frame, both eyes, counted on
/// the device by the pipelines that shade a ball's light in two parts, each over as many
/// positions as it needs (`COUNTED` in shaders/shared/glass_positions.wgsl), with integer
/// atomics: exact on every device. Only the pixels the glass covers count (a device's helper
/// invocations write nothing). The static cost of the pipeline ([`FrameWork::glass_shader`])
/// charges every fragment invocation one position of each part; each further one of a pixel
/// is charged [`GlassPositions::each`] or [`GlassPositions::each_first_image`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GlassPositions {
    /// Positions shaded for the rest of the light: the surface's reflection and the light the
    /// exit reflects back inside.
    pub shaded: u64,
    /// Positions shaded for the first image: the room refracted through both surfaces.
    pub first_images: u64,
    /// The covered pixels that shaded them.
    pub pixels: u64,
    /// The static cost of one position of the rest.
    pub each: ShaderCost,
    /// The static cost of one position of the first image.
    pub each_first_image: ShaderCost,
}

impl GlassPositions {
    /// What the pixels shaded beyond one position of each part each, at their static costs:
    /// fetches, texels and instructions.
    pub fn further(&self) -> [u64; 3] {
        let rest = self.shaded.saturating_sub(self.pixels);
        let first = self.first_images.saturating_sub(self.pixels);
        let of = |f: fn(ShaderCost) -> u32| {
            rest * u64::from(f(self.each)) + first * u64::from(f(self.each_first_image))
        };
        [of(|c| c.fetches), of(|c| c.texels), of(|c| c.instructions)]
    }
}

/// The searches of the object's triangles in one frame, both eyes, counted on the device by the
/// pipelines that leave a mesh through its triangles (`COUNTED` in shaders/glass.wgsl
/// `mesh_hit`), with integer atomics: exact on every device. The static cost of the pipeline
/// ([`FrameWork::glass_shader`]) counts one pass of each search's loops per fragment; every
/// node visited and triangle tested is charged [`MeshSearch::each_node`] or
/// [`MeshSearch::each_triangle`] on top.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshSearch {
    /// Nodes of the bounding-volume hierarchy the searches visited.
    pub nodes: u64,
    /// Triangles they tested.
    pub triangles: u64,
    /// The covered pixels' fragments that searched.
    pub fragments: u64,
    /// The positions inside their pixels those fragments shaded: a pixel's grid, and a grid
    /// twice as fine where the first left its light uncertain
    /// (shaders/shared/glass_positions.wgsl `needs_finer`).
    pub positions: u64,
    /// The static cost of visiting one node.
    pub each_node: ShaderCost,
    /// The static cost of testing one triangle.
    pub each_triangle: ShaderCost,
}

impl MeshSearch {
    /// What the searches cost at the static costs of a node and a triangle: fetches, texels and
    /// instructions.
    pub fn charged(&self) -> [u64; 3] {
        let of = |f: fn(ShaderCost) -> u32| {
            self.nodes * u64::from(f(self.each_node))
                + self.triangles * u64::from(f(self.each_triangle))
        };
        [of(|c| c.fetches), of(|c| c.texels), of(|c| c.instructions)]
    }
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

impl ShaderCost {
    /// The cost of a shader whose loop runs its body `runs` times where `self` counts it once,
    /// with `body` an upper bound of one run's cost (a loop over positions per pixel whose body
    /// is the one-position shader, `body`).
    pub fn with_runs(self, body: ShaderCost, runs: u32) -> ShaderCost {
        let more = runs.saturating_sub(1);
        ShaderCost {
            fetches: self.fetches + more * body.fetches,
            texels: self.texels + more * body.texels,
            instructions: self.instructions + more * body.instructions,
        }
    }
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
    pub(crate) fn from_query([vertex, fragment, compute]: [u64; 3]) -> Invocations {
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
    /// In the eye passes, the glass object drawn with the environment's lookup.
    pub eye_glass: Invocations,
    /// In the eye passes, the glass object drawn without it (where the frame proved every
    /// refracted ray reaches the background photo).
    pub eye_glass_covered: Invocations,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_loop_run_again_is_charged_its_body_once_more_per_run() {
        let looped = ShaderCost {
            fetches: 5,
            texels: 20,
            instructions: 300,
        };
        let body = ShaderCost {
            fetches: 4,
            texels: 16,
            instructions: 250,
        };
        assert_eq!(looped.with_runs(body, 1), looped);
        assert_eq!(looped.with_runs(body, 0), looped);
        let sixteen = looped.with_runs(body, 16);
        assert_eq!(sixteen.fetches, 5 + 15 * 4);
        assert_eq!(sixteen.texels, 20 + 15 * 16);
        assert_eq!(sixteen.instructions, 300 + 15 * 250);
    }
}
