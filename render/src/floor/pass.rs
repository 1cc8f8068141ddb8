//! The floor pass: builds the floor-space fields' pipelines once per scene and records their
//! computation (mask, distance transform, distance, ramp, live caustics) when a frame first needs
//! them (progress.rs tracks whether it has really run; readback.rs copies the fields back).
//!
//! Just over 600 lines, one idea: the pass's state and each step of its life (build, pose,
//! prepare, record, the switch to live caustics and their read-outs, the light's share) act on
//! the same private fields; splitting the steps apart would open those fields to the module.

use ash::vk;
use glam::{Mat4, Vec2, Vec3};
use vitreous_optics::camera::EyeParams;
use vitreous_optics::live_caustics::LiveCausticsDesc;

use super::distance_transform::{self, DIST, DistanceTransform, Ramp};
use super::fields::{
    CAUSTIC_PHOTONS_STAMP, CLEAR, DISTANCE, FIELD_STAMPS, FIELDS, FieldPush, FieldTarget, GAIN,
    MASK, Stamps, TexelRect,
};
use super::geometry::{Floor, caustic_rect, shadow_of, texel_rect, texels_plane_rect, union_rect};
use super::live::LiveCaustics;
use super::live_mesh::LiveMesh;
use super::mask::MaskPass;
use super::overlay::{NO_RECT, OverlayArea, OverlayPass};
use super::progress::{Prepared, Progress, Written};
use crate::context::GpuContext;
use crate::descriptors;
use crate::error::Result;
use crate::memory::{Image, upload_texture};
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, FieldStart, PipelineSpec};
use crate::pose::ScenePose;
use crate::scene::{GpuScene, InducerDesc, SceneDesc};
use crate::shaders;
use crate::work::PhotonWork;

/// The shadow inducer's floor-space fields, the passes that compute them and the overlay; all
/// GPU objects are freed on drop.
pub(crate) struct InducerPass {
    /// k, D and the resolution.
    pub(super) desc: InducerDesc,
    /// Floor metres per texel along x and y.
    pub(super) texel_m: Vec2,
    /// The floor plane's transform (unit square to world).
    world_from_plane: Mat4,
    /// The floor's frame.
    floor: Floor,
    /// The mesh's vertices, model space (to bound the shadow of each pose).
    positions: Vec<Vec3>,
    /// The object's transform and the light the fields are (or are due to be) computed for.
    pose: ScenePose,
    /// Plane-local rectangle the inducer's light covers; `None` when nothing can be lit.
    pub(super) rect: Option<[f32; 4]>,
    /// Plane-local rectangle of the caustics' non-zero extent; `None` without caustics or
    /// while only the GPU knows it.
    caustic_rect: Option<[f32; 4]>,
    /// A live map is computed for the current pose and the host has not yet read its bounds:
    /// the overlay takes them from the GPU ([`OverlayPass::live_bounds`]).
    live_rect_on_gpu: bool,
    /// The caustic gain's weight when caustics are on: the light's share of the floor's light.
    caustic_share: f32,
    /// What has really been computed.
    pub(super) progress: Progress,
    /// The overlay drawn in the eye passes.
    overlay: OverlayPass,
    /// The shadow mask's pipelines and what the current pose draws.
    mask: MaskPass,
    /// The distance field's pipeline (`DIST`), for read backs.
    field_pipelines: Vec<Owned<vk::Pipeline>>,
    /// Their pipeline layout.
    field_layout: Owned<vk::PipelineLayout>,
    /// Pool of the sets below.
    _pool: Owned<vk::DescriptorPool>,
    /// Set layout of the full-screen passes: the mask and the nearest shadow texels.
    _field_set_layout: Owned<vk::DescriptorSetLayout>,
    /// Their set.
    field_set: vk::DescriptorSet,
    /// The caustic gain G (R32F, filtered by the overlay; zeros without a map).
    caustic: Image,
    /// Its size: the bake's, or the fields' without one.
    caustic_extent: vk::Extent2D,
    /// Caustics computed per pose into `caustic`, once enabled.
    live: Option<LiveCaustics>,
    /// The nearest shadow texel of every texel (read by the distance and ramp passes).
    transform: DistanceTransform,
    /// Mask, distance and gain, in the order of [`FIELDS`].
    pub(super) targets: Vec<FieldTarget>,
}

