//! The scene as the renderer sees it: plain data in, GPU resources out.

use ash::vk;
use glam::{Mat4, Vec2, Vec3};
use vitreous_optics::absorption::Attenuation;
use vitreous_optics::display::Compensation;
use vitreous_optics::display::dimmer::DimmerDesc;
use vitreous_optics::refraction::Refraction;

use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use crate::memory::{Buffer, Image, upload_texture, upload_volume};
use crate::owned::Owned;

/// Texels of a texture, RGBA, row-major from the top-left.
#[derive(Clone, Copy, Debug)]
pub enum TexelData<'a> {
    /// 8-bit sRGB-encoded RGBA (photos, surface textures).
    Srgb8(&'a [u8]),
    /// Linear RGBA floats (HDR environment maps).
    LinearF32(&'a [f32]),
}

/// A texture to upload.
#[derive(Clone, Copy, Debug)]
pub struct TextureDesc<'a> {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The texels.
    pub data: TexelData<'a>,
}

/// A triangle mesh in model units.
#[derive(Clone, Copy, Debug)]
pub struct MeshRef<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Vertex normals (outward).
    pub normals: &'a [Vec3],
    /// Texture coordinates.
    pub uvs: &'a [Vec2],
    /// Triangle list indices.
    pub indices: &'a [u32],
}

/// A registered real-world plane with its photo.
#[derive(Clone, Copy, Debug)]
pub struct PlaneDesc<'a> {
    /// Maps the unit square [-0.5, 0.5]^2 at z = 0 onto the plane (photo top towards +y).
    pub world_from_plane: Mat4,
    /// The photo of the real surface.
    pub photo: TextureDesc<'a>,
}

/// Everything static the renderer draws.
#[derive(Clone, Copy, Debug)]
pub struct SceneDesc<'a> {
    /// The glass object's mesh.
    pub mesh: MeshRef<'a>,
    /// Model to world transform of the object: a similarity (rotation, translation and a
    /// uniform scale; the glass pass takes a ball's surface between its vertices as a sphere
    /// in the world).
    pub world_from_model: Mat4,
    /// Relative index of refraction of the object.
    pub ior: f32,
    /// How the view ray is refracted through the object.
    pub refraction: Refraction,
    /// Absorption inside the object (Beer-Lambert; two-surface refraction only, the paper's
    /// model has no path inside). [`Attenuation::NONE`] for clear glass.
    pub attenuation: Attenuation,
    /// Latitude-longitude environment map (radiance).
    pub environment: TextureDesc<'a>,
    /// The real floor.
    pub floor: PlaneDesc<'a>,
    /// The real background.
    pub background: PlaneDesc<'a>,
    /// Scale applied to environment radiance before display.
    pub exposure: f32,
    /// The object's surface texture (mapped with the mesh's uvs), if any.
    pub surface: Option<TextureDesc<'a>>,
    /// Fraction of light the surface texture lets through, 0..1 (eq. 9's alpha is 1 minus
    /// this, times the texel's alpha).
    pub surface_transmittance: f32,
    /// The point light.
    pub light: LightDesc,
    /// Blur stack of the background photo for defocus (eq. 10-14); `None`: the photo only.
    pub background_stack: Option<BlurStackDesc<'a>>,
    /// Blur stack of the surface texture for defocus; `None`: the texture only.
    pub surface_stack: Option<BlurStackDesc<'a>>,
    // --- shadow inducer (issue 5; render/src/floor/) ---
    /// Shadow inducer parameters (eq. 2-4).
    pub inducer: InducerDesc,
    // --- end shadow inducer ---
    // --- caustics (issue 6; render/src/floor/) ---
    /// The caustic gain map G (eq. 6), if the scene has a bake; the overlay adds G L_r when
    /// [`crate::Look::caustics`] is on (nothing without a map).
    pub caustics: Option<CausticsDesc<'a>>,
    // --- end caustics ---
    /// What the display takes away from the glass's light (eq. 6 over the glass).
    pub compensation: Compensation,
    /// The floor and background photos are the room the glass refracts and reflects
    /// (`[environment] room`): every ray leaving the glass takes the photo it meets first, the
    /// environment map only where it meets neither. Off: the paper's targets (the background
    /// plane with disparity or defocus, else the environment map).
    pub room: bool,
    /// Positions along each side of a pixel whose mean is the glass's light there (`[output]
    /// glass_samples`): 1, the pixel's centre (the paper); n: an n x n grid.
    pub glass_samples: u32,
    /// The display's segmented dimmer (`[display] model = "dimmer"`), when it has one: the
    /// eye images then carry the share of the real world's light to take away as their alpha,
    /// and the light that makes up for what the soft panel takes away too much
    /// (render/src/dimmer).
    pub dimmer: Option<DimmerDesc>,
}

