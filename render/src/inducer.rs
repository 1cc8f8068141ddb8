//! The shadow inducer (METHOD.md section 1, paper Sec. 3.1.1, eq. 1-5).
//!
//! An additive display cannot darken the real floor where the virtual object's shadow falls,
//! so the floor AROUND the shadow is brightened by a ramp that fades out over a width D; the
//! eye then reads the untouched shadow region as darker than its surround.
//!
//! Everything below lives in floor space: square textures of `resolution_px` texels over the
//! floor photo's area (the unit square of [`PlaneDesc::world_from_plane`], texel (0, 0) at the
//! photo's top-left, so texture uv equals photo uv). Once per scene (on the first frame that
//! asks for the inducer, or on [`InducerPass::read_back`]) four kinds of fragment passes run
//! (no compute: lavapipe's timestamps do not see compute work, and these passes are cheap):
//!
//! 1. **Shadow mask** (eq. 1, shaders/inducer_mask.wgsl): the mesh projected from the point
//!    light onto the floor plane by a homogeneous planar projection ([`planar_shadow`]) and
//!    rasterised straight into floor space; covered texels are in shadow. For an opaque
//!    occluder this equals a conventional shadow-map lookup at each floor texel, without the
//!    map's resolution and depth-bias artefacts.
//! 2. **Jump flooding** (shaders/inducer_field.wgsl `fs_seed`, `fs_jump`): ceil(log2 N)
//!    passes with halving jumps plus one of jump 1, ping-ponging two RG32F textures of
//!    nearest-shadow-texel coordinates, nearest in metres.
//! 3. **Distance to the edge** (`fs_distance`, [`edge_distance_m`]): d in metres for every
//!    lit texel, -1 inside the shadow.
//! 4. **Gain** (`fs_ramp`, eq. 2 and 4): k alpha(d) in one R16F channel, the precombined
//!    overlay texture.
//!
//! Per eye, the floor overlay (shaders/floor_overlay.wgsl) is a world-anchored rectangle on
//! the floor plane covering only the shadow plus the ramp (bounded on the CPU from the mesh's
//! projected vertices, [`overlay_rect`]); it adds L_s = k alpha(d) L_r (eq. 3) with blend
//! (ONE, ONE), discarding texels without inducer light before it reads the photo: at most two
//! texture fetches per covered pixel. The see-through preview then shows
//! L_o = (1 + k alpha(d)) L_r (eq. 5).
//!
//! # Synchronisation
//! Each floor-space pass is its own render pass whose subpass dependencies order it after the
//! previous pass's colour writes and fragment reads and make its writes visible to fragment
//! shaders and transfers; its image ends in SHADER_READ_ONLY_OPTIMAL. A recomputation (a
//! moving light, later) recorded in a frame's command buffer therefore also waits for earlier
//! frames' overlay reads.

use std::ffi::CStr;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

use ash::vk;
use glam::{Mat4, Vec2, Vec3, Vec4};
use gpu_allocator::MemoryLocation;

use crate::camera::EyeParams;
use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use crate::memory::{Buffer, Image, subresource_range, upload_texture};
use crate::scene::{CausticsDesc, GpuScene, InducerDesc, SceneDesc, VERTEX_STRIDE};
use crate::shaders;

/// SPIR-V of one entry point of a shader in `shaders/`, compiled by build.rs.
macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

const MASK_VS: &[u8] = spirv!("inducer_mask.vs_main");
const MASK_FS: &[u8] = spirv!("inducer_mask.fs_main");
const FIELD_VS: &[u8] = spirv!("inducer_field.vs_main");
const SEED_FS: &[u8] = spirv!("inducer_field.fs_seed");
const JUMP_FS: &[u8] = spirv!("inducer_field.fs_jump");
const DISTANCE_FS: &[u8] = spirv!("inducer_field.fs_distance");
const RAMP_FS: &[u8] = spirv!("inducer_field.fs_ramp");
const COMBINE_FS: &[u8] = spirv!("inducer_field.fs_combine"); // caustics (issue 6)
const OVERLAY_VS: &[u8] = spirv!("floor_overlay.vs_main");
const OVERLAY_FS: &[u8] = spirv!("floor_overlay.fs_main");

/// Smallest accepted mask side, texels.
pub const MIN_RESOLUTION_PX: u32 = 16;
/// Largest accepted mask side, texels (a 4096^2 jump flood costs seconds on lavapipe).
pub const MAX_RESOLUTION_PX: u32 = 4096;
/// Largest accepted k.
pub const MAX_K: f32 = 10.0;
/// Largest accepted ramp width D, metres.
pub const MAX_RAMP_WIDTH_M: f32 = 100.0;

/// Distance stored for lit texels when the floor has no shadow at all, metres.
pub const FAR_M: f32 = 1.0e9;

/// eq. 2: the ramp alpha(d) = (D - d) / D for 0 <= d < D, 0 for d >= D and inside the shadow
/// (negative d). `d_m` is the distance from a lit floor point to the shadow edge.
pub fn ramp(d_m: f32, ramp_width_m: f32) -> f32 {
    if d_m < 0.0 || d_m >= ramp_width_m {
        0.0
    } else {
        (ramp_width_m - d_m) / ramp_width_m
    }
}

/// eq. 3-4: the inducer light L_s = alpha'(d) L_r with alpha'(d) = k alpha(d), for the floor's
/// recorded (linear) luminance L_r.
pub fn inducer_light(k: f32, alpha: f32, floor_luminance: f32) -> f32 {
    k * alpha * floor_luminance
}

/// eq. 5: what the wearer sees on the floor, L_o = (1 + alpha'(d)) L_r.
pub fn perceived_floor(k: f32, alpha: f32, floor_luminance: f32) -> f32 {
    floor_luminance + inducer_light(k, alpha, floor_luminance)
}

/// Distance from a lit texel to the shadow edge, metres, given the offset (in texels) from it
/// to its nearest shadow texel and the texel size in metres: the edge is taken halfway
/// between the shadow texel's centre and its lit neighbour's, half a texel short of the
/// shadow texel's centre along the offset. Same formula as `edge_distance_m` in
/// shaders/inducer_field.wgsl.
pub fn edge_distance_m(offset_texels: Vec2, texel_m: Vec2) -> f32 {
    let texels = offset_texels.length();
    (offset_texels * texel_m).length() * (1.0 - 0.5 / texels)
}

