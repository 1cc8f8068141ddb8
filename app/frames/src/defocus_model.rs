//! The numbers eq. 13-14 need of a scene, and the blur of both images they give for a gaze
//! image: what each frame's look (`look.rs`) and the blur stacks (`blur_stack.rs`) both use.

use glam::Vec3;
use vitreous_render::Defocus;

use vitreous_gaze::blur::{image_blur, px_per_m};
use vitreous_gaze::{GazeImage, ImageDistances, PupilSource};
use vitreous_scene::{Scene, ViewingGeometry};

/// The numbers eq. 13-14 need of a scene: where the images lie, pixels per metre of each
/// image's photo, and the pupil.
#[derive(Clone, Debug)]
pub struct DefocusModel {
    /// Distances of the surface and refracted images from the scene's fixed viewing position,
    /// metres (what the blur stacks are sized for; frames use [`DefocusModel::distances_from`]).
    pub distances: ImageDistances,
    /// The object and background plane the image distances are measured to.
    pub geometry: ViewingGeometry,
    /// The fixed pupil diameter A_p, metres.
    pub pupil_m: f32,
    /// Where each frame's A_p comes from.
    pub pupil_source: PupilSource,
    /// W_p / W_l of the surface texture: texels per metre on the object's surface.
    pub surface_px_per_m: f32,
    /// W_p / W_l of the background photo: pixels per metre on the background plane.
    pub background_px_per_m: f32,
}

impl DefocusModel {
    /// The model of `scene` with fixed pupil diameter `pupil_m` and the scene's pupil source.
    pub fn new(scene: &Scene, pupil_m: f32) -> DefocusModel {
        DefocusModel {
            distances: scene.image_distances(),
            geometry: scene.viewing_geometry(),
            pupil_m,
            pupil_source: scene.gaze.pupil,
            background_px_per_m: px_per_m(
                scene.background.photo.width as f32,
                scene.background.size_m.x,
            ),
            // u runs once around the object: texels per metre of its circumference.
            surface_px_per_m: scene.object.surface_texture.as_ref().map_or(1.0, |t| {
                px_per_m(
                    t.width as f32,
                    std::f32::consts::PI * 2.0 * scene.object.radius_m,
                )
            }),
        }
    }

    /// The image distances from a viewer at `viewing_m` (scene frame, metres).
    pub fn distances_from(&self, viewing_m: Vec3) -> ImageDistances {
        self.geometry.distances_from(viewing_m)
    }

    /// The blur of both images for a gaze image (eq. 13-14) from the fixed viewing position
    /// with the fixed pupil; `None` while it is unknown.
    pub fn defocus(&self, image: GazeImage) -> Option<Defocus> {
        self.defocus_at(image, &self.distances, self.pupil_m)
    }

    /// The blur of both images for a gaze image (eq. 13-14) with the images at `distances` and
    /// pupil diameter `pupil_m`; `None` while the gaze image is unknown.
    pub fn defocus_at(
        &self,
        image: GazeImage,
        distances: &ImageDistances,
        pupil_m: f32,
    ) -> Option<Defocus> {
        if image == GazeImage::Unknown {
            return None;
        }
        let blur = image_blur(
            image,
            distances,
            pupil_m,
            self.surface_px_per_m,
            self.background_px_per_m,
        );
        Some(Defocus {
            refracted_k_g_px: blur.refracted_k_g_px,
            surface_k_g_px: blur.surface_k_g_px,
        })
    }
}
