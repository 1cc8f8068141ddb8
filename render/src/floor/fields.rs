//! The floor-space fields: the images the floor passes render into (one render pass and
//! framebuffer each), their push constants, and the fields as read back to the CPU.

use ash::vk;
use glam::Vec2;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Image;
use crate::owned::Owned;
use crate::pipeline::{self, FieldStart, PassBegin};

/// Indices into the pass's field targets.
pub(crate) const MASK: usize = 0;
pub(crate) const DISTANCE: usize = 1;
pub(crate) const GAIN: usize = 2;

/// Name and format of each floor-space image, in the order of the indices above.
pub(crate) const FIELDS: [(&str, vk::Format); 3] = [
    ("shadow mask", vk::Format::R8_UNORM),
    ("edge distance", vk::Format::R32_SFLOAT),
    // Half floats filter linearly on every device: the overlay samples it bilinearly.
    ("gain", vk::Format::R16_SFLOAT),
];

/// What each floor-space image holds where its passes do not draw (outside the rectangle
/// the overlay can light): lit floor, beyond the ramp (the shader's `FAR_M`), no gain.
pub(crate) const CLEAR: [f32; 3] = [0.0, 1.0e9, 0.0];

/// The ways a field's render pass may start, in the order of [`FieldTarget`]'s render passes.
const STARTS: [FieldStart; 3] = [
    FieldStart::Discard,
    FieldStart::Clear,
    FieldStart::KeepClear,
];

/// A rectangle of texels `[x0, y0, x1, y1]`, ends excluded.
pub(crate) type TexelRect = [u32; 4];

/// One floor-space image with the render passes and framebuffer that write it (dropped in
/// that order: framebuffer, render passes, image).
pub(crate) struct FieldTarget {
    /// The framebuffer over the image.
    pub framebuffer: Owned<vk::Framebuffer>,
    /// Single-attachment render passes ending in SHADER_READ_ONLY_OPTIMAL, one per
    /// [`FieldStart`] in the order of [`STARTS`] (compatible with each other).
    render_passes: Vec<Owned<vk::RenderPass>>,
    /// The image.
    pub image: Image,
    /// Its size.
    pub extent: vk::Extent2D,
}

impl FieldTarget {
    /// Creates the image `name` of `format` and `extent` with its render pass and framebuffer.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
    ) -> Result<FieldTarget> {
        let image = Image::new(
            ctx,
            &format!("inducer {name}"),
            format,
            extent,
            1,
            vk::ImageUsageFlags::COLOR_ATTACHMENT
                | vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_SRC
                | vk::ImageUsageFlags::TRANSFER_DST,
        )?;
        let mut render_passes = Vec::with_capacity(STARTS.len());
        for start in STARTS {
            render_passes.push(pipeline::field_render_pass(ctx, format, start)?);
        }
        let framebuffer =
            pipeline::framebuffer(ctx, render_passes[0].raw(), &[image.view], extent)?;
        Ok(FieldTarget {
            framebuffer,
            render_passes,
            image,
            extent,
        })
    }

    /// A render pass of this target, for making pipelines (all of them are compatible).
    pub fn render_pass(&self) -> vk::RenderPass {
        self.render_passes[0].raw()
    }

    /// Begins this target's render pass starting as `start` says over `area` (cleared to
    /// `clear` if `start` clears), with a viewport covering the whole image (so that
    /// fragment coordinates are texel coordinates) and draws limited to `scissor`, which
    /// must lie in `area`.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, and execute while `self` lives; for
    /// the `Keep` starts the image must be in SHADER_READ_ONLY_OPTIMAL when it executes.
    pub unsafe fn begin(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        start: FieldStart,
        area: TexelRect,
        clear: f32,
        scissor: TexelRect,
    ) {
        let clear = [vk::ClearValue {
            color: vk::ClearColorValue {
                float32: [clear; 4],
            },
        }];
        let rect = |[x0, y0, x1, y1]: TexelRect| vk::Rect2D {
            offset: vk::Offset2D {
                x: x0 as i32,
                y: y0 as i32,
            },
            extent: vk::Extent2D {
                width: x1 - x0,
                height: y1 - y0,
            },
        };
        let index = match start {
            FieldStart::Discard => 0,
            FieldStart::Clear => 1,
            FieldStart::KeepClear => 2,
        };
        let pass = PassBegin {
            render_pass: self.render_passes[index].raw(),
            framebuffer: self.framebuffer.raw(),
            extent: self.extent,
            area: rect(area),
            scissor: rect(scissor),
        };
        // SAFETY: the caller's contract; the render pass and framebuffer are this target's
        // and compatible.
        unsafe { pass.record(ctx, cmd, &clear) }
    }
}