/// eq. 1 (the shadow region): the homogeneous planar projection from a point light at
/// `light_m` onto the plane through `plane_point_m` with unit normal `normal` (pointing to the
/// light's side). A point X maps to `M * (X, 1)`, whose perspective division is where the ray
/// from the light through X meets the plane; points at or beyond the light's height get
/// w <= 0. `None` when the light is not above the plane.
pub fn planar_shadow(plane_point_m: Vec3, normal: Vec3, light_m: Vec3) -> Option<Mat4> {
    let plane = normal.extend(-normal.dot(plane_point_m));
    let light = light_m.extend(1.0);
    let height = plane.dot(light);
    // Also refuses NaN.
    if height.is_nan() || height <= 1e-6 {
        return None;
    }
    // M = (plane . L) I - L plane^T: M X = h X - L (plane . X).
    let column = |j: usize| Mat4::IDENTITY.col(j) * height - light * plane[j];
    Some(Mat4::from_cols(column(0), column(1), column(2), column(3)))
}

/// The floor's geometry as the inducer uses it.
#[derive(Clone, Copy, Debug)]
struct Floor {
    /// Unit square [-0.5, 0.5]^2 at z = 0 to the world.
    world_from_plane: Mat4,
    /// Its inverse.
    plane_from_world: Mat4,
    /// The plane's centre, metres.
    center_m: Vec3,
    /// Unit normal of the photographed side.
    normal: Vec3,
    /// Width and height of the photographed area, metres.
    size_m: Vec2,
}

impl Floor {
    fn new(world_from_plane: Mat4) -> Floor {
        let x = world_from_plane.x_axis.truncate();
        let y = world_from_plane.y_axis.truncate();
        Floor {
            world_from_plane,
            plane_from_world: world_from_plane.inverse(),
            center_m: world_from_plane.w_axis.truncate(),
            normal: x.cross(y).normalize(),
            size_m: Vec2::new(x.length(), y.length()),
        }
    }
}

/// Model space to the mask's clip space: the model transform, the planar shadow projection
/// and the floor's unit square to clip space (texel row 0 at the photo's top, +y local).
fn mask_clip_from_model(floor: &Floor, shadow: Mat4, world_from_model: Mat4) -> Mat4 {
    // Plane-local (x, y) in [-0.5, 0.5] to clip (2x, -2y); depth 0; w kept, so that the
    // rasteriser clips what lies beyond the light's height.
    let clip_from_plane = Mat4::from_cols(
        Vec4::new(2.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, -2.0, 0.0, 0.0),
        Vec4::ZERO,
        Vec4::new(0.0, 0.0, 0.0, 1.0),
    );
    clip_from_plane * floor.plane_from_world * shadow * world_from_model
}

/// The part of the floor's unit square (plane-local min x, min y, max x, max y) that can
/// receive inducer light: the bounding rectangle of the mesh's shadow (the projected
/// vertices: the shadow of a triangle mesh lies in their convex hull) grown by the ramp width
/// `margin` (plane-local units) and clamped to the square. The whole square when part of the
/// mesh is at or above the light's height (the shadow is then unbounded); `None` when the
/// rectangle misses the square.
pub fn overlay_rect(
    world_positions: impl IntoIterator<Item = Vec3>,
    shadow: Mat4,
    plane_from_world: Mat4,
    margin: Vec2,
) -> Option<[f32; 4]> {
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for p in world_positions {
        let s = plane_from_world * (shadow * p.extend(1.0));
        if s.w.is_nan() || s.w <= 1e-6 {
            return Some([-0.5, -0.5, 0.5, 0.5]);
        }
        let local = s.truncate().truncate() / s.w;
        lo = lo.min(local);
        hi = hi.max(local);
    }
    let lo = (lo - margin).max(Vec2::splat(-0.5));
    let hi = (hi + margin).min(Vec2::splat(0.5));
    (lo.x < hi.x && lo.y < hi.y).then_some([lo.x, lo.y, hi.x, hi.y])
}

/// CPU reference of the distance field: for every texel of a `size` x `size` mask (nonzero =
/// shadow), the exact Euclidean distance in metres to its nearest shadow texel (searched over
/// all shadow texels with a lit 4-neighbour, which include every lit texel's nearest),
/// converted to a distance to the edge by [`edge_distance_m`]; -1 inside the shadow and
/// [`FAR_M`] when there is no shadow. Brute force: for tests.
pub fn exact_edge_distances(mask: &[u8], size: u32, texel_m: Vec2) -> Vec<f32> {
    let n = size as i32;
    let at = |x: i32, y: i32| mask[(y * n + x) as usize] != 0;
    let mut boundary = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let lit_neighbour = [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|(dx, dy)| {
                let (qx, qy) = (x + dx, y + dy);
                (0..n).contains(&qx) && (0..n).contains(&qy) && !at(qx, qy)
            });
            if at(x, y) && lit_neighbour {
                boundary.push(Vec2::new(x as f32, y as f32));
            }
        }
    }
    let mut out = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            if at(x, y) {
                out.push(-1.0);
                continue;
            }
            let p = Vec2::new(x as f32, y as f32);
            let nearest = boundary.iter().min_by(|a, b| {
                (((**a - p) * texel_m).length_squared())
                    .total_cmp(&((**b - p) * texel_m).length_squared())
            });
            out.push(match nearest {
                Some(q) => edge_distance_m(*q - p, texel_m),
                None => FAR_M,
            });
        }
    }
    out
}

