//! The renderer's live caustics (docs/caustics.md): turning them on, and what the last frame
//! that computed the map read back of it.

use super::Renderer;
use crate::error::Result;
use crate::scene::SceneDesc;
use vitreous_optics::live_caustics::LiveCausticsDesc;

impl Renderer {
    /// Computes the caustics on the GPU for every pose from now on instead of using the
    /// scene's bake (docs/caustics.md); `scene` must be the description the renderer was
    /// made with.
    pub fn enable_live_caustics(
        &mut self,
        scene: &SceneDesc,
        live: LiveCausticsDesc,
    ) -> Result<()> {
        self.inducer.enable_live(&self.ctx, scene, live)
    }

    /// The live caustic gain map of the last finished frame that computed it (call
    /// [`Renderer::flush`] first); `None` without live caustics.
    pub fn live_caustic_gain(&self) -> Result<Option<Vec<f32>>> {
        self.inducer.live_gain()
    }

    /// The texels `[x0, y0, x1, y1]` (ends excluded) holding every non-zero gain of the live
    /// map of the last finished frame that computed it, as the GPU bounded them for the
    /// overlay (call [`Renderer::flush`] first); `None` when all are 0 or without live
    /// caustics.
    pub fn live_caustic_bounds(&self) -> Result<Option<[u32; 4]>> {
        self.inducer.live_bounds()
    }

    /// How many of the live map's smoothing tiles of 8 x 8 texels the last finished frame that
    /// computed it wrote, and how many the map has; the others hold no gain (call
    /// [`Renderer::flush`] first); `None` without live caustics.
    pub fn live_caustic_tiles(&self) -> Result<Option<[u32; 2]>> {
        self.inducer.live_tiles()
    }
}