/// Push constants of the floor-space passes, as `Field` in shaders/inducer_field.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FieldPush {
    /// Floor metres per texel along x and y.
    pub texel_m: [f32; 2],
    /// Texels per row of the nearest shadow texels ([`super::distance_transform::pitch`]).
    pub nearest_pitch: i32,
    /// Padding (the region is 16-byte aligned).
    pub _pad: f32,
    /// The texels the fields are computed in (`[x0, y0, x1, y1]`, ends excluded): d is
    /// "beyond the ramp" outside.
    pub region: [i32; 4],
}

/// The floor-space fields read back from the GPU, row-major from the photo's top-left.
#[derive(Clone, Debug)]
pub struct InducerFields {
    /// Side of every field, texels.
    pub resolution_px: u32,
    /// Floor metres per texel along x (u) and y (v).
    pub texel_m: Vec2,
    /// 1 where the floor is in the object's shadow, 0 where lit.
    pub mask: Vec<u8>,
    /// Distance to the shadow edge, metres; -1 inside the shadow, [`super::FAR_M`] without
    /// shadow and outside the overlay's rectangle (where the floor is farther than D from it).
    pub distance_m: Vec<f32>,
    /// k alpha(d) (eq. 2, 4): the overlay multiplies the floor photo by this.
    pub gain: Vec<f32>,
    /// The plane-local rectangle the overlay draws (see [`super::overlay_rect`]), if any.
    pub rect: Option<[f32; 4]>,
}

impl InducerFields {
    /// Index of texel (x, y).
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y * self.resolution_px + x) as usize
    }

    /// The texel holding photo coordinate `uv` (0..1, v down).
    pub fn texel_at(&self, uv: Vec2) -> (u32, u32) {
        let n = self.resolution_px;
        let t = (uv * n as f32).floor();
        (
            (t.x.max(0.0) as u32).min(n - 1),
            (t.y.max(0.0) as u32).min(n - 1),
        )
    }

    /// The gain at `uv` filtered bilinearly between texel centres, as the overlay's sampler
    /// does (clamped at the edges).
    pub fn gain_bilinear(&self, uv: Vec2) -> f32 {
        let n = self.resolution_px as i32;
        let t = uv * n as f32 - Vec2::splat(0.5);
        let base = t.floor();
        let f = t - base;
        let get = |dx: i32, dy: i32| {
            let x = (base.x as i32 + dx).clamp(0, n - 1);
            let y = (base.y as i32 + dy).clamp(0, n - 1);
            self.gain[(y * n + x) as usize]
        };
        let top = get(0, 0) * (1.0 - f.x) + get(1, 0) * f.x;
        let bottom = get(0, 1) * (1.0 - f.x) + get(1, 1) * f.x;
        top * (1.0 - f.y) + bottom * f.y
    }
}

/// Bytes per texel of the readback of the distance (R32F), the gain (R16F) and the mask (R8),
/// stored one after another (in that order, so that each starts at a multiple of its texel's
/// size).
pub(crate) const READBACK_BYTES_PER_TEXEL: u64 = 7;

impl InducerFields {
    /// Decodes a readback of `n` x `n` texels: the distances, then the gains, then the mask.
    pub(crate) fn decode(bytes: &[u8], n: u32, texel_m: Vec2, rect: Option<[f32; 4]>) -> Self {
        let t = n as usize * n as usize;
        InducerFields {
            resolution_px: n,
            texel_m,
            mask: bytes[6 * t..7 * t]
                .iter()
                .map(|&b| u8::from(b > 127))
                .collect(),
            distance_m: bytes[..4 * t]
                .chunks_exact(4)
                .map(|f| f32::from_le_bytes([f[0], f[1], f[2], f[3]]))
                .collect(),
            gain: bytes[4 * t..6 * t]
                .chunks_exact(2)
                .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
                .collect(),
            rect,
        }
    }
}