/// Checks the inducer's parameters; `max_image_px` is the device's largest 2-D image side.
pub fn validate(desc: &InducerDesc, max_image_px: u32) -> Result<()> {
    if !(desc.k.is_finite() && (0.0..=MAX_K).contains(&desc.k)) {
        return Err(RenderError::InvalidInput(format!(
            "inducer k must be within 0..={MAX_K}, got {}",
            desc.k
        )));
    }
    if !(desc.ramp_width_m.is_finite()
        && desc.ramp_width_m > 0.0
        && desc.ramp_width_m <= MAX_RAMP_WIDTH_M)
    {
        return Err(RenderError::InvalidInput(format!(
            "inducer ramp width D must be > 0 and <= {MAX_RAMP_WIDTH_M} m, got {}",
            desc.ramp_width_m
        )));
    }
    let max = MAX_RESOLUTION_PX.min(max_image_px);
    if !(MIN_RESOLUTION_PX..=max).contains(&desc.resolution_px) {
        return Err(RenderError::InvalidInput(format!(
            "inducer resolution must be within {MIN_RESOLUTION_PX}..={max} texels, got {}",
            desc.resolution_px
        )));
    }
    Ok(())
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
    /// Distance to the shadow edge, metres; -1 inside the shadow, [`FAR_M`] without shadow.
    pub distance_m: Vec<f32>,
    /// k alpha(d) (eq. 2, 4): the overlay multiplies the floor photo by this.
    pub gain: Vec<f32>,
    /// The plane-local rectangle the overlay draws (see [`overlay_rect`]), if any.
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

/// Push constants of the floor-space passes, as `Field` in shaders/inducer_field.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FieldPush {
    texel_m: [f32; 2],
    step: i32,
    size: i32,
    ramp_width_m: f32,
    k: f32,
    /// fs_combine: weights of k alpha(d) and of the caustic gain G (1 on, 0 off).
    switches: [f32; 2],
}

/// Push constants of the overlay, as `Overlay` in shaders/floor_overlay.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct OverlayPush {
    clip_from_plane: [f32; 16],
    rect: [f32; 4],
}

/// Indices into [`InducerPass::images`].
const MASK: usize = 0;
const SEEDS_A: usize = 1;
const SEEDS_B: usize = 2;
const DISTANCE: usize = 3;
const GAIN: usize = 4;
/// The overlay's gain, k alpha(d) + G as switched on, at the caustic map's resolution
/// (caustics, issue 6).
const OVERLAY: usize = 5;

/// Format of each floor-space image, in the order of the indices above.
const FORMATS: [vk::Format; 6] = [
    vk::Format::R8_UNORM,
    vk::Format::R32G32_SFLOAT,
    vk::Format::R32G32_SFLOAT,
    vk::Format::R32_SFLOAT,
    // Half floats filter linearly on every device: the overlay samples it bilinearly.
    vk::Format::R16_SFLOAT,
    vk::Format::R16_SFLOAT,
];

/// Indices into [`InducerPass::field_pipelines`].
const SEED: usize = 0;
const JUMP: usize = 1;
const DIST: usize = 2;
const RAMP: usize = 3;
const COMBINE: usize = 4;

/// Largest caustic gain accepted (the overlay's gain is stored as a half float).
pub const MAX_CAUSTIC_GAIN: f32 = 60000.0;

/// Checks a caustic gain map; `max_image_px` is the device's largest 2-D image side.
pub fn validate_caustics(desc: &CausticsDesc, max_image_px: u32) -> Result<()> {
    let (w, h) = (desc.width, desc.height);
    if w == 0 || h == 0 || w > max_image_px || h > max_image_px {
        return Err(RenderError::InvalidInput(format!(
            "the caustic gain map is {w}x{h} texels; this device takes 1..={max_image_px} per side"
        )));
    }
    if desc.gain.len() != w as usize * h as usize {
        return Err(RenderError::InvalidInput(format!(
            "the caustic gain map has {} values for {w}x{h} texels",
            desc.gain.len()
        )));
    }
    if let Some(bad) = desc
        .gain
        .iter()
        .find(|g| !(g.is_finite() && (0.0..=MAX_CAUSTIC_GAIN).contains(*g)))
    {
        return Err(RenderError::InvalidInput(format!(
            "caustic gains must be finite and within 0..={MAX_CAUSTIC_GAIN}, found {bad}"
        )));
    }
    Ok(())
}

