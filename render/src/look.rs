//! What the renderer draws in one frame: the look (which layers of the method, and how) and
//! both eyes' cameras.

use vitreous_optics::camera::EyeParams;

/// How the reflected image is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reflection {
    /// The environment map in the mirror direction, weighted by the Fresnel term.
    #[default]
    EnvironmentFresnel,
    /// A Phong highlight of the scene's point light (the paper's choice).
    Phong,
}

/// Gaze-dependent defocus of one frame (eq. 9-14): the kernel width K_g of eq. 13 for each
/// image, in pixels of its own photo or texture (0: sharp).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Defocus {
    /// K_g of the refracted image (the background photo), pixels.
    pub refracted_k_g_px: f32,
    /// K_g of the surface image (the surface texture), pixels.
    pub surface_k_g_px: f32,
}

/// Which layers of the method are drawn, per frame (so one process can alternate them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Look {
    /// Refract each eye's own view ray to the registered background plane (eq. 7-8), giving
    /// the refracted image its own disparity. Off, the baseline refracts into the environment
    /// map, unless `defocus` is on: then the background plane is refracted from the point
    /// between the eyes, the same for both eyes (no refracted-image disparity).
    pub disparity: bool,
    /// Gaze-dependent defocus; `None`: both images sharp.
    pub defocus: Option<Defocus>,
    /// How the reflected image is drawn.
    pub reflection: Reflection,
    /// Add the shadow inducer's floor overlay (eq. 1-5, render/src/inducer.rs).
    pub inducer: bool,
    /// Add the corrected caustics G L_r (eq. 6) to the floor overlay; needs the scene's
    /// caustic gain map ([`crate::SceneDesc::caustics`]), draws nothing without one.
    pub caustics: bool,
    /// Draw nothing of the method: the display adds no light (a study's blank between two
    /// stimuli, or a condition where a real object is shown instead). The real-world photos
    /// are still drawn behind where the composition needs them.
    pub blank: bool,
}

/// Everything the renderer needs to draw one stereo frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// Left and right eye, in that order.
    pub eyes: [EyeParams; 2],
    /// Which layers are drawn and how.
    pub look: Look,
}
