//! The renderer: owns the GPU context, the scene's resources, the passes and the frame slots.
//!
//! Over 600 lines: the passes, the counting of work and the recording of a frame's passes
//! ([`record`]) live in their own modules; what stays here is a frame's life (slot choice,
//! submission for each composition and target, collecting what it measured), which reads best
//! in one place.

use std::sync::Arc;
use std::time::Instant;
use vitreous_optics::display::Compensation;

use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::blur_blend::BlurBlend;
use crate::compensation::CompensationSet;
use crate::context::GpuContext;
use crate::dimmer::DimmerPass;
use crate::error::{RenderError, Result, VkContext};
use crate::floor::{FIELD_STAMPS, FieldPassesMs, InducerFields, InducerPass, Prepared};
use crate::footprint::Footprint;
use crate::glass::{GlassPass, GlassVariant, Pick};
use crate::look::FrameParams;
use crate::memory::Buffer;
use crate::owned::Owned;
use crate::pose::ScenePose;
use crate::scene::{GpuScene, SceneDesc};
use crate::statistics;
use crate::target::{self, StereoTarget};
use crate::work::{FrameWork, PhotonWork};
use crate::world::WorldPass;

mod composition;
mod convert;
mod copy;
mod external;
mod live;
mod record;

pub use composition::Composition;

/// Frames that may be in flight at once.
pub const PIPELINE_DEPTH: usize = 2;

/// Largest eye image side the renderer accepts, in pixels.
pub const MAX_EXTENT: u32 = 8192;

/// Timestamps per frame: the start of the floor fields' work, the start and the end of the
/// eye passes, then the floor passes' own.
const QUERIES: u32 = 3 + FIELD_STAMPS;

/// What to read back from a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Want {
    /// Read back both eye images.
    pub eyes: bool,
    /// Also render and read back the real world (floor and background photos) from both eyes,
    /// for the see-through preview.
    pub world: bool,
}

/// Pixels read back from a frame: RGBA8, sRGB-encoded, rows from the top.
#[derive(Clone, Debug)]
pub struct Readback {
    /// Width of each image in pixels.
    pub width: u32,
    /// Height of each image in pixels.
    pub height: u32,
    /// Left and right eye images (the display's light).
    pub eyes: [Vec<u8>; 2],
    /// Left and right views of the real world, when asked for.
    pub world: Option<[Vec<u8>; 2]>,
}

/// Timing of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTiming {
    /// GPU time of the frame's rendering (both eyes, without the readback copy), milliseconds;
    /// `None` when the device cannot write timestamps.
    pub gpu_ms: Option<f64>,
    /// GPU time of the floor fields' work recorded before the eye passes (the shadow
    /// inducer's computation after a move, with the live caustic map's; 0 when none was
    /// due), milliseconds; `None` without timestamps.
    pub prepare_gpu_ms: Option<f64>,
    /// That work stage by stage (the parts of `prepare_gpu_ms`); `None` without timestamps.
    pub field_passes: Option<FieldPassesMs>,
    /// CPU time spent recording and submitting the frame, milliseconds.
    pub cpu_submit_ms: f64,
}

/// A finished frame.
#[derive(Clone, Debug)]
pub struct FrameResult {
    /// The sequence number [`Renderer::submit`] gave the frame.
    pub sequence: u64,
    /// Its timing.
    pub timing: FrameTiming,
    /// Its counted work.
    pub work: FrameWork,
    /// Its pixels, when asked for.
    pub readback: Option<Readback>,
}

/// A frame submitted but not yet collected.
struct Pending {
    /// Its sequence number.
    sequence: u64,
    /// What to read back.
    want: Want,
    /// CPU time spent recording and submitting it, milliseconds.
    cpu_submit_ms: f64,
    /// The floor fields' work recorded into it, confirmed once its fence signalled.
    prepared: Prepared,
    /// The work recorded into it, and the shaders it drew with (as [`FrameWork`]).
    recorded: FrameWork,
    /// Whether it counted its passes' invocations (in the slot's statistics pool).
    counted: bool,
    /// Whether a live caustic map it computed copied what it counted into the slot's
    /// `photons`.
    photons: bool,
    /// How the eye images it read back store their texels (an external image's format).
    eye_texels: convert::Texels,
}