/// Timestamps the floor passes write after each of their stages, in this order: the mask, the
/// nearest shadow texels, the ramp, the live caustics' photons, their smoothing.
pub const FIELD_STAMPS: u32 = 5;
/// The stamp written after the live caustics' photons (the one after their smoothing follows).
pub(crate) const CAUSTIC_PHOTONS_STAMP: u32 = 3;

/// GPU milliseconds of each stage of the floor passes in one frame (0 for a stage that did
/// not run: nothing moved, or no live caustics).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldPassesMs {
    /// The shadow mask (eq. 1).
    pub mask_ms: f64,
    /// The nearest shadow texel of every texel (the distance transform's compute passes).
    pub nearest_ms: f64,
    /// The gain k alpha(d) (eq. 2, 4), with the distance d to the shadow edge.
    pub ramp_ms: f64,
    /// The live caustic map's photons: clearing the sums, tracing and splatting.
    pub caustic_photons_ms: f64,
    /// The live caustic map's smoothing, clamp and bound, and its copy into the image.
    pub caustic_smoothing_ms: f64,
}

impl FieldPassesMs {
    /// The stages' times from the timestamp written before them (`start`) and the
    /// [`FIELD_STAMPS`] written after each, with `period_ns` nanoseconds per tick.
    pub fn from_stamps(start: u64, stamps: [u64; FIELD_STAMPS as usize], period_ns: f32) -> Self {
        let mut previous = start;
        let ms = stamps.map(|stamp| {
            let ms = stamp.wrapping_sub(previous) as f64 * f64::from(period_ns) * 1e-6;
            previous = stamp;
            ms
        });
        FieldPassesMs {
            mask_ms: ms[0],
            nearest_ms: ms[1],
            ramp_ms: ms[2],
            caustic_photons_ms: ms[3],
            caustic_smoothing_ms: ms[4],
        }
    }

    /// The live caustic map's stages together.
    pub fn live_caustics_ms(&self) -> f64 {
        self.caustic_photons_ms + self.caustic_smoothing_ms
    }

    /// Their sum.
    pub fn total_ms(&self) -> f64 {
        self.mask_ms + self.nearest_ms + self.ramp_ms + self.live_caustics_ms()
    }
}

/// Where a frame's floor passes mark the end of each of their [`FIELD_STAMPS`] stages: a
/// timestamp, and the stage's pipeline-statistics query ended and the next one begun
/// (`work.rs`; the first is begun before the floor passes).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stamps {
    /// The frame's timestamp pool (reset before), when the device writes timestamps.
    pub pool: Option<vk::QueryPool>,
    /// The query of the first stamp.
    pub first: u32,
    /// The frame's pipeline-statistics pool (reset before; its query 0 begun), when the
    /// frame counts invocations.
    pub statistics: Option<vk::QueryPool>,
    /// Where a live caustic map's computation copies what it counted (host-visible,
    /// [`super::live::LiveCaustics::photon_readback_bytes`] long), when the frame counts its
    /// work; the computation then runs the trace that counts.
    pub photons: Option<vk::Buffer>,
}

impl Stamps {
    /// Marks the end of stages `range` (indices from 0 to [`FIELD_STAMPS`]), once all
    /// earlier work is done.
    ///
    /// # Safety
    /// `cmd` must be recording, outside a render pass, and the pools must hold the queries;
    /// the statistics query of `range.start` must be active.
    pub unsafe fn write(
        &self,
        device: &ash::Device,
        cmd: vk::CommandBuffer,
        range: std::ops::Range<u32>,
    ) {
        for i in range {
            // SAFETY: the caller's contract; query i is active, i + 1 was reset and not yet
            // begun this frame.
            unsafe {
                if let Some(pool) = self.pool {
                    device.cmd_write_timestamp(
                        cmd,
                        vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                        pool,
                        self.first + i,
                    );
                }
                if let Some(statistics) = self.statistics {
                    device.cmd_end_query(cmd, statistics, i);
                    if i + 1 < FIELD_STAMPS {
                        device.cmd_begin_query(
                            cmd,
                            statistics,
                            i + 1,
                            vk::QueryControlFlags::empty(),
                        );
                    }
                }
            }
        }
    }
}
