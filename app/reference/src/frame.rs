//! One frame of the physical reference: the floor's light traced for the object and light where
//! they are, then each eye's image of the real object and of the world with nothing there.

use glam::Vec3;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::solid::SolidError;
use vitreous_scene::{Placement, Scene};

use crate::eye::{EyeImage, Window, render_eye};
use crate::floor_light::PhotonParams;
use crate::light_map::FloorLight;
use crate::world::World;

/// How the physical reference is rendered.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceSettings {
    /// Positions along each side of a pixel averaged for its light.
    pub samples_per_side: u32,
    /// How the floor's light is traced.
    pub photons: PhotonParams,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            samples_per_side: 3,
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
    for camera in cameras {
        let n = settings.samples_per_side;
        real_images.push(render_eye(&world, camera, (width, height), whole, n));
        seen_images.push(render_eye(&seen, camera, (width, height), whole, n));
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