/// The plane-local rectangle (min x, min y, max x, max y) holding every non-zero texel of a
/// `width` x `height` caustic gain map (row 0 at plane-local +y), grown by one texel for the
/// bilinear footprint and clamped to the unit square; `None` when every gain is 0.
pub fn caustic_rect(width: u32, height: u32, gain: &[f32]) -> Option<[f32; 4]> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (i, &g) in gain.iter().enumerate() {
        if g > 0.0 {
            let (x, y) = (i as u32 % width, i as u32 / width);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 == u32::MAX {
        return None;
    }
    let u_lo = (x0 as f32 - 1.0) / width as f32;
    let u_hi = (x1 as f32 + 2.0) / width as f32;
    let v_lo = (y0 as f32 - 1.0) / height as f32;
    let v_hi = (y1 as f32 + 2.0) / height as f32;
    Some([
        (u_lo - 0.5).max(-0.5),
        (0.5 - v_hi).max(-0.5),
        (u_hi - 0.5).min(0.5),
        (0.5 - v_lo).min(0.5),
    ])
}

/// The smallest rectangle holding both (either may be absent).
fn union_rect(a: Option<[f32; 4]>, b: Option<[f32; 4]>) -> Option<[f32; 4]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// Sentinel of [`InducerPass::combined_for`]: the overlay gain has not been combined yet.
const NOT_COMBINED: u8 = u8::MAX;

/// The shadow inducer's floor-space fields, the passes that compute them and the overlay.
pub(crate) struct InducerPass {
    /// k, D and the resolution.
    desc: InducerDesc,
    /// Floor metres per texel along x and y.
    texel_m: Vec2,
    /// The floor plane's transform (unit square to world).
    world_from_plane: Mat4,
    /// Model space to the mask's clip space; `None` when the light is not above the floor.
    mask_clip_from_model: Option<Mat4>,
    /// Plane-local rectangle the inducer's light covers; `None` when nothing can be lit.
    rect: Option<[f32; 4]>,
    /// The caustic gain map's size (the overlay gain's), and its G values (empty without a
    /// map).
    caustic_extent: vk::Extent2D,
    caustic_gain: Vec<f32>,
    /// Plane-local rectangle of the caustics' non-zero extent; `None` without caustics.
    caustic_rect: Option<[f32; 4]>,
    /// The caustic gain G (R32F, read texel for texel by fs_combine; zeros without a map).
    caustic: Option<Image>,
    /// Extent of each image in [`InducerPass::images`].
    extents: Vec<vk::Extent2D>,
    /// Switches (bit 0 inducer, bit 1 caustics) the overlay gain was last combined for, or
    /// [`NOT_COMBINED`].
    combined_for: AtomicU8,
    /// Triangle indices of the mesh.
    index_count: u32,
    /// Mask, seeds (two), distance, gain and overlay gain, in that order ([`MASK`] ..=
    /// [`OVERLAY`]).
    images: Vec<Image>,
    /// One single-attachment render pass per image, ending in SHADER_READ_ONLY_OPTIMAL.
    render_passes: Vec<vk::RenderPass>,
    /// One framebuffer per image.
    framebuffers: Vec<vk::Framebuffer>,
    /// Layout of the mask pass (push constants only).
    mask_layout: vk::PipelineLayout,
    /// The mask pipeline.
    mask_pipeline: vk::Pipeline,
    /// Set layout of the full-screen passes: source and mask textures.
    field_set_layout: vk::DescriptorSetLayout,
    /// Their pipeline layout.
    field_layout: vk::PipelineLayout,
    /// Seed, jump, distance, ramp and combine pipelines ([`SEED`] ..= [`COMBINE`]).
    field_pipelines: Vec<vk::Pipeline>,
    /// Set layout of the overlay: gain, floor photo, sampler.
    overlay_set_layout: vk::DescriptorSetLayout,
    /// The overlay's pipeline layout.
    overlay_layout: vk::PipelineLayout,
    /// The overlay pipeline (additive, in the eye render pass).
    overlay_pipeline: vk::Pipeline,
    /// Pool of every set below.
    pool: vk::DescriptorPool,
    /// Sets reading: the mask (seed pass), seeds A, seeds B (jumps), the final seeds
    /// (distance pass), the distances (ramp pass), the gain and G (combine pass).
    field_sets: Vec<vk::DescriptorSet>,
    /// The overlay's set.
    overlay_set: vk::DescriptorSet,
    /// Whether the fields' computation has been recorded (into a frame or a one-shot).
    computed: AtomicBool,
}

impl InducerPass {
    /// Prepares the passes for the scene's object, light and floor; the overlay pipeline draws
    /// in `eye_render_pass`. Nothing is computed yet.
    pub fn new(
        ctx: &GpuContext,
        eye_render_pass: vk::RenderPass,
        scene: &GpuScene,
        desc: &SceneDesc,
    ) -> Result<InducerPass> {
        let params = desc.inducer;
        let n = params.resolution_px;
        let floor = Floor::new(desc.floor.world_from_plane);
        let shadow = planar_shadow(floor.center_m, floor.normal, desc.light.position_m);
        let texel_m = floor.size_m / n as f32;
        let rect = shadow.and_then(|shadow| {
            // Ramp width plus two texels (rasterisation and the overlay's bilinear footprint).
            let margin = Vec2::splat(params.ramp_width_m) / floor.size_m + 2.0 / n as f32;
            let world = desc
                .mesh
                .positions
                .iter()
                .map(|p| desc.world_from_model.transform_point3(*p));
            overlay_rect(world, shadow, floor.plane_from_world, margin)
        });
        let (caustic_extent, caustic_gain, caustic_rect) = match &desc.caustics {
            Some(c) => (
                vk::Extent2D {
                    width: c.width,
                    height: c.height,
                },
                c.gain.to_vec(),
                caustic_rect(c.width, c.height, c.gain),
            ),
            None => (
                vk::Extent2D {
                    width: n,
                    height: n,
                },
                Vec::new(),
                None,
            ),
        };
        let mut pass = InducerPass {
            desc: params,
            texel_m,
            world_from_plane: floor.world_from_plane,
            mask_clip_from_model: shadow
                .map(|s| mask_clip_from_model(&floor, s, desc.world_from_model)),
            rect,
            caustic_extent,
            caustic_gain,
            caustic_rect,
            caustic: None,
            extents: Vec::new(),
            combined_for: AtomicU8::new(NOT_COMBINED),
            index_count: scene.index_count,
            images: Vec::new(),
            render_passes: Vec::new(),
            framebuffers: Vec::new(),
            mask_layout: vk::PipelineLayout::null(),
            mask_pipeline: vk::Pipeline::null(),
            field_set_layout: vk::DescriptorSetLayout::null(),
            field_layout: vk::PipelineLayout::null(),
            field_pipelines: Vec::new(),
            overlay_set_layout: vk::DescriptorSetLayout::null(),
            overlay_layout: vk::PipelineLayout::null(),
            overlay_pipeline: vk::Pipeline::null(),
            pool: vk::DescriptorPool::null(),
            field_sets: Vec::new(),
            overlay_set: vk::DescriptorSet::null(),
            computed: AtomicBool::new(false),
        };
        match pass.build(ctx, eye_render_pass, scene) {
            Ok(()) => Ok(pass),
            Err(e) => {
                unsafe { pass.destroy(ctx) };
                Err(e)
            }
        }
    }

    /// Creates the GPU objects; on error the caller destroys what was made.
    fn build(
        &mut self,
        ctx: &GpuContext,
        eye_render_pass: vk::RenderPass,
        scene: &GpuScene,
    ) -> Result<()> {
        let d = &ctx.device;
        let n = self.desc.resolution_px;
        let extent = vk::Extent2D {
            width: n,
            height: n,
        };
        let names = [
            "shadow mask",
            "jump flood A",
            "jump flood B",
            "edge distance",
            "gain",
            "overlay gain",
        ];
        for (index, (name, format)) in names.into_iter().zip(FORMATS).enumerate() {
            let extent = if index == OVERLAY {
                self.caustic_extent
            } else {
                extent
            };
            self.extents.push(extent);
            self.images.push(Image::new(
                ctx,
                &format!("inducer {name}"),
                format,
                extent,
                1,
                vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            )?);
            let render_pass = field_render_pass(ctx, format)?;
            self.render_passes.push(render_pass);
            let attachments = [self.images.last().expect("just pushed").view];
            let info = vk::FramebufferCreateInfo::default()
                .render_pass(render_pass)
                .attachments(&attachments)
                .width(extent.width)
                .height(extent.height)
                .layers(1);
            self.framebuffers
                .push(unsafe { d.create_framebuffer(&info, None) }.vk("vkCreateFramebuffer")?);
        }

        let vertex = vk::ShaderStageFlags::VERTEX;
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        self.mask_layout = pipeline_layout(ctx, None, vertex, size_of::<[f32; 16]>() as u32)?;
        self.mask_pipeline = create_pipeline(
            ctx,
            &PipelineSpec {
                render_pass: self.render_passes[MASK],
                layout: self.mask_layout,
                vertex: (MASK_VS, c"vs_main"),
                fragment: (MASK_FS, c"fs_main"),
                mesh_positions: true,
                additive: false,
            },
        )?;

        self.field_set_layout = crate::pipeline::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
            ],
        )?;
        self.field_layout = pipeline_layout(
            ctx,
            Some(self.field_set_layout),
            fragment,
            size_of::<FieldPush>() as u32,
        )?;
        let field_stages = [
            (SEED_FS, c"fs_seed", SEEDS_A),
            (JUMP_FS, c"fs_jump", SEEDS_A),
            (DISTANCE_FS, c"fs_distance", DISTANCE),
            (RAMP_FS, c"fs_ramp", GAIN),
            (COMBINE_FS, c"fs_combine", OVERLAY),
        ];
        for (spirv, entry, target) in field_stages {
            let pipeline = create_pipeline(
                ctx,
                &PipelineSpec {
                    render_pass: self.render_passes[target],
                    layout: self.field_layout,
                    vertex: (FIELD_VS, c"vs_main"),
                    fragment: (spirv, entry),
                    mesh_positions: false,
                    additive: false,
                },
            )?;
            self.field_pipelines.push(pipeline);
        }

        self.overlay_set_layout = crate::pipeline::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (2, vk::DescriptorType::SAMPLER, fragment),
            ],
        )?;
        self.overlay_layout = pipeline_layout(
            ctx,
            Some(self.overlay_set_layout),
            vertex,
            size_of::<OverlayPush>() as u32,
        )?;
        self.overlay_pipeline = create_pipeline(
            ctx,
            &PipelineSpec {
                render_pass: eye_render_pass,
                layout: self.overlay_layout,
                vertex: (OVERLAY_VS, c"vs_main"),
                fragment: (OVERLAY_FS, c"fs_main"),
                mesh_positions: false,
                additive: true,
            },
        )?;

        // The caustic gain G; zeros when the scene has no map, so that fs_combine always
        // reads a valid image of the overlay gain's size.
        let zeros;
        let gain: &[f32] = if self.caustic_gain.is_empty() {
            zeros = vec![0.0f32; (n * n) as usize];
            &zeros
        } else {
            &self.caustic_gain
        };
        self.caustic = Some(upload_texture(
            ctx,
            "caustic gain",
            vk::Format::R32_SFLOAT,
            self.caustic_extent,
            bytemuck::cast_slice(gain),
        )?);
        self.pool = crate::pipeline::pool(
            ctx,
            7,
            &[
                (vk::DescriptorType::SAMPLED_IMAGE, 14),
                (vk::DescriptorType::SAMPLER, 1),
            ],
        )?;
        let final_seeds = self.jump_targets().last().map_or(SEEDS_A, |&(_, to)| to);
        for source in [MASK, SEEDS_A, SEEDS_B, final_seeds, DISTANCE] {
            let set = crate::pipeline::allocate_set(ctx, self.pool, self.field_set_layout)?;
            crate::pipeline::write_image(ctx, set, 0, self.images[source].view);
            crate::pipeline::write_image(ctx, set, 1, self.images[MASK].view);
            self.field_sets.push(set);
        }
        let set = crate::pipeline::allocate_set(ctx, self.pool, self.field_set_layout)?;
        crate::pipeline::write_image(ctx, set, 0, self.images[GAIN].view);
        let caustic_view = self.caustic.as_ref().expect("just uploaded").view;
        crate::pipeline::write_image(ctx, set, 1, caustic_view);
        self.field_sets.push(set);
        self.overlay_set = crate::pipeline::allocate_set(ctx, self.pool, self.overlay_set_layout)?;
        crate::pipeline::write_image(ctx, self.overlay_set, 0, self.images[OVERLAY].view);
        crate::pipeline::write_texture(
            ctx,
            self.overlay_set,
            1,
            2,
            scene.photos[0].view,
            scene.photo_sampler,
        );
        Ok(())
    }

    /// The jump of each jump-flooding pass with the seed image it writes, after the seed pass
    /// wrote [`SEEDS_A`]: halving jumps from half the next power of two down to 1, then one
    /// more of 1 (JFA+1, which mends most of plain jump flooding's rare misses).
    fn jump_targets(&self) -> Vec<(i32, usize)> {
        let mut jumps = Vec::new();
        let mut step = self.desc.resolution_px.next_power_of_two() / 2;
        while step >= 1 {
            jumps.push(step as i32);
            step /= 2;
        }
        jumps.push(1);
        let mut to = SEEDS_A;
        jumps
            .into_iter()
            .map(|jump| {
                to = if to == SEEDS_A { SEEDS_B } else { SEEDS_A };
                (jump, to)
            })
            .collect()
    }

    /// Records the fields' computation the first time it is called, and the overlay gain's
    /// combination (k alpha(d) if `inducer`, + G if `caustics`) whenever those switches
    /// differ from the last combination's; otherwise nothing (the scene is static).
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass, and be submitted before any command
    /// buffer recorded later that draws the overlay.
    pub unsafe fn prepare(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        inducer: bool,
        caustics: bool,
    ) {
        if !self.computed.swap(true, Ordering::AcqRel) {
            unsafe { self.record_fields(ctx, cmd, scene) };
        }
        let switches = u8::from(inducer) | (u8::from(caustics) << 1);
        if self.combined_for.swap(switches, Ordering::AcqRel) != switches {
            let push = FieldPush {
                texel_m: self.texel_m.to_array(),
                step: 0,
                size: self.desc.resolution_px as i32,
                ramp_width_m: self.desc.ramp_width_m,
                k: self.desc.k,
                switches: [f32::from(u8::from(inducer)), f32::from(u8::from(caustics))],
            };
            unsafe { self.full_screen(ctx, cmd, OVERLAY, COMBINE, self.field_sets[5], &push) };
        }
    }

    /// The plane-local rectangle the overlay draws for these switches, if any.
    pub fn overlay_rect(&self, inducer: bool, caustics: bool) -> Option<[f32; 4]> {
        union_rect(
            self.rect.filter(|_| inducer),
            self.caustic_rect.filter(|_| caustics),
        )
    }

    /// Records the mask, jump-flooding, distance and ramp passes.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass.
    unsafe fn record_fields(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, scene: &GpuScene) {
        let d = &ctx.device;
        let mut push = FieldPush {
            texel_m: self.texel_m.to_array(),
            step: 0,
            size: self.desc.resolution_px as i32,
            ramp_width_m: self.desc.ramp_width_m,
            k: self.desc.k,
            switches: [0.0; 2],
        };
        unsafe {
            self.begin(ctx, cmd, MASK);
            if let Some(clip_from_model) = self.mask_clip_from_model {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.mask_pipeline);
                d.cmd_push_constants(
                    cmd,
                    self.mask_layout,
                    vk::ShaderStageFlags::VERTEX,
                    0,
                    bytemuck::bytes_of(&clip_from_model.to_cols_array()),
                );
                d.cmd_bind_vertex_buffers(cmd, 0, &[scene.vertices.buffer], &[0]);
                d.cmd_bind_index_buffer(cmd, scene.indices.buffer, 0, vk::IndexType::UINT32);
                d.cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
            }
            d.cmd_end_render_pass(cmd);

            self.full_screen(ctx, cmd, SEEDS_A, SEED, self.field_sets[0], &push);
            let mut source = SEEDS_A;
            for (jump, target) in self.jump_targets() {
                push.step = jump;
                let set = self.field_sets[if source == SEEDS_A { 1 } else { 2 }];
                self.full_screen(ctx, cmd, target, JUMP, set, &push);
                source = target;
            }
            self.full_screen(ctx, cmd, DISTANCE, DIST, self.field_sets[3], &push);
            self.full_screen(ctx, cmd, GAIN, RAMP, self.field_sets[4], &push);
        }
    }

    /// Begins the render pass writing image `target`, with a viewport covering it.
    unsafe fn begin(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, target: usize) {
        let extent = self.extents[target];
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent,
        };
        let clear = [vk::ClearValue {
            color: vk::ClearColorValue { float32: [0.0; 4] },
        }];
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_passes[target])
            .framebuffer(self.framebuffers[target])
            .render_area(area)
            .clear_values(&clear);
        let d = &ctx.device;
        unsafe {
            d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            d.cmd_set_viewport(
                cmd,
                0,
                &[vk::Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: extent.width as f32,
                    height: extent.height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }],
            );
            d.cmd_set_scissor(cmd, 0, &[area]);
        }
    }

    /// One full-screen pass of `pipeline` into image `target`.
    unsafe fn full_screen(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        target: usize,
        pipeline: usize,
        set: vk::DescriptorSet,
        push: &FieldPush,
    ) {
        let d = &ctx.device;
        unsafe {
            self.begin(ctx, cmd, target);
            d.cmd_bind_pipeline(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.field_pipelines[pipeline],
            );
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.field_layout,
                0,
                &[set],
                &[],
            );
            d.cmd_push_constants(
                cmd,
                self.field_layout,
                vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(push),
            );
            d.cmd_draw(cmd, 3, 1, 0, 0);
            d.cmd_end_render_pass(cmd);
        }
    }

    /// Records the floor overlay for one eye, inside that eye's render pass: the inducer's
    /// light if `inducer`, the corrected caustics if `caustics` (as last given to
    /// [`InducerPass::prepare`]). Draws nothing when no floor texel can receive either.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with the one given to
    /// [`InducerPass::new`], after [`InducerPass::prepare`] was recorded into it or into a
    /// command buffer submitted earlier.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eye: &EyeParams,
        inducer: bool,
        caustics: bool,
    ) {
        let Some(rect) = self.overlay_rect(inducer, caustics) else {
            return;
        };
        let d = &ctx.device;
        let push = OverlayPush {
            clip_from_plane: (eye.clip_from_world() * self.world_from_plane).to_cols_array(),
            rect,
        };
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.overlay_pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.overlay_layout,
                0,
                &[self.overlay_set],
                &[],
            );
            d.cmd_push_constants(
                cmd,
                self.overlay_layout,
                vk::ShaderStageFlags::VERTEX,
                0,
                bytemuck::bytes_of(&push),
            );
            d.cmd_draw(cmd, 6, 1, 0, 0);
        }
    }

    /// Computes the fields if that has not happened yet, then copies the mask, the distance
    /// field and the gain back to the CPU. Waits for the GPU.
    pub fn read_back(&self, ctx: &GpuContext, scene: &GpuScene) -> Result<InducerFields> {
        let n = self.desc.resolution_px;
        let texels = u64::from(n) * u64::from(n);
        // Mask (1 byte), distance (4), gain (2) per texel, one after another.
        let offsets = [(MASK, 0), (DISTANCE, texels), (GAIN, 5 * texels)];
        let mut buffer = Buffer::new(
            ctx,
            "inducer readback",
            7 * texels,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let compute = !self.computed.swap(true, Ordering::AcqRel);
        let d = &ctx.device;
        let result = ctx.one_shot(|cmd| unsafe {
            if compute {
                self.record_fields(ctx, cmd, scene);
            }
            let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
            let barrier = |image: usize, old, new, src_access, dst_access| {
                vk::ImageMemoryBarrier::default()
                    .src_access_mask(src_access)
                    .dst_access_mask(dst_access)
                    .old_layout(old)
                    .new_layout(new)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(self.images[image].image)
                    .subresource_range(range)
            };
            let to_copy: Vec<_> = offsets
                .iter()
                .map(|&(image, _)| {
                    barrier(
                        image,
                        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                        vk::AccessFlags::TRANSFER_READ,
                    )
                })
                .collect();
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::FRAGMENT_SHADER,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &to_copy,
            );
            for &(image, offset) in &offsets {
                let region = vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width: n,
                        height: n,
                        depth: 1,
                    });
                d.cmd_copy_image_to_buffer(
                    cmd,
                    self.images[image].image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.buffer,
                    &[region],
                );
            }
            let back: Vec<_> = offsets
                .iter()
                .map(|&(image, _)| {
                    barrier(
                        image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                        vk::AccessFlags::empty(),
                        vk::AccessFlags::SHADER_READ,
                    )
                })
                .collect();
            let to_host = [vk::BufferMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::HOST_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.buffer)
                .offset(0)
                .size(vk::WHOLE_SIZE)];
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[],
                &to_host,
                &back,
            );
        });
        let fields = result.map(|()| {
            let bytes = buffer.mapped();
            let t = texels as usize;
            InducerFields {
                resolution_px: n,
                texel_m: self.texel_m,
                mask: bytes[..t].iter().map(|&b| u8::from(b > 127)).collect(),
                distance_m: bytes[t..5 * t]
                    .chunks_exact(4)
                    .map(|f| f32::from_le_bytes([f[0], f[1], f[2], f[3]]))
                    .collect(),
                gain: bytes[5 * t..7 * t]
                    .chunks_exact(2)
                    .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
                    .collect(),
                rect: self.rect,
            }
        });
        unsafe { buffer.destroy(ctx) };
        fields
    }

    /// Frees the pass; safe on a partly built one.
    ///
    /// # Safety
    /// The GPU must no longer use it.
    pub unsafe fn destroy(&mut self, ctx: &GpuContext) {
        let d = &ctx.device;
        unsafe {
            for pipeline in self.field_pipelines.drain(..) {
                d.destroy_pipeline(pipeline, None);
            }
            d.destroy_pipeline(self.mask_pipeline, None);
            d.destroy_pipeline(self.overlay_pipeline, None);
            d.destroy_pipeline_layout(self.mask_layout, None);
            d.destroy_pipeline_layout(self.field_layout, None);
            d.destroy_pipeline_layout(self.overlay_layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.field_set_layout, None);
            d.destroy_descriptor_set_layout(self.overlay_set_layout, None);
            for framebuffer in self.framebuffers.drain(..) {
                d.destroy_framebuffer(framebuffer, None);
            }
            for render_pass in self.render_passes.drain(..) {
                d.destroy_render_pass(render_pass, None);
            }
            for mut image in self.images.drain(..) {
                image.destroy(ctx);
            }
            if let Some(mut image) = self.caustic.take() {
                image.destroy(ctx);
            }
        }
        self.mask_pipeline = vk::Pipeline::null();
        self.overlay_pipeline = vk::Pipeline::null();
        self.mask_layout = vk::PipelineLayout::null();
        self.field_layout = vk::PipelineLayout::null();
        self.overlay_layout = vk::PipelineLayout::null();
        self.pool = vk::DescriptorPool::null();
        self.field_set_layout = vk::DescriptorSetLayout::null();
        self.overlay_set_layout = vk::DescriptorSetLayout::null();
    }
}