impl InducerPass {
    /// Prepares the passes for the scene's object, light and floor; the overlay pipeline draws
    /// in `eye_render_pass`. Nothing is computed yet. On an error part way, what was made is
    /// freed.
    pub fn new(
        ctx: &GpuContext,
        eye_render_pass: vk::RenderPass,
        scene: &GpuScene,
        desc: &SceneDesc,
    ) -> Result<InducerPass> {
        let params = desc.inducer;
        let n = params.resolution_px;
        let floor = Floor::new(desc.floor.world_from_plane);
        let pose = ScenePose::of(desc);
        let (mask_clip_from_model, rect) = shadow_of(&floor, &params, desc.mesh.positions, &pose);
        let field_extent = vk::Extent2D {
            width: n,
            height: n,
        };
        // G is zeros when the scene has no map, so that the overlay always reads a valid
        // image (and live caustics have a map to write, at the fields' size).
        let zeros;
        let (caustic_extent, caustic_gain, caustic_rect) = match &desc.caustics {
            Some(c) => (
                vk::Extent2D {
                    width: c.width,
                    height: c.height,
                },
                c.gain,
                caustic_rect(c.width, c.height, c.gain),
            ),
            None => {
                zeros = vec![0.0f32; (n * n) as usize];
                (field_extent, &zeros[..], None)
            }
        };

        let mut targets = Vec::with_capacity(FIELDS.len());
        for (name, format) in FIELDS {
            targets.push(FieldTarget::new(ctx, name, format, field_extent)?);
        }

        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let (positions, indices) = (desc.mesh.positions, desc.mesh.indices);
        let (closed, convex) = vitreous_optics::convex::closed_and_convex(positions, indices);
        let mut mask = MaskPass::new(ctx, targets[MASK].render_pass(), &desc.mesh, convex, closed)?;
        mask.set_pose(mask_clip_from_model, positions);

        let field_set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (1, vk::DescriptorType::STORAGE_BUFFER, fragment),
            ],
        )?;
        let field_layout = pipeline::layout(
            ctx,
            Some(field_set_layout.raw()),
            fragment,
            size_of::<FieldPush>() as u32,
        )?;
        // In the order of their indices (DIST), with the field each writes.
        let field_stages = [(shaders::DISTANCE_FS, c"fs_distance", DISTANCE)];
        let mut field_pipelines = Vec::with_capacity(field_stages.len());
        for (spirv, entry, target) in field_stages {
            field_pipelines.push(pipeline::create(
                ctx,
                &PipelineSpec {
                    render_pass: targets[target].render_pass(),
                    layout: field_layout.raw(),
                    vertex: (shaders::FIELD_VS, c"vs_main"),
                    fragment: (spirv, entry),
                    bindings: &[],
                    attributes: &[],
                    cull: vk::CullModeFlags::NONE,
                    depth: Depth::Off,
                    blend: Blend::Replace,
                },
            )?);
        }

        let caustic = upload_texture(
            ctx,
            "caustic gain",
            vk::Format::R32_SFLOAT,
            caustic_extent,
            bytemuck::cast_slice(caustic_gain),
        )?;
        let mask_view = targets[MASK].image.view;
        let ramp = Ramp {
            k: params.k,
            width_m: params.ramp_width_m,
            texel_m: floor.size_m / n as f32,
        };
        let transform = DistanceTransform::new(ctx, mask_view, n, ramp)?;
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::SAMPLED_IMAGE, 1),
                (vk::DescriptorType::STORAGE_BUFFER, 1),
            ],
        )?;
        let field_set = descriptors::allocate_set(ctx, pool.raw(), field_set_layout.raw())?;
        descriptors::write_image(ctx, field_set, 0, mask_view);
        descriptors::write_storage_buffer(ctx, field_set, 1, transform.nearest.buffer);
        let overlay = OverlayPass::new(
            ctx,
            eye_render_pass,
            scene,
            [targets[GAIN].image.view, caustic.view, mask_view],
            desc.dimmer.is_some(),
        )?;

        Ok(InducerPass {
            desc: params,
            texel_m: floor.size_m / n as f32,
            world_from_plane: floor.world_from_plane,
            floor,
            positions: desc.mesh.positions.to_vec(),
            pose,
            rect,
            caustic_rect,
            live_rect_on_gpu: false,
            caustic_share: desc.light.share,
            progress: Progress::default(),
            overlay,
            mask,
            field_pipelines,
            field_layout,
            _pool: pool,
            _field_set_layout: field_set_layout,
            field_set,
            caustic,
            caustic_extent,
            transform,
            live: None,
            targets,
        })
    }

    /// Moves the object or the light: when `pose` differs from the current one, the shadow's
    /// projection and the overlay's rectangle follow at once, and the fields (eq. 1-5,
    /// unchanged) are computed again by the next frame that draws the overlay.
    pub fn set_pose(&mut self, pose: ScenePose) {
        if pose == self.pose {
            return;
        }
        let (clip, rect) = shadow_of(&self.floor, &self.desc, &self.positions, &pose);
        self.mask.set_pose(clip, &self.positions);
        self.rect = rect;
        self.pose = pose;
        if self.live.is_some() {
            // Where the GPU finds it, until the new map's computation has finished.
            (self.caustic_rect, self.live_rect_on_gpu) = (None, true);
        }
        self.progress.invalidate();
    }

    /// Computes the caustic gain map on the GPU for each pose from now on (with the fields,
    /// so on the next frame drawing the overlay and after every move), at the map's current
    /// size (the bake's, or the inducer's resolution without one); the overlay covers the box
    /// of its non-zero texels, read by the GPU until the host can read it.
    pub fn enable_live(
        &mut self,
        ctx: &GpuContext,
        desc: &SceneDesc,
        live: LiveCausticsDesc,
    ) -> Result<()> {
        let extent = self.caustic_extent;
        super::live::check(&live)?;
        let mesh = LiveMesh::new(ctx, &desc.mesh, self.mask.convex())?;
        self.live = Some(LiveCaustics::new(
            ctx,
            mesh,
            desc.ior,
            self.world_from_plane,
            [extent.width, extent.height],
            live,
            self.overlay.live_bounds_buffer(),
        )?);
        (self.caustic_rect, self.live_rect_on_gpu) = (None, true);
        self.progress.invalidate();
        Ok(())
    }

    /// The live caustic gain map of the last finished computation, if live caustics are on.
    pub fn live_gain(&self) -> Result<Option<Vec<f32>>> {
        self.live.as_ref().map(LiveCaustics::gain).transpose()
    }

    /// The bytes a live map's computation that counts its work copies into its frame's
    /// buffer (`None` without live caustics).
    pub fn photon_readback_bytes(&self) -> Option<u64> {
        self.live.as_ref().map(LiveCaustics::photon_readback_bytes)
    }

    /// What a live map's computation counted, from the bytes it copied (`None` without live
    /// caustics).
    pub fn photon_work(&self, bytes: &[u8]) -> Option<PhotonWork> {
        self.live.as_ref().map(|live| live.photon_work(bytes))
    }

    /// How many of the live map's smoothing tiles the last finished computation wrote, and
    /// how many it has (`None` without live caustics).
    pub fn live_tiles(&self) -> Result<Option<[u32; 2]>> {
        self.live
            .as_ref()
            .map(LiveCaustics::tiles_written)
            .transpose()
    }

    /// The texels `[x0, y0, x1, y1]` (ends excluded) the last finished live computation found
    /// its non-zero gains in (`None` when all are 0, or without live caustics).
    pub fn live_bounds(&self) -> Result<Option<[u32; 4]>> {
        match self.live {
            Some(_) => self.overlay.live_bounds(),
            None => Ok(None),
        }
    }

    /// Makes the fields (and a live caustic map) due again at the current pose, as for a pass
    /// just made: the next frame that draws the overlay computes them.
    pub fn recompute(&mut self) {
        if self.live.is_some() {
            (self.caustic_rect, self.live_rect_on_gpu) = (None, true);
        }
        self.progress.invalidate();
    }

    /// How many computations of the fields were submitted since the pass was made.
    pub fn computations(&self) -> u64 {
        self.progress.computations
    }

    /// The push constants of the full-screen pass.
    fn push(&self, region: TexelRect) -> FieldPush {
        FieldPush {
            texel_m: self.texel_m.to_array(),
            nearest_pitch: distance_transform::pitch(self.desc.resolution_px) as i32,
            _pad: 0.0,
            region: region.map(|v| v as i32),
        }
    }

    /// Records what a frame drawing the overlay still needs: the fields' computation (and the
    /// live caustic map's) when no submitted work holds it. Returns what was recorded, for
    /// [`InducerPass::submitted`] and [`InducerPass::finished`]; records nothing (the scene
    /// is static) otherwise. With `stamps`, writes all [`super::FIELD_STAMPS`] timestamps,
    /// one after each stage.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, and be submitted before any command
    /// buffer recorded later that draws the overlay; `scene` must be the scene the pass was
    /// made for, and `self` and `scene` must outlive the command buffer's execution; the
    /// stamps' pool must hold their queries, reset.
    pub unsafe fn prepare(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        stamps: Option<Stamps>,
    ) -> Prepared {
        let d = &ctx.device;
        let mut prepared = self.progress.plan();
        // SAFETY: the caller's contract covers both recordings (outside a render pass, the
        // objects outlive the execution) and the stamps.
        unsafe {
            if prepared.fields {
                prepared.fields_within = self.record_pose_work(ctx, cmd, scene, stamps);
            } else if let Some(stamps) = stamps {
                stamps.write(d, cmd, 0..FIELD_STAMPS);
            }
        }
        prepared
    }

    /// The command buffer `prepared` was recorded into has been submitted.
    pub fn submitted(&mut self, prepared: Prepared) {
        self.progress.submitted(prepared);
    }

    /// The command buffer `prepared` was recorded into has finished (`ok`: its fence
    /// signalled) or failed to (its wait failed), so its results cannot be relied on. When it
    /// computed the live caustic map of the current pose, the overlay covers from now on
    /// only the box of its non-zero texels.
    pub fn finished(&mut self, prepared: Prepared, ok: bool) {
        let live_map = ok && prepared.fields && self.progress.is_current(prepared);
        self.progress.finished(prepared, ok);
        if self.live.is_some() && live_map {
            let extent = self.caustic_extent;
            self.caustic_rect = match self.overlay.live_bounds() {
                Ok(bounds) => bounds.map(|b| texels_plane_rect(b, extent.width, extent.height)),
                // Unreadable (never on a host-visible buffer): the whole floor.
                Err(_) => Some(WHOLE_FLOOR),
            };
            self.live_rect_on_gpu = false;
        }
    }

    /// The plane-local rectangle the overlay draws for these switches, if any.
    pub fn overlay_rect(&self, inducer: bool, caustics: bool) -> Option<[f32; 4]> {
        union_rect(
            self.rect.filter(|_| inducer),
            self.caustic_rect.filter(|_| caustics),
        )
    }

    /// Records what a new pose needs: the fields ([`InducerPass::record_fields`]) and, with
    /// live caustics, the caustic map. Returns the fields' texels as `record_fields` does.
    ///
    /// # Safety
    /// As [`InducerPass::prepare`].
    pub(super) unsafe fn record_pose_work(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        stamps: Option<Stamps>,
    ) -> Option<TexelRect> {
        // SAFETY: the caller's contract, which is both recordings'.
        unsafe {
            let within = self.record_fields(ctx, cmd, scene, stamps);
            match &self.live {
                Some(live) => live.record(ctx, cmd, &self.pose, &self.caustic, stamps),
                None => {
                    if let Some(stamps) = stamps {
                        stamps.write(&ctx.device, cmd, CAUSTIC_PHOTONS_STAMP..FIELD_STAMPS);
                    }
                }
            }
            within
        }
    }

    /// Records the mask, the distance transform and the distance and ramp passes, each stage
    /// followed by its stamp (the first three of `stamps`, before the caustics'); returns the texels that may differ
    /// from the cleared values once they ran (the overlay's rectangle).
    ///
    /// Only that rectangle is computed (the shadow and its ramp); the rest of each field
    /// keeps its cleared value (lit, beyond the ramp, no gain). So only the rectangle and
    /// where the last submitted computation drew are cleared or drawn; the distance transform
    /// only runs in the rectangle, as nothing reads it elsewhere.
    ///
    /// # Safety
    /// As [`InducerPass::prepare`].
    unsafe fn record_fields(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        stamps: Option<Stamps>,
    ) -> Option<TexelRect> {
        let d = &ctx.device;
        let stamp = |range| {
            if let Some(stamps) = stamps {
                // SAFETY: the caller's contract (recording outside a render pass, queries
                // reset).
                unsafe { stamps.write(d, cmd, range) };
            }
        };
        let n = self.desc.resolution_px;
        let region = self.rect.map(|r| texel_rect(r, n, n));
        let (before, clear_start) = match self.progress.fields_written {
            Written::Anywhere => (Some([0, 0, n, n]), FieldStart::Clear),
            Written::Within(before) => (before, FieldStart::KeepClear),
        };
        // Nothing drawn before nor now: every field already holds its cleared value.
        let Some(area) = union_rect(before, region) else {
            stamp(0..CAUSTIC_PHOTONS_STAMP);
            return None;
        };
        // SAFETY: the caller's contract: `cmd` records outside a render pass and everything
        // bound (this pass's pipelines, sets and targets, the scene's buffers) outlives it;
        // the `Keep` starts are used only once submitted work drew the images.
        unsafe {
            if region.is_some() {
                self.mask.record_upload(ctx, cmd);
            }
            let mask = &self.targets[MASK];
            mask.begin(
                ctx,
                cmd,
                clear_start,
                area,
                CLEAR[MASK],
                region.unwrap_or(area),
            );
            if region.is_some() {
                self.mask.record_draw(ctx, cmd, scene);
            }
            d.cmd_end_render_pass(cmd);
            stamp(0..1);
            let Some(region) = region else {
                // No shadow: no light either; only where the last computation drew is cleared.
                stamp(1..2);
                self.targets[GAIN].begin(ctx, cmd, clear_start, area, CLEAR[GAIN], area);
                d.cmd_end_render_pass(cmd);
                stamp(2..3);
                return None;
            };
            self.transform.record(ctx, cmd, region, area);
            stamp(1..2);
            let discard = clear_start == FieldStart::Clear;
            let gain = self.targets[GAIN].image.image;
            self.transform.record_gain_copy(d, cmd, gain, area, discard);
            stamp(2..3);
        }
        region
    }

    /// Records the distance field's pass over the whole image (d of eq. 2 per texel: -1 in
    /// the shadow, [`super::FAR_M`] beyond the fields' region), from the mask and the nearest
    /// shadow texels of the last computation recorded, for a read back: the frames' ramp
    /// computes d itself and nothing else reads the field.
    ///
    /// # Safety
    /// As [`InducerPass::prepare`], after the pose's fields were recorded into `cmd` or into
    /// a command buffer submitted earlier.
    pub(super) unsafe fn record_distance(&self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        let n = self.desc.resolution_px;
        let whole = [0, 0, n, n];
        // SAFETY: the caller's contract; every texel is drawn or cleared, so the image's
        // earlier contents do not matter.
        unsafe {
            match self.rect.map(|r| texel_rect(r, n, n)) {
                Some(region) => {
                    let push = self.push(region);
                    self.full_screen(
                        ctx,
                        cmd,
                        (DISTANCE, DIST),
                        FieldStart::Discard,
                        whole,
                        &push,
                    );
                }
                None => {
                    let target = &self.targets[DISTANCE];
                    target.begin(ctx, cmd, FieldStart::Clear, whole, CLEAR[DISTANCE], whole);
                    ctx.device.cmd_end_render_pass(cmd);
                }
            }
        }
    }

    /// One full-screen pass of `pipeline` into field `target` (`(target, pipeline)`) starting
    /// as `start` says, drawing every texel of `area` and nothing else.
    ///
    /// # Safety
    /// As [`InducerPass::prepare`]; for the `Keep` starts the target must be in
    /// SHADER_READ_ONLY_OPTIMAL.
    unsafe fn full_screen(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        (target, pipeline): (usize, usize),
        start: FieldStart,
        area: TexelRect,
        push: &FieldPush,
    ) {
        let d = &ctx.device;
        // SAFETY: the caller's contract; the pipeline, layout, set and target are this
        // pass's.
        unsafe {
            self.targets[target].begin(ctx, cmd, start, area, CLEAR[target], area);
            d.cmd_bind_pipeline(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.field_pipelines[pipeline].raw(),
            );
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.field_layout.raw(),
                0,
                &[self.field_set],
                &[],
            );
            d.cmd_push_constants(
                cmd,
                self.field_layout.raw(),
                vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(push),
            );
            d.cmd_draw(cmd, 3, 1, 0, 0);
            d.cmd_end_render_pass(cmd);
        }
        ctx.work.upload(std::mem::size_of::<FieldPush>());
        ctx.work.draw(3);
    }

    /// The light's share of the floor's light (`[light] share`, or as set).
    pub fn light_share(&self) -> f32 {
        self.caustic_share
    }

    /// Sets the light's share of the floor's light (clamped to 0..=1; a NaN is ignored).
    pub fn set_light_share(&mut self, share: f32) {
        if !share.is_nan() {
            self.caustic_share = share.clamp(0.0, 1.0);
        }
    }

    /// The static cost of one fragment of the overlay drawn with the caustics or without.
    pub fn overlay_cost(&self, caustics: bool) -> crate::work::ShaderCost {
        self.overlay.cost(caustics)
    }

    /// Records the floor overlay for one eye, inside that eye's render pass: the inducer's
    /// light if `inducer`, the corrected caustics if `caustics` (as last given to
    /// [`InducerPass::prepare`]), and with `shadow` the share of the floor's light the shadow
    /// takes away as alpha (for a segmented dimmer; the pass must have been made for a scene
    /// with one). Draws nothing when no floor texel can receive any.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with the one given to
    /// [`InducerPass::new`], after [`InducerPass::prepare`] was recorded into it or into a
    /// command buffer submitted earlier; `self` must outlive its execution.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eye: &EyeParams,
        [inducer, caustics, shadow]: [bool; 3],
    ) {
        let with_live_bounds = caustics && self.live_rect_on_gpu;
        let rect = self.overlay_rect(inducer || shadow, caustics);
        if rect.is_some() || with_live_bounds {
            let switches = [
                f32::from(u8::from(inducer)),
                if caustics { self.caustic_share } else { 0.0 },
                if shadow { self.caustic_share } else { 0.0 },
            ];
            let area = OverlayArea {
                rect: rect.unwrap_or(NO_RECT),
                with_live_bounds,
            };
            // SAFETY: the caller's contract, which is the overlay's (the live bounds are
            // written by the live computation recorded before with the pose's work).
            unsafe {
                self.overlay
                    .record(ctx, cmd, eye, self.world_from_plane, switches, area)
            };
        }
    }
}

/// The floor's whole unit square, plane-local.
const WHOLE_FLOOR: [f32; 4] = [-0.5, -0.5, 0.5, 0.5];
