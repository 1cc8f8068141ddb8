//! The floor overlay (shaders/floor_overlay.wgsl): per eye, a world-anchored rectangle on the
//! floor plane that adds a gain times the floor photo, L_s = k alpha(d) L_r (eq. 3) plus the
//! corrected caustics G L_r (eq. 6), with blend (ONE, ONE). Each pixel sums the inducer's gain
//! and the caustic gain, as switched on, in the same draw: nothing is recombined when the
//! switches change or the light moves.

use ash::vk;
use glam::Mat4;
use gpu_allocator::MemoryLocation;
use vitreous_optics::camera::EyeParams;

use crate::context::GpuContext;
use crate::descriptors;
use crate::error::Result;
use crate::memory::Buffer;
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, PipelineSpec};
use crate::scene::GpuScene;
use crate::shaders::{OVERLAY_FS, OVERLAY_FS_COST, OVERLAY_VS};
use crate::work::ShaderCost;

/// Push constants of the overlay, as `Overlay` in shaders/floor_overlay.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct OverlayPush {
    /// Floor plane (unit square) to this eye's clip space.
    clip_from_plane: [f32; 16],
    /// The plane-local rectangle to draw (min x, min y, max x, max y; empty when min x >
    /// max x).
    rect: [f32; 4],
    /// Weights of k alpha(d) and of the caustic gain G (1 on, 0 off); 1 to draw also over
    /// the box in the live bounds buffer; the share of the floor's light the shadow takes
    /// away, written as alpha (a segmented dimmer's, 0 without one).
    switches: [f32; 4],
}

/// The overlay's pipeline and descriptors, freed on drop.
pub(crate) struct OverlayPass {
    /// The pipelines (additive, in the eye render pass): the inducer's gain alone, and with
    /// the caustic gain added.
    pipelines: Vec<Owned<vk::Pipeline>>,
    /// The static cost of one invocation of each pipeline's fragment shader.
    costs: [ShaderCost; 2],
    /// Their layout.
    layout: Owned<vk::PipelineLayout>,
    /// Pool of the sets.
    _pool: Owned<vk::DescriptorPool>,
    /// Layout of the set: gain, floor photo, sampler, caustic gain, live bounds, shadow mask.
    _set_layout: Owned<vk::DescriptorSetLayout>,
    /// The set.
    set: vk::DescriptorSet,
    /// The box of the live caustic map's non-zero texels (`[x0, y0, x1, y1]`, ends included;
    /// empty when x0 > x1), written by the live computation, read by the vertex stage on the
    /// frames that compute a map and by the host once they finished; empty until then.
    live_bounds: Buffer,
}

/// A rectangle the vertex stage draws nothing for (min x > max x).
pub(crate) const NO_RECT: [f32; 4] = [1.0, 1.0, -1.0, -1.0];

/// Where the overlay draws.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OverlayArea {
    /// A plane-local rectangle (min x, min y, max x, max y; [`NO_RECT`] for none).
    pub rect: [f32; 4],
    /// Joined with the box in the live bounds buffer, as the GPU wrote it earlier on the
    /// queue.
    pub with_live_bounds: bool,
}