// --- caustics (issue 6; render/src/floor/) ---
/// A caustic gain map over the floor photo's area: `width` x `height` linear gains G >= 0,
/// row-major, row 0 at the photo's top edge (the same orientation and uvs as the photo). The
/// corrected caustics of eq. 6 are L'_c = G L_r (docs/caustics.md).
#[derive(Clone, Copy, Debug)]
pub struct CausticsDesc<'a> {
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The gains, `width * height` of them.
    pub gain: &'a [f32],
    /// The point light's irradiance on the floor with the object over that without it
    /// (`E_with / E_without`, the same texels), when the bake holds it: through an object other
    /// than a ball in the room, the glass sees the floor under it lit so (its shadow and
    /// caustic, for the light's share of the floor's light) while the object and the light
    /// are where the bake was made.
    pub light: Option<&'a [f32]>,
}
// --- end caustics ---

// --- shadow inducer (issue 5; render/src/floor/) ---
/// Parameters of the shadow inducer (METHOD.md section 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InducerDesc {
    /// k of eq. 4: the inducer's gain at the shadow edge, relative to the floor's luminance.
    pub k: f32,
    /// D of eq. 2: width of the ramp around the shadow, metres.
    pub ramp_width_m: f32,
    /// Side of the floor-space shadow mask and distance field, texels (over the floor
    /// photo's area).
    pub resolution_px: u32,
}

impl InducerDesc {
    /// The paper's HoloLens values: k = 0.3, D = 140 mm, on a 512 x 512 mask.
    pub const PAPER: InducerDesc = InducerDesc {
        k: 0.3,
        ramp_width_m: 0.14,
        resolution_px: 512,
    };
}

impl Default for InducerDesc {
    fn default() -> InducerDesc {
        InducerDesc::PAPER
    }
}
// --- end shadow inducer ---

/// An image blurred by increasing amounts: slice i is the image convolved with the Gaussian
/// of eq. 10-12 for kernel width K_g = i * `k_g_step_px`. Sampled with trilinear filtering,
/// a fractional slice position blends two neighbours, which has exactly the interpolated
/// variance (eq. 11: the variance grows linearly with K_g): one fetch whatever the blur.
#[derive(Clone, Copy, Debug)]
pub struct BlurStackDesc<'a> {
    /// Width of each slice, texels.
    pub width: u32,
    /// Height of each slice, texels.
    pub height: u32,
    /// Number of slices (at least 2).
    pub slices: u32,
    /// K_g between consecutive slices, pixels of the image.
    pub k_g_step_px: f32,
    /// sRGB-encoded RGBA8 texels, slice after slice.
    pub srgb8: &'a [u8],
}

/// A point light.
#[derive(Clone, Copy, Debug)]
pub struct LightDesc {
    /// World position, metres.
    pub position_m: Vec3,
    /// Linear RGB colour times intensity.
    pub radiance: Vec3,
    /// Fraction of the real floor's light that comes from this light, 0..=1: the caustic
    /// gain G is added times it (eq. 6 with only this share of the floor's light focused).
    pub share: f32,
}

/// Bytes per interleaved vertex: position, normal, uv.
pub(crate) const VERTEX_STRIDE: u32 = 8 * 4;

/// The scene's GPU resources.
pub(crate) struct GpuScene {
    /// Interleaved vertices.
    pub vertices: Buffer,
    /// Triangle indices.
    pub indices: Buffer,
    /// Number of indices.
    pub index_count: u32,
    /// Environment map (RGBA16F).
    pub environment: Image,
    /// Floor photo then background photo (sRGB).
    pub photos: [Image; 2],
    /// The surface texture's blur stack (3-D, sRGB); a white texel when the scene has none.
    pub surface: Image,
    /// The background photo's blur stack (3-D, sRGB), which the frame's blur is blended from
    /// (`blur_blend.rs`).
    pub background_stack: Image,
    /// The size of a slice of the background and surface stacks, texels.
    pub stack_extents: [vk::Extent2D; 2],
    /// Slices of the background and surface stacks.
    pub stack_slices: [u32; 2],
    /// K_g between slices of the background and surface stacks, pixels.
    pub stack_steps: [f32; 2],
    /// Repeating in u, clamped in v: latitude-longitude maps.
    env_sampler: Owned<vk::Sampler>,
    /// Clamped: photos.
    photo_sampler: Owned<vk::Sampler>,
}

