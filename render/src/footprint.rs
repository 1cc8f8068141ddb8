//! The real floor and background photos over a pixel's footprint on the device: their ripmaps
//! (render/src/ripmap.rs) in one atlas and where each reduction lies in it
//! (shaders/shared/ripmap.wgsl `Levels`). Read by eq. 6 over the glass and by the world view
//! when the scene takes several positions per glass pixel, so that what is taken away and what
//! the wearer is shown to see are the same world.

use ash::vk;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Buffer, Image, upload_texture};
use crate::ripmap;
use crate::scene::SceneDesc;

/// Where each photo's reductions lie in the ripmap atlas (shaders/shared/ripmap.wgsl `Levels`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Levels {
    floor: [[f32; 4]; ripmap::LEVELS],
    background: [[f32; 4]; ripmap::LEVELS],
    sizes: [f32; 4],
}

/// The photos' ripmaps and where their reductions lie; freed on drop.
pub(crate) struct Footprint {
    /// [`Levels`], a uniform buffer.
    pub(crate) levels: Buffer,
    /// The atlas, 8-bit sRGB.
    pub(crate) atlas: Image,
}

impl Footprint {
    /// Builds `desc`'s floor and background ripmaps and uploads them.
    pub(crate) fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<Footprint> {
        let atlas = ripmap::atlas(&[&desc.floor.photo, &desc.background.photo])?;
        let (w, h) = (atlas.width as f32, atlas.height as f32);
        let table = |p: &ripmap::PhotoLevels| {
            std::array::from_fn(|k| {
                let ((x, cw), (y, rh)) = (p.columns[k], p.rows[k]);
                [x as f32 / w, cw as f32 / w, y as f32 / h, rh as f32 / h]
            })
        };
        let [floor, background] = [&atlas.photos[0], &atlas.photos[1]];
        let levels = Levels {
            floor: table(floor),
            background: table(background),
            sizes: [
                floor.size.0 as f32,
                floor.size.1 as f32,
                background.size.0 as f32,
                background.size.1 as f32,
            ],
        };
        let levels = Buffer::with_data(
            ctx,
            "ripmap levels",
            bytemuck::bytes_of(&levels),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let atlas = upload_texture(
            ctx,
            "ripmaps",
            vk::Format::R8G8B8A8_SRGB,
            vk::Extent2D {
                width: atlas.width,
                height: atlas.height,
            },
            &atlas.texels,
        )?;
        Ok(Footprint { levels, atlas })
    }
}