/// A render pass with one colour attachment of `format`, cleared, left for fragment shaders
/// to read. Its dependencies order it after earlier reads and writes of the image (by
/// fragment shaders, attachments or transfers) and make its writes visible to later fragment
/// shaders and transfers.
fn field_render_pass(ctx: &GpuContext, format: vk::Format) -> Result<vk::RenderPass> {
    let attachments = [vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)];
    let color_ref = [vk::AttachmentReference {
        attachment: 0,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    }];
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color_ref)];
    let dependencies = [
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(
                vk::PipelineStageFlags::FRAGMENT_SHADER
                    | vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::TRANSFER,
            )
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .dst_access_mask(
                vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::COLOR_ATTACHMENT_READ,
            ),
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(
                vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::TRANSFER,
            )
            .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::TRANSFER_READ),
    ];
    let info = vk::RenderPassCreateInfo::default()
        .attachments(&attachments)
        .subpasses(&subpasses)
        .dependencies(&dependencies);
    unsafe { ctx.device.create_render_pass(&info, None) }.vk("vkCreateRenderPass")
}

/// A pipeline layout with at most one set layout and one push-constant range.
fn pipeline_layout(
    ctx: &GpuContext,
    set_layout: Option<vk::DescriptorSetLayout>,
    push_stages: vk::ShaderStageFlags,
    push_size: u32,
) -> Result<vk::PipelineLayout> {
    let set_layouts: Vec<_> = set_layout.into_iter().collect();
    let ranges = [vk::PushConstantRange {
        stage_flags: push_stages,
        offset: 0,
        size: push_size,
    }];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(&set_layouts)
        .push_constant_ranges(&ranges);
    unsafe { ctx.device.create_pipeline_layout(&info, None) }.vk("vkCreatePipelineLayout")
}