impl GpuScene {
    /// Validates `desc` and uploads it. On an error part way, what was created is freed (every
    /// piece frees itself on drop).
    pub fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<GpuScene> {
        validate(ctx, desc)?;
        let m = desc.mesh;
        let mut interleaved = Vec::with_capacity(m.positions.len() * 8);
        for i in 0..m.positions.len() {
            interleaved.extend_from_slice(&m.positions[i].to_array());
            interleaved.extend_from_slice(&m.normals[i].to_array());
            interleaved.extend_from_slice(&m.uvs[i].to_array());
        }
        let vertices = Buffer::with_data(
            ctx,
            "vertices",
            bytemuck::cast_slice(&interleaved),
            vk::BufferUsageFlags::VERTEX_BUFFER,
        )?;
        let indices = Buffer::with_data(
            ctx,
            "indices",
            bytemuck::cast_slice(m.indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
        )?;
        let environment = upload(ctx, "environment map", &desc.environment)?;
        let floor = upload(ctx, "floor photo", &desc.floor.photo)?;
        let background = upload(ctx, "background photo", &desc.background.photo)?;
        let white = [255u8; 4];
        let surface_photo = desc.surface.unwrap_or(TextureDesc {
            width: 1,
            height: 1,
            data: TexelData::Srgb8(&white),
        });
        let (background_stack, background_extent, background_slices, background_step) =
            upload_stack(
                ctx,
                "background blur stack",
                &desc.background.photo,
                desc.background_stack,
            )?;
        let (surface, surface_extent, surface_slices, surface_step) = upload_stack(
            ctx,
            "surface blur stack",
            &surface_photo,
            desc.surface_stack,
        )?;
        Ok(GpuScene {
            vertices,
            indices,
            index_count: m.indices.len() as u32,
            environment,
            photos: [floor, background],
            surface,
            background_stack,
            stack_extents: [background_extent, surface_extent],
            stack_slices: [background_slices, surface_slices],
            stack_steps: [background_step, surface_step],
            env_sampler: sampler(ctx, vk::SamplerAddressMode::REPEAT)?,
            photo_sampler: sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE)?,
        })
    }

    /// The sampler of latitude-longitude maps (repeating in u).
    pub fn env_sampler(&self) -> vk::Sampler {
        self.env_sampler.raw()
    }

    /// The sampler of photos (clamped).
    pub fn photo_sampler(&self) -> vk::Sampler {
        self.photo_sampler.raw()
    }
}

/// Smallest accepted inducer mask side, texels.
pub const MIN_RESOLUTION_PX: u32 = 16;
/// Largest accepted inducer mask side, texels (a 4096^2 jump flood costs seconds on
/// lavapipe).
pub const MAX_RESOLUTION_PX: u32 = 4096;
/// Largest accepted inducer k.
pub const MAX_K: f32 = 10.0;
/// Largest accepted ramp width D, metres.
pub const MAX_RAMP_WIDTH_M: f32 = 100.0;
/// Largest caustic gain accepted (the overlay's gain is stored as a half float).
pub const MAX_CAUSTIC_GAIN: f32 = 60000.0;