/// Per-frame resources, used round-robin; freed on drop.
struct FrameSlot {
    /// Its place among the renderer's slots (where the glass counts its positions).
    index: usize,
    /// Command buffer recorded anew each use (freed with the renderer's command pool).
    cmd: vk::CommandBuffer,
    /// Signalled when the slot's last submission finished.
    fence: Owned<vk::Fence>,
    /// Timestamps (start of the floor fields' work, start and end of the eye passes, then
    /// the floor passes' [`FIELD_STAMPS`]), when supported.
    queries: Option<Owned<vk::QueryPool>>,
    /// Pipeline statistics of each pass (`work.rs`), once [`Renderer::count_invocations`]
    /// made them.
    statistics: Option<Owned<vk::QueryPool>>,
    /// Host-visible copy of both eye layers, then both world layers.
    readback: Buffer,
    /// Host-visible copy of what a live caustic map's computation counted (`work.rs`
    /// `PhotonWork`), and its size, once the frames count their work with live caustics on.
    photons: Option<(Buffer, u64)>,
    /// What the slot's in-flight frame is.
    pending: Option<Pending>,
}

/// Draws stereo frames of one scene.
///
/// Every GPU object is owned by a field and freed when it drops; [`Drop`] first waits for
/// the device to be idle. Fields drop in declaration order, so `ctx`, holding the device,
/// is declared last.
pub struct Renderer {
    /// Size of each eye image.
    extent: vk::Extent2D,
    /// Images owned by someone else (an OpenXR swapchain) that frames may be drawn into
    /// instead of `eye_target`; see [`Renderer::attach_external`].
    external: Option<external::External>,
    /// Frame slots.
    slots: Vec<FrameSlot>,
    /// Command pool of the slots.
    _pool: Owned<vk::CommandPool>,
    /// Eye images.
    eye_target: StereoTarget,
    /// Real-world views.
    world_target: StereoTarget,
    /// The glass pass.
    glass: GlassPass,
    /// The frame's blur of the background and surface, blended from their stacks.
    blur: BlurBlend,
    /// The real-world pass for previews.
    world: WorldPass,
    /// The segmented dimmer's panel and eye image, when the display has one.
    dimmer: Option<DimmerPass>,
    /// The shadow inducer's fields and floor overlay.
    inducer: InducerPass,
    /// The render pass all passes draw in.
    render_pass: Owned<vk::RenderPass>,
    /// The scene's GPU resources.
    scene: GpuScene,
    /// Sequence number of the next frame.
    next_sequence: u64,
    /// The object's and the light's pose for the next frame.
    pose: ScenePose,
    /// The pose the glass pass's uniform block holds once submitted work has run.
    glass_pose: ScenePose,
    /// Whether each frame proves where the glass's refracted rays all reach the background
    /// photo and draws there without the environment's lookup (`coverage.rs`); on unless
    /// turned off for a comparison.
    prove_coverage: bool,
    /// The GPU context; dropped last.
    ctx: GpuContext,
}

