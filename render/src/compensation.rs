//! Eq. 6 over the glass (`[display] compensation = "background"`): each eye's glass pixels lose
//! the light of the real floor or background the eye already sees there, `max(T - B, 0)`, so the
//! display adds only what is missing. The glass's own fragment shader takes it away
//! (shaders/glass.wgsl `COMPENSATED`): no pass, draw or invocation of its own, one more fetch per
//! covered pixel. This module holds what that shader reads in its set 1: the planes and both
//! photos packed side by side, and with several positions per pixel the photos' ripmaps.

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec4};

use crate::context::GpuContext;
use crate::descriptors;
use crate::error::{RenderError, Result};
use crate::footprint::{Footprint, Levels};
use crate::memory::{Buffer, Image, upload_texture};
use crate::owned::Owned;
use crate::scene::{GpuScene, PlaneDesc, SceneDesc, TexelData};
use bytemuck::Zeroable as _;

/// The planes and where each photo lies in the packed texture (shaders/shared/seen.wgsl
/// `Planes`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Planes {
    floor_from_world: [f32; 16],
    background_from_world: [f32; 16],
    floor_rect: [f32; 4],
    background_rect: [f32; 4],
}

/// What the glass's compensated pipelines read (their set 1), freed on drop.
pub struct CompensationSet {
    _pool: Owned<vk::DescriptorPool>,
    set_layout: Owned<vk::DescriptorSetLayout>,
    set: vk::DescriptorSet,
    _seen: SeenPhotos,
    _ripmaps: Ripmaps,
}

/// What the set's bindings 3 and 4 hold.
enum Ripmaps {
    /// B over a pixel's footprint (several positions per glass pixel): the photos' ripmaps,
    /// shared with the world view.
    Read(Arc<Footprint>),
    /// One position per glass pixel: the pipelines read none; an empty table (and the seen
    /// photos) stand in.
    Unread(Box<Buffer>),
}

/// The real floor and background as the eye sees them (shaders/shared/seen.wgsl): the planes'
/// transforms and the photos packed side by side; freed on drop.
pub(crate) struct SeenPhotos {
    planes: Buffer,
    photos: Image,
}