/// Checks the inducer's parameters; `max_image_px` is the device's largest 2-D image side.
pub fn validate_inducer(desc: &InducerDesc, max_image_px: u32) -> Result<()> {
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

fn validate(ctx: &GpuContext, desc: &SceneDesc) -> Result<()> {
    let m = desc.mesh;
    let n = m.positions.len();
    if n == 0 || m.indices.is_empty() || !m.indices.len().is_multiple_of(3) {
        return Err(RenderError::InvalidInput(format!(
            "the mesh needs vertices and a whole number of triangles (has {n} vertices, {} indices)",
            m.indices.len()
        )));
    }
    if m.normals.len() != n || m.uvs.len() != n {
        return Err(RenderError::InvalidInput(format!(
            "mesh attribute counts differ: {n} positions, {} normals, {} uvs",
            m.normals.len(),
            m.uvs.len()
        )));
    }
    if let Some(bad) = m.indices.iter().find(|&&i| i as usize >= n) {
        return Err(RenderError::InvalidInput(format!(
            "mesh index {bad} is out of range for {n} vertices"
        )));
    }
    if !(desc.ior.is_finite() && desc.ior >= 1.0) {
        return Err(RenderError::InvalidInput(format!(
            "index of refraction must be finite and >= 1, got {}",
            desc.ior
        )));
    }
    // SAFETY: `physical` was enumerated from `instance`, which the context keeps alive.
    let limit = unsafe { ctx.instance.get_physical_device_properties(ctx.physical) }
        .limits
        .max_image_dimension2_d;
    validate_inducer(&desc.inducer, limit)?;
    if let Some(caustics) = &desc.caustics {
        validate_caustics(caustics, limit)?;
    }
    if !(0.0..=1.0).contains(&desc.surface_transmittance) {
        return Err(RenderError::InvalidInput(format!(
            "surface transmittance must be within 0..1, got {}",
            desc.surface_transmittance
        )));
    }
    for (name, stack, plain) in [
        (
            "background blur stack",
            &desc.background_stack,
            Some(&desc.background.photo),
        ),
        (
            "surface blur stack",
            &desc.surface_stack,
            desc.surface.as_ref(),
        ),
    ] {
        if let Some(st) = stack {
            let expected = st.width as usize * st.height as usize * 4 * st.slices as usize;
            if st.slices < 2
                || st.srgb8.len() != expected
                || st.k_g_step_px.is_nan()
                || st.k_g_step_px <= 0.0
            {
                return Err(RenderError::InvalidInput(format!(
                    "{name}: needs at least 2 slices of {}x{} RGBA8 texels ({expected} bytes) and \
                     a positive K_g step; got {} slices, {} bytes, step {}",
                    st.width,
                    st.height,
                    st.srgb8.len(),
                    st.slices,
                    st.k_g_step_px
                )));
            }
            if plain.is_none() {
                return Err(RenderError::InvalidInput(format!(
                    "{name} given without its image"
                )));
            }
        }
    }
    let mut textures = vec![
        ("environment map", &desc.environment),
        ("floor photo", &desc.floor.photo),
        ("background photo", &desc.background.photo),
    ];
    if let Some(surface) = &desc.surface {
        textures.push(("surface texture", surface));
    }
    for (name, t) in textures {
        if t.width == 0 || t.height == 0 || t.width > limit || t.height > limit {
            return Err(RenderError::InvalidInput(format!(
                "{name} is {}x{} texels; this device takes 1..={limit} per side",
                t.width, t.height
            )));
        }
        let expected = t.width as usize * t.height as usize * 4;
        let got = match t.data {
            TexelData::Srgb8(d) => d.len(),
            TexelData::LinearF32(d) => d.len(),
        };
        if got != expected {
            return Err(RenderError::InvalidInput(format!(
                "{name}: expected {expected} RGBA components for {}x{}, got {got}",
                t.width, t.height
            )));
        }
    }
    Ok(())
}

fn upload(ctx: &GpuContext, name: &str, t: &TextureDesc) -> Result<Image> {
    let extent = vk::Extent2D {
        width: t.width,
        height: t.height,
    };
    match t.data {
        TexelData::Srgb8(bytes) => {
            upload_texture(ctx, name, vk::Format::R8G8B8A8_SRGB, extent, bytes)
        }
        TexelData::LinearF32(floats) => {
            // Half floats filter linearly on every device; 32-bit floats do not.
            let halves: Vec<half::f16> = floats.iter().map(|&f| half::f16::from_f32(f)).collect();
            let bytes: Vec<u8> = halves.iter().flat_map(|h| h.to_le_bytes()).collect();
            upload_texture(ctx, name, vk::Format::R16G16B16A16_SFLOAT, extent, &bytes)
        }
    }
}

/// Uploads a blur stack as a 3-D texture, with the size of its slices; without one, the plain
/// image twice (a 3-D texture needs two slices to be one), which samples as the unblurred
/// image at any slice position.
fn upload_stack(
    ctx: &GpuContext,
    name: &str,
    plain: &TextureDesc,
    stack: Option<BlurStackDesc>,
) -> Result<(Image, vk::Extent2D, u32, f32)> {
    let extent = |w, h| vk::Extent2D {
        width: w,
        height: h,
    };
    match stack {
        Some(s) => Ok((
            upload_volume(
                ctx,
                name,
                vk::Format::R8G8B8A8_SRGB,
                extent(s.width, s.height),
                s.slices,
                s.srgb8,
            )?,
            extent(s.width, s.height),
            s.slices,
            s.k_g_step_px,
        )),
        None => {
            let TexelData::Srgb8(bytes) = plain.data else {
                return Err(RenderError::InvalidInput(format!(
                    "{name}: an 8-bit sRGB image is needed"
                )));
            };
            let twice = [bytes, bytes].concat();
            let image = upload_volume(
                ctx,
                name,
                vk::Format::R8G8B8A8_SRGB,
                extent(plain.width, plain.height),
                2,
                &twice,
            )?;
            Ok((image, extent(plain.width, plain.height), 2, 1.0))
        }
    }
}

fn sampler(ctx: &GpuContext, u_mode: vk::SamplerAddressMode) -> Result<Owned<vk::Sampler>> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::LINEAR)
        .min_filter(vk::Filter::LINEAR)
        .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
        .address_mode_u(u_mode)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .max_lod(0.0);
    // SAFETY: `info` is a valid create info; the sampler is owned by the returned value.
    let sampler = unsafe { ctx.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
    Ok(Owned::new(ctx, sampler))
}
