//! One frame of the physical reference: the floor's light traced for the object and light where
//! they are, then each eye's image of the real object and of the world with nothing there.

use glam::Vec3;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::solid::SolidError;
use vitreous_scene::{Placement, Scene};

use crate::eye::{EyeImage, NearObject, Sampling, Window, render_eye};
use crate::floor_light::PhotonParams;
use crate::light_map::FloorLight;
use crate::world::World;

/// Positions along each side of a pixel the object may cover, by default. The goblet's disc
/// (`goblet-real.toml`, 640 x 480) at 3 x 3 stands 0.064 in ꟻLIP from itself at 16 x 16, at
/// 12 x 12 0.016; the GPU's glass (4 x 4) scores a gap of 0.43 against the first, 0.354 and
/// 0.355 against the others.
pub const OBJECT_SAMPLES_PER_SIDE: u32 = 12;

/// How the physical reference is rendered.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceSettings {
    /// Positions along each side of a pixel averaged for its light.
    pub samples_per_side: u32,
    /// Positions along each side of a pixel the object may cover (in both the real and the
    /// seen image, so that they differ by the object alone): see [`NearObject`].
    pub object_samples_per_side: u32,
    /// How the floor's light is traced.
    pub photons: PhotonParams,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            samples_per_side: 3,
            object_samples_per_side: OBJECT_SAMPLES_PER_SIDE,
            photons: PhotonParams::default(),
        }
    }
}

/// One frame of the physical reference, for some eyes.
pub struct ReferenceFrame {
    /// The real scene with the real object, per eye asked for (linear).
    pub real: Vec<EyeImage>,
    /// The real scene with nothing there, per eye asked for (linear).
    pub seen: Vec<EyeImage>,
    /// Photons traced for the floor's light (0 without).
    pub photons: u64,
    /// Standard error of the floor's light ratio where the object changes it.
    pub noise: f32,
}

/// The scene's object cannot be traced: its mesh is not a closed solid.
#[derive(Debug, thiserror::Error)]
#[error("{}: the object {} is not a closed solid", scene.display(), object.display())]
pub struct NotClosed {
    /// The scene file.
    pub scene: std::path::PathBuf,
    /// The object's model file.
    pub object: std::path::PathBuf,
    /// What is wrong with the mesh.
    #[source]
    pub source: SolidError,
}

/// Renders the physical reference of `scene` with its object and light at `placement`, seen
/// by each of `cameras` at `size`.
pub fn render_reference(
    scene: &Scene,
    cameras: &[EyeParams],
    placement: &Placement,
    (width, height): (u32, u32),
    settings: &ReferenceSettings,
) -> Result<ReferenceFrame, NotClosed> {
    let world = World::of(scene, placement).map_err(|source| NotClosed {
        scene: scene.path.clone(),
        object: scene.object.model_path.clone(),
        source,
    })?;
    let floor_light = if world.light_share > 0.0 {
        FloorLight::trace(&world, &settings.photons)
    } else {
        None
    };
    let (photons, noise) = floor_light
        .as_ref()
        .map_or((0, 0.0), |l| (l.photons(), l.noise()));
    let world = World {
        floor_light,
        ..world
    };
    let seen = world.without_object();
    let whole = Window {
        x: 0,
        y: 0,
        width,
        height,
    };
    let (mut real_images, mut seen_images) = (Vec::new(), Vec::new());
    let sampling = Sampling {
        per_side: settings.samples_per_side,
        near_object: world.glass.as_ref().map(|glass| NearObject {
            center_m: glass.bound_center_m,
            radius_m: glass.bound_radius_m,
            per_side: settings.object_samples_per_side,
        }),
    };
    for camera in cameras {
        real_images.push(render_eye(&world, camera, (width, height), whole, sampling));
        seen_images.push(render_eye(&seen, camera, (width, height), whole, sampling));
    }
    Ok(ReferenceFrame {
        real: real_images,
        seen: seen_images,
        photons,
        noise,
    })
}

/// A linear eye image as sRGB RGBA8.
pub fn srgb_rgba(image: &EyeImage) -> Vec<u8> {
    let encode = vitreous_optics::srgb::from_linear;
    image
        .rgb
        .iter()
        .flat_map(|c: &Vec3| [encode(c.x), encode(c.y), encode(c.z), 255])
        .collect()
}
