//! `reference.json`: what the physical reference's images are (each frame's eye cameras, where
//! the object and light were, the files) and how they were rendered. `vitreous reference` and
//! `replay --compare-reference` write it beside the images; `vitreous compare` reads it to
//! split an image into the regions of its own frame.

use std::path::Path;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_scene::{Placement, Scene};

use crate::frame::ReferenceSettings;

/// One eye's camera in `reference.json`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct EyeRecord {
    /// The eye's position, metres.
    pub position_m: [f32; 3],
    /// The view's orientation, quaternion x, y, z, w.
    pub orientation_xyzw: [f32; 4],
    /// Field of view: left, right, up, down edge angles, radians.
    pub fov_rad: [f32; 4],
}

impl EyeRecord {
    /// The eye's camera (its orientation normalised: a file's quaternion may be off unit length).
    pub fn camera(&self) -> EyeParams {
        let [left_rad, right_rad, up_rad, down_rad] = self.fov_rad;
        EyeParams::new(
            Vec3::from_array(self.position_m),
            Quat::from_array(self.orientation_xyzw).normalize(),
            Fov {
                left_rad,
                right_rad,
                up_rad,
                down_rad,
            },
        )
    }
}

/// One written frame of `reference.json`.
#[derive(Debug, Serialize, Deserialize)]
pub struct FrameReport {
    /// Frame index (as the replay's of the same trace and rate).
    pub frame: u64,
    /// Display time, ns (0 without a trace).
    pub time_ns: i64,
    /// Left and right eye.
    pub eyes: [EyeRecord; 2],
    /// Object centre and light, metres.
    pub object_position_m: [f32; 3],
    /// The object's orientation, quaternion x, y, z, w.
    pub object_rotation_xyzw: [f32; 4],
    /// The light, metres.
    pub light_position_m: [f32; 3],
    /// Photons traced for the floor light (0: no floor light, e.g. share 0).
    pub photons: u64,
    /// Standard error of the floor light ratio where the object changes it.
    pub floor_light_noise: f32,
    /// Files written.
    pub files: Vec<String>,
    /// Seconds spent on the frame.
    pub seconds: f64,
}

impl FrameReport {
    /// Where the object and the light were.
    pub fn placement(&self) -> Placement {
        Placement {
            object_position_m: Vec3::from_array(self.object_position_m),
            object_rotation: Quat::from_array(self.object_rotation_xyzw).normalize(),
            light_position_m: Vec3::from_array(self.light_position_m),
        }
    }
}

/// `reference.json`, written last: its absence means the run did not finish.
#[derive(Debug, Serialize, Deserialize)]
pub struct Report {
    /// The version of vitreous that wrote it.
    pub vitreous_version: String,
    /// The scene file.
    pub scene: String,
    /// [`Scene::hash`] of the scene.
    pub scene_hash: String,
    /// The trace, or `neutral head`.
    pub trace: String,
    /// Eye image size, pixels.
    pub width_px: u32,
    /// Eye image size, pixels.
    pub height_px: u32,
    /// Positions averaged per pixel away from the object.
    pub samples_per_pixel: u32,
    /// Positions averaged per pixel the object may cover (its bounding sphere's, widened by a
    /// pixel); absent from references written when every pixel took `samples_per_pixel`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object_samples_per_pixel: Option<u32>,
    /// Side of the floor light's texels, mm.
    pub texel_mm: f32,
    /// Photons per texel of floor under the object's cone.
    pub photons_per_texel: f32,
    /// `[light] share`.
    pub light_share: f32,
    /// `analytic ball` or `closed mesh`.
    pub object: String,
    /// Every frame written.
    pub frames: Vec<FrameReport>,
}

impl Report {
    /// The report of `frames` of `scene` (read from `scene_path`) seen along `trace` (or
    /// `neutral head`), rendered at `size` with `settings`.
    pub fn new(
        scene: &Scene,
        scene_path: &Path,
        trace: String,
        size: (u32, u32),
        settings: &ReferenceSettings,
        frames: Vec<FrameReport>,
    ) -> Report {
        Report {
            vitreous_version: env!("CARGO_PKG_VERSION").into(),
            scene: scene_path.display().to_string(),
            scene_hash: scene.hash.clone(),
            trace,
            width_px: size.0,
            height_px: size.1,
            samples_per_pixel: settings.samples_per_side * settings.samples_per_side,
            object_samples_per_pixel: Some(
                settings.object_samples_per_side * settings.object_samples_per_side,
            ),
            texel_mm: settings.photons.texel_m * 1000.0,
            photons_per_texel: settings.photons.photons_per_texel,
            light_share: scene.light.share,
            object: if scene.object.is_ball() {
                "analytic ball".into()
            } else {
                "closed mesh".into()
            },
            frames,
        }
    }
}