impl Renderer {
    /// Uploads `scene` and prepares to draw eye images of `width` x `height` pixels.
    pub fn new(ctx: GpuContext, scene: &SceneDesc, width: u32, height: u32) -> Result<Renderer> {
        if !(1..=MAX_EXTENT).contains(&width) || !(1..=MAX_EXTENT).contains(&height) {
            return Err(RenderError::InvalidInput(format!(
                "eye image size {width}x{height} is outside 1..={MAX_EXTENT} pixels per side"
            )));
        }
        let extent = vk::Extent2D { width, height };
        // Every piece frees itself when dropped: an error part way returns early and drops
        // what was made, in reverse order, before the context (a parameter, dropped after the
        // locals), so the device never goes under live objects.
        let gpu_scene = GpuScene::new(&ctx, scene)?;
        let render_pass = target::create_render_pass(&ctx)?;
        let blur = BlurBlend::new(&ctx, &gpu_scene)?;
        // With several positions per glass pixel, the real world over each pixel's footprint
        // (the photos' ripmaps), for the world view and eq. 6 over the glass alike.
        let footprint = match scene.glass_samples {
            0 | 1 => None,
            _ => Some(Arc::new(Footprint::new(&ctx, scene)?)),
        };
        // Eq. 6 over the glass, when the scene asks for it: the glass's own pipelines take away
        // what the eye already sees.
        let compensation = match scene.compensation {
            Compensation::None => None,
            Compensation::Background => Some(CompensationSet::new(
                &ctx,
                &gpu_scene,
                scene,
                footprint.clone(),
            )?),
        };
        let glass = GlassPass::new(
            &ctx,
            render_pass.raw(),
            &gpu_scene,
            scene,
            blur.views(),
            compensation,
        )?;
        let world = WorldPass::new(
            &ctx,
            render_pass.raw(),
            &gpu_scene,
            [
                scene.floor.world_from_plane,
                scene.background.world_from_plane,
            ],
            footprint,
        )?;
        let inducer = InducerPass::new(&ctx, render_pass.raw(), &gpu_scene, scene)?;
        let dimmer = match scene.dimmer {
            Some(d) => Some(DimmerPass::new(
                &ctx,
                render_pass.raw(),
                &gpu_scene,
                scene,
                d,
                extent,
            )?),
            None => None,
        };
        let eye_target = StereoTarget::new(&ctx, "eye images", render_pass.raw(), extent)?;
        let world_target = StereoTarget::new(&ctx, "world views", render_pass.raw(), extent)?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: a valid create info for the context's queue family; owned right away.
        let pool = Owned::new(
            &ctx,
            unsafe { ctx.device.create_command_pool(&pool_info, None) }
                .vk("vkCreateCommandPool")?,
        );
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool.raw())
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(PIPELINE_DEPTH as u32);
        // SAFETY: the pool is live and used only by this renderer; the buffers are freed
        // with it.
        let cmds = unsafe { ctx.device.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")?;
        let image_bytes = u64::from(width) * u64::from(height) * 4;
        let mut slots = Vec::with_capacity(PIPELINE_DEPTH);
        for cmd in cmds {
            let signalled = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            // SAFETY: a valid create info; owned right away.
            let fence = Owned::new(
                &ctx,
                unsafe { ctx.device.create_fence(&signalled, None) }.vk("vkCreateFence")?,
            );
            let queries = match ctx.timestamp_period_ns {
                Some(_) => {
                    let info = vk::QueryPoolCreateInfo::default()
                        .query_type(vk::QueryType::TIMESTAMP)
                        .query_count(QUERIES);
                    // SAFETY: a valid create info; owned right away.
                    let pool = unsafe { ctx.device.create_query_pool(&info, None) }
                        .vk("vkCreateQueryPool")?;
                    Some(Owned::new(&ctx, pool))
                }
                None => None,
            };
            let readback = Buffer::new(
                &ctx,
                "readback",
                image_bytes * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?;
            slots.push(FrameSlot {
                index: slots.len(),
                cmd,
                fence,
                queries,
                statistics: None,
                readback,
                photons: None,
                pending: None,
            });
        }
        Ok(Renderer {
            extent,
            external: None,
            slots,
            _pool: pool,
            eye_target,
            world_target,
            glass,
            blur,
            world,
            dimmer,
            inducer,
            render_pass,
            scene: gpu_scene,
            next_sequence: 0,
            pose: ScenePose::of(scene),
            glass_pose: ScenePose::of(scene),
            prove_coverage: true,
            ctx,
        })
    }

    /// Whether frames from now on prove where every refracted ray reaches the background photo
    /// and draw the glass there without the environment's lookup (on from the start; the
    /// image is the same either way, which tests and comparisons check by turning it off).
    pub fn set_coverage_proof(&mut self, on: bool) {
        self.prove_coverage = on;
    }

    /// The GPU context.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Size of each eye image in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.extent.width, self.extent.height)
    }

    /// The shadow inducer's floor-space fields (mask, distance to the shadow edge, gain),
    /// computed first if no submitted frame has. Waits for the GPU; for tests and debugging.
    pub fn inducer_fields(&mut self) -> Result<InducerFields> {
        self.inducer.read_back(&self.ctx, &self.scene)
    }