impl SeenPhotos {
    /// Uploads `desc`'s floor and background photos and planes.
    pub(crate) fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<SeenPhotos> {
        let (w, h, packed, [floor_rect, background_rect]) = pack(&desc.floor, &desc.background)?;
        let photos = upload_texture(
            ctx,
            "seen photos",
            vk::Format::R8G8B8A8_SRGB,
            vk::Extent2D {
                width: w,
                height: h,
            },
            &packed,
        )?;
        let planes = Planes {
            floor_from_world: inverse(desc.floor.world_from_plane),
            background_from_world: inverse(desc.background.world_from_plane),
            floor_rect: floor_rect.to_array(),
            background_rect: background_rect.to_array(),
        };
        let planes = Buffer::with_data(
            ctx,
            "seen planes",
            bytemuck::bytes_of(&planes),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        Ok(SeenPhotos { planes, photos })
    }

    /// Writes the planes (binding 0), the photos (1) and the scene's photo sampler (2) into
    /// `set`, which no pending command buffer uses.
    pub(crate) fn write(&self, ctx: &GpuContext, set: vk::DescriptorSet, scene: &GpuScene) {
        descriptors::write_uniform_buffer(ctx, set, 0, self.planes.buffer);
        descriptors::write_texture(ctx, set, 1, 2, self.photos.view, scene.photo_sampler());
    }
}

/// The two photos side by side in one sRGB texture (floor left, background right), and each
/// one's normalised rectangle.
fn pack(floor: &PlaneDesc, background: &PlaneDesc) -> Result<(u32, u32, Vec<u8>, [Vec4; 2])> {
    let photo = |p: &PlaneDesc| -> Result<(u32, u32, Vec<u8>)> {
        match p.photo.data {
            TexelData::Srgb8(bytes) => Ok((p.photo.width, p.photo.height, bytes.to_vec())),
            TexelData::LinearF32(_) => Err(RenderError::Creation(
                "a real plane's photo must be 8-bit sRGB".into(),
            )),
        }
    };
    let (fw, fh, f) = photo(floor)?;
    let (bw, bh, b) = photo(background)?;
    let (w, h) = (fw + bw, fh.max(bh));
    let mut packed = vec![0u8; (w * h * 4) as usize];
    for (x0, pw, ph, pixels) in [(0, fw, fh, &f), (fw, bw, bh, &b)] {
        for y in 0..ph {
            let src = &pixels[(y * pw * 4) as usize..((y + 1) * pw * 4) as usize];
            let at = ((y * w + x0) * 4) as usize;
            packed[at..at + src.len()].copy_from_slice(src);
        }
    }
    let rect = |x0: u32, pw: u32, ph: u32| {
        Vec4::new(
            x0 as f32 / w as f32,
            0.0,
            (x0 + pw) as f32 / w as f32,
            ph as f32 / h as f32,
        )
    };
    Ok((w, h, packed, [rect(0, fw, fh), rect(fw, bw, bh)]))
}

impl CompensationSet {
    /// Uploads `desc`'s floor and background and writes the set, with `footprint` (the
    /// photos' ripmaps, which the pipelines read with several positions per glass pixel).
    pub(crate) fn new(
        ctx: &GpuContext,
        scene: &GpuScene,
        desc: &SceneDesc,
        footprint: Option<Arc<Footprint>>,
    ) -> Result<CompensationSet> {
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::UNIFORM_BUFFER, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (2, vk::DescriptorType::SAMPLER, fragment),
                (3, vk::DescriptorType::UNIFORM_BUFFER, fragment),
                (4, vk::DescriptorType::SAMPLED_IMAGE, fragment),
            ],
        )?;
        let seen = SeenPhotos::new(ctx, desc)?;
        let ripmaps = match footprint {
            Some(f) => Ripmaps::Read(f),
            None => Ripmaps::Unread(Box::new(Buffer::with_data(
                ctx,
                "ripmap levels (unread)",
                bytemuck::bytes_of(&Levels::zeroed()),
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?)),
        };
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::UNIFORM_BUFFER, 2),
                (vk::DescriptorType::SAMPLED_IMAGE, 2),
                (vk::DescriptorType::SAMPLER, 1),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        seen.write(ctx, set, scene);
        let (levels, atlas) = match &ripmaps {
            Ripmaps::Read(f) => (&f.levels, &f.atlas),
            Ripmaps::Unread(levels) => (&**levels, &seen.photos),
        };
        descriptors::write_uniform_buffer(ctx, set, 3, levels.buffer);
        descriptors::write_image(ctx, set, 4, atlas.view);
        Ok(CompensationSet {
            _pool: pool,
            set_layout,
            set,
            _seen: seen,
            _ripmaps: ripmaps,
        })
    }

    /// The set's layout (set 1 of the glass's pipeline layout).
    pub fn set_layout(&self) -> vk::DescriptorSetLayout {
        self.set_layout.raw()
    }

    /// The set, written once; no command buffer changes it.
    pub fn set(&self) -> vk::DescriptorSet {
        self.set
    }
}

/// A plane's world-to-plane transform, as the shader takes it.
fn inverse(world_from_plane: Mat4) -> [f32; 16] {
    world_from_plane.inverse().to_cols_array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TextureDesc;

    #[test]
    fn the_photos_are_packed_side_by_side_with_their_rectangles() {
        let floor = [1u8, 2, 3, 4].repeat(2 * 2);
        let wall = [9u8, 9, 9, 9].repeat(3);
        let plane = |width, height, data| PlaneDesc {
            world_from_plane: Mat4::IDENTITY,
            photo: TextureDesc {
                width,
                height,
                data: TexelData::Srgb8(data),
            },
        };
        let (w, h, packed, [f, b]) = pack(&plane(2, 2, &floor), &plane(3, 1, &wall)).unwrap();
        assert_eq!((w, h), (5, 2));
        // Row 0: two floor texels, three wall texels; row 1: two floor texels, then nothing.
        assert_eq!(&packed[..8], &[1, 2, 3, 4, 1, 2, 3, 4]);
        assert_eq!(&packed[8..20], &[9; 12]);
        assert_eq!(&packed[20..28], &[1, 2, 3, 4, 1, 2, 3, 4]);
        assert_eq!(&packed[28..40], &[0; 12]);
        assert_eq!(f, Vec4::new(0.0, 0.0, 0.4, 1.0));
        assert_eq!(b, Vec4::new(0.4, 0.0, 1.0, 0.5));
    }
}