impl OverlayPass {
    /// The overlay drawing in `eye_render_pass`, reading the inducer's gain `gain_view`
    /// (R16F, filtered by the sampler), the caustic gain `caustic_view` (R32F, filtered in the
    /// shader), the shadow mask `mask_view` and the scene's floor photo. With `shadow_alpha`
    /// (a display with a segmented dimmer) its pipelines add their alpha, the shadow's share,
    /// to the target's too.
    pub fn new(
        ctx: &GpuContext,
        eye_render_pass: vk::RenderPass,
        scene: &GpuScene,
        [gain_view, caustic_view, mask_view]: [vk::ImageView; 3],
        shadow_alpha: bool,
    ) -> Result<OverlayPass> {
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (2, vk::DescriptorType::SAMPLER, fragment),
                (3, vk::DescriptorType::SAMPLED_IMAGE, PUSH_STAGES),
                (
                    4,
                    vk::DescriptorType::STORAGE_BUFFER,
                    vk::ShaderStageFlags::VERTEX,
                ),
                (5, vk::DescriptorType::SAMPLED_IMAGE, fragment),
            ],
        )?;
        let mut live_bounds = Buffer::new(
            ctx,
            "live caustic bounds",
            size_of::<[u32; 4]>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let empty: [u32; 4] = [u32::MAX, u32::MAX, 0, 0];
        live_bounds
            .mapped_mut()?
            .copy_from_slice(bytemuck::bytes_of(&empty));
        let layout = pipeline::layout(
            ctx,
            Some(set_layout.raw()),
            PUSH_STAGES,
            size_of::<OverlayPush>() as u32,
        )?;
        // G through the sampler's filter where the device filters R32_SFLOAT, else four loads.
        let filtered = ctx.filters_r32_float();
        // The shadow's variants (`SHADOW`) follow the three others in OVERLAY_FS.
        let first = if shadow_alpha { 3 } else { 0 };
        let caustic = first + usize::from(filtered) + 1;
        let caustic_shader = OVERLAY_FS[caustic];
        let costs = [OVERLAY_FS_COST[first], OVERLAY_FS_COST[caustic]];
        tracing::debug!(
            "floor overlay: G {}",
            if filtered {
                "filtered by the sampler"
            } else {
                "filtered from four loads (this device does not filter R32_SFLOAT)"
            }
        );
        // The overlay neither tests nor writes depth: it is drawn before the glass, which then
        // covers it where the object is in front (on a see-through display the real floor
        // behind the glass is seen through the glass's own layer).
        let pipelines = [OVERLAY_FS[first], caustic_shader]
            .into_iter()
            .map(|fragment| {
                pipeline::create(
                    ctx,
                    &PipelineSpec {
                        render_pass: eye_render_pass,
                        layout: layout.raw(),
                        vertex: (OVERLAY_VS, c"vs_main"),
                        fragment: (fragment, c"fs_main"),
                        bindings: &[],
                        attributes: &[],
                        cull: vk::CullModeFlags::NONE,
                        depth: Depth::Off,
                        blend: if shadow_alpha {
                            Blend::AddWithAlpha
                        } else {
                            Blend::Add
                        },
                    },
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::SAMPLED_IMAGE, 4),
                (vk::DescriptorType::SAMPLER, 1),
                (vk::DescriptorType::STORAGE_BUFFER, 1),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        descriptors::write_image(ctx, set, 0, gain_view);
        descriptors::write_texture(ctx, set, 1, 2, scene.photos[0].view, scene.photo_sampler());
        descriptors::write_image(ctx, set, 3, caustic_view);
        descriptors::write_storage_buffer(ctx, set, 4, live_bounds.buffer);
        descriptors::write_image(ctx, set, 5, mask_view);
        Ok(OverlayPass {
            pipelines,
            costs,
            layout,
            _pool: pool,
            _set_layout: set_layout,
            set,
            live_bounds,
        })
    }

    /// The static cost of one fragment of the overlay, with or without the caustic gain.
    pub fn cost(&self, caustics: bool) -> ShaderCost {
        self.costs[usize::from(caustics)]
    }

    /// The buffer the live computation writes its map's bounds to.
    pub fn live_bounds_buffer(&self) -> vk::Buffer {
        self.live_bounds.buffer
    }

    /// The texels `[x0, y0, x1, y1]` (ends excluded) holding every non-zero gain of the last
    /// live computation that finished (wait for the frame first); `None` when all are 0.
    pub fn live_bounds(&self) -> Result<Option<[u32; 4]>> {
        let b: Vec<u32> = self
            .live_bounds
            .mapped()?
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok((b[0] <= b[2] && b[1] <= b[3]).then(|| [b[0], b[1], b[2] + 1, b[3] + 1]))
    }

    /// Records `area` for one eye, adding k alpha(d) and G weighted by `switches[0..2]`, and
    /// the shadow's share `switches[2]` as alpha.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with the one given to
    /// [`OverlayPass::new`], and the gain images must have been written by commands submitted
    /// before (or recorded earlier into) `cmd`, and still be alive when it executes.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eye: &EyeParams,
        world_from_plane: Mat4,
        switches: [f32; 3],
        area: OverlayArea,
    ) {
        let d = &ctx.device;
        let live = f32::from(u8::from(area.with_live_bounds));
        let push = OverlayPush {
            clip_from_plane: (eye.clip_from_world() * world_from_plane).to_cols_array(),
            rect: area.rect,
            switches: [switches[0], switches[1], live, switches[2]],
        };
        // SAFETY: the caller's contract; the pipeline, layout and set are this pass's and
        // live until the renderer has waited for its frames.
        unsafe {
            // The caustic pipeline only when G is added.
            let pipeline = &self.pipelines[usize::from(switches[1] > 0.0)];
            pipeline::Binding {
                point: vk::PipelineBindPoint::GRAPHICS,
                pipeline: pipeline.raw(),
                layout: self.layout.raw(),
                set: self.set,
                push_stages: PUSH_STAGES,
            }
            .record(d, cmd, bytemuck::bytes_of(&push));
            d.cmd_draw(cmd, 6, 1, 0, 0);
        }
        ctx.work.upload(std::mem::size_of::<OverlayPush>());
        ctx.work.draw(6);
    }
}

/// The stages reading the push constants (the vertex stage the rectangle, the fragment stage
/// the switches) and the caustic map (the vertex stage its size).
const PUSH_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::VERTEX.as_raw() | vk::ShaderStageFlags::FRAGMENT.as_raw(),
);