    /// Places the object and the light for the next frames. The glass follows at once; the
    /// shadow inducer's fields are computed again on the next frame that draws them, and only
    /// when `pose` differs from the last one.
    pub fn set_pose(&mut self, pose: ScenePose) {
        self.pose = pose;
        self.inducer.set_pose(pose);
    }

    /// The light's share of the floor's light from the next frame on (clamped to 0..=1),
    /// instead of the scene's `[light] share`: what the caustics add (eq. 6) and, with a
    /// segmented dimmer, how much of the shadow the panel darkens. Nothing is computed again.
    pub fn set_light_share(&mut self, share: f32) {
        self.inducer.set_light_share(share);
    }

    /// How [`Renderer::submit`] composes: for the scene's own display.
    fn own_composition(&self) -> Composition {
        if self.dimmer.is_some() {
            Composition::AlphaBlend
        } else {
            Composition::Additive
        }
    }

    /// Counts the shader invocations of each pass of every frame submitted from now on
    /// ([`FrameWork::invocations`]), with pipeline-statistics queries. Returns `false`, and
    /// counts nothing, on a device without them.
    pub fn count_invocations(&mut self) -> Result<bool> {
        if !self.ctx.pipeline_statistics {
            return Ok(false);
        }
        for slot in &mut self.slots {
            if slot.statistics.is_none() {
                slot.statistics = Some(statistics::statistics_pool(&self.ctx)?);
            }
        }
        // And the positions the glass shades, where it shades a ball's light in parts.
        self.glass.count_positions(&self.ctx)?;
        Ok(true)
    }

    /// Makes slot `index`'s copy of what a live caustic map's computation counts, where the
    /// frames count their work and live caustics are on (dropped where they no longer are).
    fn prepare_photon_readback(&mut self, index: usize) -> Result<()> {
        let slot = &mut self.slots[index];
        let bytes = self
            .inducer
            .photon_readback_bytes()
            .filter(|_| slot.statistics.is_some());
        if slot.photons.as_ref().map(|(_, n)| *n) != bytes {
            slot.photons = match bytes {
                Some(n) => {
                    let usage = vk::BufferUsageFlags::TRANSFER_DST;
                    let location = MemoryLocation::GpuToCpu;
                    let name = "live caustics' counts readback";
                    Some((Buffer::new(&self.ctx, name, n, usage, location)?, n))
                }
                None => None,
            };
        }
        Ok(())
    }

    /// How many times the shadow inducer's fields (mask, distance, gain) were computed: once
    /// for the first frame that drew them, then once per frame after the object or light moved.
    pub fn inducer_computations(&self) -> u64 {
        self.inducer.computations()
    }

    /// Makes the shadow inducer's fields and a live caustic map due again at the current
    /// pose, as for a renderer just made: after frames drawn only to warm the pipelines, the
    /// first real frame computes them as it would have.
    pub fn recompute_floor(&mut self) {
        self.inducer.recompute();
    }

    /// Records and submits a frame, composed for the scene's own display: with a segmented
    /// dimmer as for [`Composition::AlphaBlend`] (the alpha the dimmer takes away), else
    /// [`Composition::Additive`]. Returns the frame that last used the same slot
    /// ([`PIPELINE_DEPTH`] frames earlier), once finished, so the caller handles results in
    /// order while the GPU works on newer frames.
    pub fn submit(&mut self, params: &FrameParams, want: Want) -> Result<Option<FrameResult>> {
        self.submit_to(params, want, None)
    }

    /// Like [`Renderer::submit`], composed for a display that blends as `composition` says
    /// (what is drawn behind the glass, and the alpha written). A scene's segmented dimmer
    /// is driven only with [`Composition::AlphaBlend`]; the other blends leave it out.
    pub fn submit_composed(
        &mut self,
        params: &FrameParams,
        want: Want,
        composition: Composition,
    ) -> Result<Option<FrameResult>> {
        self.submit_to(
            params,
            want,
            Some(external::ExternalDraw {
                image: external::OWN_TARGET,
                composition,
            }),
        )
    }

