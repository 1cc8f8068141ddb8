//! The floor under the object as the glass sees it through a mesh in the room: the point
//! light's irradiance there with the object over that without it (the caustic bake's
//! `E_with / E_without`: its shadow and its caustic), as an R16F texture over the floor photo's
//! area, and the share of the floor's light it applies to. The share is 0 (the bare photo)
//! without a map, and while the object or the light is away from where the bake was made.

use ash::vk;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Image, upload_texture};
use crate::pose::ScenePose;
use crate::scene::SceneDesc;

/// The floor's light ratio on the device, and where it holds.
pub(super) struct FloorLight {
    /// `E_with / E_without` per texel (R16F), or one texel of 1 without a map.
    pub image: Image,
    /// The pose the map was made for and the light's share of the floor's light, when the
    /// scene has a map.
    holds_at: Option<(ScenePose, f32)>,
}

impl FloorLight {
    /// The map of `desc`'s caustic bake, when it holds the floor's light.
    pub fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<FloorLight> {
        let map = desc
            .caustics
            .and_then(|c| c.light.map(|light| (c.width, c.height, light)));
        let (extent, texels, holds_at) = match map {
            Some((width, height, light)) => (
                vk::Extent2D { width, height },
                light,
                Some((ScenePose::of(desc), desc.light.share.clamp(0.0, 1.0))),
            ),
            None => (
                vk::Extent2D {
                    width: 1,
                    height: 1,
                },
                &[1.0f32][..],
                None,
            ),
        };
        // Half floats filter linearly on every device (up to 65504: a caustic's peak is far
        // below).
        let bytes: Vec<u8> = texels
            .iter()
            .flat_map(|&r| half::f16::from_f32(r).to_le_bytes())
            .collect();
        let image = upload_texture(
            ctx,
            "floor light under the glass",
            vk::Format::R16_SFLOAT,
            extent,
            &bytes,
        )?;
        Ok(FloorLight { image, holds_at })
    }

    /// The light's share of the floor's light the map applies to with the object and light at
    /// `pose`: the scene's where the bake was made, else 0.
    pub fn share_at(&self, pose: &ScenePose) -> f32 {
        match self.holds_at {
            Some((made_at, share)) if made_at == *pose => share,
            _ => 0.0,
        }
    }
}