/// How one of the inducer's pipelines draws.
struct PipelineSpec<'a> {
    /// The render pass (subpass 0) it draws in.
    render_pass: vk::RenderPass,
    /// Its layout.
    layout: vk::PipelineLayout,
    /// Vertex shader SPIR-V and entry point.
    vertex: (&'a [u8], &'a CStr),
    /// Fragment shader SPIR-V and entry point.
    fragment: (&'a [u8], &'a CStr),
    /// Read vertex positions from the scene's interleaved vertex buffer (else no input).
    mesh_positions: bool,
    /// Add to the target's colour (ONE, ONE) without touching alpha (else overwrite).
    additive: bool,
}

/// Creates a triangle-list pipeline without culling or depth test, with dynamic viewport and
/// scissor.
fn create_pipeline(ctx: &GpuContext, spec: &PipelineSpec) -> Result<vk::Pipeline> {
    let d = &ctx.device;
    let module = |spirv: &[u8]| {
        let words = shaders::words(spirv);
        let info = vk::ShaderModuleCreateInfo::default().code(&words);
        unsafe { d.create_shader_module(&info, None) }.vk("vkCreateShaderModule")
    };
    let vs = module(spec.vertex.0)?;
    let fs = match module(spec.fragment.0) {
        Ok(fs) => fs,
        Err(e) => {
            unsafe { d.destroy_shader_module(vs, None) };
            return Err(e);
        }
    };
    let stages = [
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vs)
            .name(spec.vertex.1),
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(fs)
            .name(spec.fragment.1),
    ];
    let bindings = [vk::VertexInputBindingDescription {
        binding: 0,
        stride: VERTEX_STRIDE,
        input_rate: vk::VertexInputRate::VERTEX,
    }];
    let attributes = [vk::VertexInputAttributeDescription {
        location: 0,
        binding: 0,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 0,
    }];
    let vertex_input = if spec.mesh_positions {
        vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(&attributes)
    } else {
        vk::PipelineVertexInputStateCreateInfo::default()
    };
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    // The overlay neither tests nor writes depth: it is drawn before the glass, which then
    // covers it where the object is in front (on a see-through display the real floor behind
    // the glass is seen through the glass's own layer).
    let depth = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(false)
        .depth_write_enable(false);
    let blend_attachments = [if spec.additive {
        vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ZERO)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(
                vk::ColorComponentFlags::R
                    | vk::ColorComponentFlags::G
                    | vk::ColorComponentFlags::B,
            )
    } else {
        vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(false)
            .color_write_mask(vk::ColorComponentFlags::RGBA)
    }];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(spec.layout)
        .render_pass(spec.render_pass)
        .subpass(0);
    let result = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    unsafe {
        d.destroy_shader_module(vs, None);
        d.destroy_shader_module(fs, None);
    }
    result
        .map(|p| p[0])
        .map_err(|(_, e)| e)
        .vk("vkCreateGraphicsPipelines")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_follows_eq_2() {
        let d = 0.14;
        assert_eq!(ramp(-1.0, d), 0.0);
        assert_eq!(ramp(0.0, d), 1.0);
        assert!((ramp(0.07, d) - 0.5).abs() < 1e-6);
        assert_eq!(ramp(0.14, d), 0.0);
        assert_eq!(ramp(0.2, d), 0.0);
        assert!((inducer_light(0.3, 0.5, 0.8) - 0.12).abs() < 1e-6);
        assert!((perceived_floor(0.3, 1.0, 0.5) - 0.65).abs() < 1e-6);
    }

    #[test]
    fn planar_shadow_sends_points_along_the_light_ray_to_the_plane() {
        let light = Vec3::new(0.1, 1.0, -0.5);
        let m = planar_shadow(Vec3::new(0.0, -0.3, 0.0), Vec3::Y, light).unwrap();
        for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.2, -0.1, 0.3)] {
            let s = m * p.extend(1.0);
            assert!(s.w > 0.0);
            let q = s.truncate() / s.w;
            assert!((q.y + 0.3).abs() < 1e-5, "{q}");
            // q lies on the line from the light through p.
            let along = (q - light).normalize().dot((p - light).normalize());
            assert!((along - 1.0).abs() < 1e-5);
        }
        // A point above the light has no shadow on the floor.
        assert!((m * Vec3::new(0.0, 2.0, 0.0).extend(1.0)).w < 0.0);
        assert!(planar_shadow(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, -1.0, 0.0)).is_none());
    }

    #[test]
    fn edge_distance_is_half_a_texel_short_of_the_shadow_texel() {
        let h = Vec2::splat(0.002);
        assert!((edge_distance_m(Vec2::new(1.0, 0.0), h) - 0.001).abs() < 1e-7);
        assert!((edge_distance_m(Vec2::new(0.0, -3.0), h) - 0.005).abs() < 1e-7);
        let diag = edge_distance_m(Vec2::new(3.0, 4.0), h);
        assert!((diag - 0.002 * 4.5).abs() < 1e-6);
    }

    #[test]
    fn exact_distances_of_a_single_shadow_texel() {
        let mut mask = vec![0u8; 16 * 16];
        mask[5 * 16 + 5] = 1;
        let d = exact_edge_distances(&mask, 16, Vec2::splat(1.0));
        assert_eq!(d[5 * 16 + 5], -1.0);
        assert!((d[5 * 16 + 9] - 3.5).abs() < 1e-6);
        assert!((d[9 * 16 + 8] - 4.5).abs() < 1e-6);
    }

    #[test]
    fn overlay_rect_bounds_the_shadow_plus_margin() {
        let floor = Floor::new(Mat4::from_scale_rotation_translation(
            Vec3::new(1.0, 1.0, 1.0),
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, -0.3, -1.5),
        ));
        assert!(floor.normal.abs_diff_eq(Vec3::Y, 1e-6));
        let light = Vec3::new(0.0, 0.74, -2.5);
        let shadow = planar_shadow(floor.center_m, floor.normal, light).unwrap();
        let center = Vec3::new(0.0, -0.26, -1.5);
        let points = (0..64).map(|i| {
            let a = i as f32 * 0.3;
            center + Vec3::new(a.cos() * 0.04, (a * 1.7).sin() * 0.04, a.sin() * 0.04)
        });
        let rect = overlay_rect(points, shadow, floor.plane_from_world, Vec2::splat(0.14)).unwrap();
        // The shadow falls towards the viewer (+z), which is the photo's -y.
        assert!(
            rect[1] < -0.14 && rect[3] > 0.14 && rect[3] < 0.3,
            "{rect:?}"
        );
        // Something above the light: the whole floor.
        let high = [center, Vec3::new(0.0, 1.0, -2.5)];
        let all = overlay_rect(high, shadow, floor.plane_from_world, Vec2::ZERO).unwrap();
        assert_eq!(all, [-0.5, -0.5, 0.5, 0.5]);
    }
}