    /// [`Renderer::submit`], drawing into an attached external image when `draw` says so.
    fn submit_to(
        &mut self,
        params: &FrameParams,
        want: Want,
        draw: Option<external::ExternalDraw>,
    ) -> Result<Option<FrameResult>> {
        let sequence = self.next_sequence;
        let slot_index = (sequence % PIPELINE_DEPTH as u64) as usize;
        let previous = self.collect(slot_index)?;
        self.prepare_photon_readback(slot_index)?;

        let started = Instant::now();
        let d = &self.ctx.device;
        let slot = &self.slots[slot_index];
        let fence = slot.fence.raw();
        // SAFETY: the slot's previous submission finished (`collect` waited for its fence, or
        // it was never submitted), so its fence and command buffer are free to reset and
        // re-record; `record` is given the recording command buffer it requires, and the
        // objects it records outlive the submission (the renderer waits before dropping them).
        let prepared = unsafe {
            d.reset_fences(&[fence]).vk("vkResetFences")?;
            d.reset_command_buffer(slot.cmd, vk::CommandBufferResetFlags::empty())
                .vk("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(slot.cmd, &begin)
                .vk("vkBeginCommandBuffer")?;
            self.ctx.work.take();
            let look = &params.look;
            let composition = draw.map_or(self.own_composition(), |d| d.composition);
            let glass = (!look.blank).then(|| {
                let pick = Pick {
                    variant: GlassVariant::of(look),
                    compensated: self.compensates(composition),
                    covered: false,
                };
                let (pose, prove) = (&self.pose, self.prove_coverage);
                let mesh = (self.extent, self.scene.index_count);
                self.glass
                    .plan(pick, (pose, prove), &params.eyes, look, mesh)
            });
            let prepared = self.record(slot, params, want, draw, glass.as_ref());
            let recorded = FrameWork {
                recorded: self.ctx.work.take(),
                invocations: None,
                photons: None,
                glass_shader: glass.as_ref().map(|g| self.glass.cost(g.pick)),
                glass_covered_shader: glass
                    .as_ref()
                    .filter(|g| g.rects.iter().any(|eye| !eye[1].is_empty()))
                    .map(|g| {
                        self.glass.cost(Pick {
                            covered: true,
                            ..g.pick
                        })
                    }),
                overlay_shader: ((look.inducer || look.caustics) && !look.blank)
                    .then(|| self.inducer.overlay_cost(look.caustics)),
                // Filled in from the device's counters once the frame finished.
                glass_positions: glass
                    .as_ref()
                    .and_then(|g| self.glass.counted_positions(g.pick)),
                glass_mesh: glass.as_ref().and_then(|g| self.glass.counted_mesh(g.pick)),
            };
            let cmds = [slot.cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            let submitted = d
                .end_command_buffer(slot.cmd)
                .vk("vkEndCommandBuffer")
                .and_then(|()| {
                    d.queue_submit(self.ctx.queue, &submit, fence)
                        .vk("vkQueueSubmit")
                });
            if let Err(e) = submitted {
                // The blends recorded into it never ran.
                self.blur.forget();
                return Err(e);
            }
            (prepared, recorded)
        };
        let (prepared, recorded) = prepared;
        // Only now, with the work on the queue, do later frames rely on what it computes.
        self.inducer.submitted(prepared);
        self.glass_pose = self.pose;
        self.slots[slot_index].pending = Some(Pending {
            sequence,
            want,
            cpu_submit_ms: started.elapsed().as_secs_f64() * 1e3,
            prepared,
            recorded,
            counted: self.slots[slot_index].statistics.is_some(),
            photons: self.slots[slot_index].photons.is_some(),
            eye_texels: draw
                .filter(|d| d.image != external::OWN_TARGET)
                .and(self.external.as_ref())
                .map_or(convert::Texels::OWN, external::External::texels),
        });
        self.next_sequence += 1;
        Ok(previous)
    }

    /// Waits for every frame in flight and returns them in submission order.
    pub fn flush(&mut self) -> Result<Vec<FrameResult>> {
        let mut done = Vec::new();
        for i in 0..PIPELINE_DEPTH as u64 {
            let slot = ((self.next_sequence + i) % PIPELINE_DEPTH as u64) as usize;
            if let Some(result) = self.collect(slot)? {
                done.push(result);
            }
        }
        Ok(done)
    }

    /// Waits for the slot's frame, if any, and takes its results.
    fn collect(&mut self, slot_index: usize) -> Result<Option<FrameResult>> {
        let d = &self.ctx.device;
        let slot = &mut self.slots[slot_index];
        let Some(pending) = slot.pending.take() else {
            return Ok(None);
        };
        if let Err(e) = self.ctx.wait_fence(slot.fence.raw(), "a frame") {
            if e.gpu_may_still_run() {
                // Still in flight: kept, so that the slot is not reset and re-recorded under
                // the GPU; a later call waits for it again.
                slot.pending = Some(pending);
            } else {
                self.inducer.finished(pending.prepared, false);
            }
            return Err(e);
        }
        self.inducer.finished(pending.prepared, true);
        let (gpu_ms, prepare_gpu_ms, field_passes) =
            match (&slot.queries, self.ctx.timestamp_period_ns) {
                (Some(pool), Some(period)) => {
                    let mut stamps = [0u64; QUERIES as usize];
                    // SAFETY: the frame that wrote both queries finished (its fence signalled
                    // above), so the results are available.
                    unsafe {
                        d.get_query_pool_results(
                            pool.raw(),
                            0,
                            &mut stamps,
                            vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                        )
                    }
                    .vk("vkGetQueryPoolResults")?;
                    let ms =
                        |a: u64, b: u64| Some(b.wrapping_sub(a) as f64 * f64::from(period) * 1e-6);
                    let mut field = [0u64; FIELD_STAMPS as usize];
                    field.copy_from_slice(&stamps[3..]);
                    (
                        ms(stamps[1], stamps[2]),
                        ms(stamps[0], stamps[1]),
                        Some(FieldPassesMs::from_stamps(stamps[0], field, period)),
                    )
                }
                _ => (None, None, None),
            };
        let invocations = match (&slot.statistics, pending.counted) {
            // SAFETY: the frame began and ended every query of the pool (`counted`), and it
            // finished (its fence signalled above).
            (Some(pool), true) => Some(
                unsafe { statistics::read_statistics(d, pool.raw()) }
                    .vk("vkGetQueryPoolResults")?,
            ),
            _ => None,
        };
        let photons = match &slot.photons {
            Some((buffer, _)) if pending.photons => Some(if pending.prepared.computed() {
                self.inducer
                    .photon_work(buffer.mapped()?)
                    .unwrap_or_default()
            } else {
                PhotonWork::default()
            }),
            _ => None,
        };
        let glass_positions = match pending.recorded.glass_positions {
            Some(counted) if pending.counted => {
                Some(self.glass.read_positions(slot_index, counted)?)
            }
            _ => None,
        };
        let glass_mesh = match pending.recorded.glass_mesh {
            Some(counted) if pending.counted => Some(self.glass.read_mesh(slot_index, counted)?),
            _ => None,
        };
        let bytes = if pending.want.eyes {
            Some(slot.readback.mapped()?)
        } else {
            None
        };
        let readback = bytes.map(|bytes| {
            let n = (self.extent.width * self.extent.height * 4) as usize;
            Readback {
                width: self.extent.width,
                height: self.extent.height,
                eyes: [&bytes[..n], &bytes[n..2 * n]].map(|eye| {
                    let mut eye = eye.to_vec();
                    pending.eye_texels.to_own(&mut eye);
                    eye
                }),
                world: pending
                    .want
                    .world
                    .then(|| [bytes[2 * n..3 * n].to_vec(), bytes[3 * n..4 * n].to_vec()]),
            }
        });
        Ok(Some(FrameResult {
            sequence: pending.sequence,
            timing: FrameTiming {
                gpu_ms,
                prepare_gpu_ms,
                field_passes,
                cpu_submit_ms: pending.cpu_submit_ms,
            },
            work: FrameWork {
                invocations,
                photons,
                glass_positions,
                glass_mesh,
                ..pending.recorded
            },
            readback,
        }))
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // SAFETY: waiting for idle has no preconditions; afterwards no submitted work uses
        // the objects the fields free as they drop (before `ctx`, declared last). A lost
        // device makes the wait fail, and objects may then be destroyed regardless.
        let _ = unsafe { self.ctx.device.device_wait_idle() };
    }
}
