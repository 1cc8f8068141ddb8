//! vitreous-scene: scene files, their assets, effect sets and caustic bakes, loaded and
//! checked; no device and no window, so the caustic baker and the fuzz targets read scenes
//! and bakes without the application.
//!
//! A scene file is TOML describing the virtual glass object, its light, the registered real
//! floor and background, the environment map, the viewer and the output, resolved into a
//! [`Scene`] with every asset loaded and checked.
//!
//! Frame: OpenXR LOCAL-like, right-handed, +x right, +y up, -z forward, metres, origin at
//! the viewer's initial head position. The paper's Unity coordinates `(x, y, z)` are
//! `(x, y, -z)` here. The field reference is `docs/config.md`.
//!
//! Every error names the scene file, line, column and dotted field; asset errors also name
//! the asset file and the decoder's reason. No input makes the loader panic.
//!
//! | module | what it is |
//! |---|---|
//! | this file | what a loaded scene is |
//! | `load` | reads and checks a file into a [`Scene`] (`load/object.rs`: the glass object) |
//! | `file` | the file's raw TOML shape |
//! | `error` | the loader's errors, with file, line and field |
//! | `image`, `mesh`, `accessor` | the assets: photos and HDRIs; glTF and OBJ meshes |
//! | `latlong` | an environment map turned about the vertical (`[environment] yaw_deg`) |
//! | `motion` | keyframed object motion |
//! | `fixation` | where a viewer of the scene looks (the synthetic traces' targets) |
//! | [`effects`] | the effect sets a scene or a study condition turns on |
//! | [`caustics`] | the caustic bake file format (eq. 6's gain map), read and written |
//! | [`files`] | where a scene's files are read from (the disk, or a test's memory) |

mod accessor;
pub mod caustics;
pub mod consistency;
pub mod effects;
mod error;
mod file;
pub mod files;
mod fixation;
mod image;
mod latlong;
mod load;
mod mesh;
mod motion;

use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use vitreous_trace::{Fov, Pose};

use crate::effects::EffectSet;
use vitreous_gaze::{FilterKind, GazeOverride, PupilSource};

pub use crate::files::{DiskFiles, SceneFiles};
pub use error::{Location, SceneError};
pub use fixation::{
    FixationPoints, MeshLens, REFRACTED_TARGET, SURFACE_TARGET, ViewingGeometry,
    gaze_image_of_target, synth_params_for,
};
pub use image::{Image, ImageError, MAX_IMAGE_PIXELS, MAX_IMAGE_SIZE_PX, PixelData};
pub use load::{load_scene, load_scene_from};
pub use mesh::{Mesh, load_mesh};
pub use motion::{LightKey, MAX_KEYFRAMES, MAX_TIME_S, Motion, ObjectKey, Placement};

/// A fully loaded scene, in the world frame described in the module docs.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene file, as given to [`load_scene`].
    pub path: PathBuf,
    /// Hex SHA-256 over the scene file's bytes and the bytes of every asset it loads
    /// (labelled by field, so moving the files elsewhere keeps the hash).
    pub hash: String,
    /// Every asset file the scene names and the loader read (`object.model`,
    /// `floor.photo`, ...), each with the field that names it, in the order read: with the
    /// scene file, the files [`Scene::hash`] covers. A glTF model's external buffers are not
    /// listed; the caustic bake, read later, is [`Caustics::bake`].
    pub assets: Vec<(String, PathBuf)>,
    /// The virtual transparent object.
    pub object: Object,
    /// The point light.
    pub light: Light,
    /// The registered real floor.
    pub floor: RealPlane,
    /// The registered real background behind the object.
    pub background: RealPlane,
    /// The environment map of the baseline method.
    pub environment: Environment,
    /// The wearer.
    pub viewer: Viewer,
    /// Per-eye output image and field of view.
    pub output: Output,
    /// The effects the scene asks for (parsed, not yet checked against this build).
    pub effects: EffectSet,
    /// How the gaze image is chosen for defocus.
    pub gaze: GazeChoice,
    /// What the display takes away from the glass's light (`[display] compensation`): nothing
    /// (the paper's), or the real floor or background the eye already sees (eq. 6 over the
    /// glass).
    pub compensation: vitreous_optics::display::Compensation,
    /// How much the headset's global dimmer darkens the whole view (`[display] global_dimmer`,
    /// 0 none to 1 the most; Magic Leap 2's `XR_ML_global_dimmer`), when the scene asks for it.
    pub global_dimmer: Option<f32>,
    /// The display's segmented dimmer (`[display] model = "dimmer"`), when it has one.
    pub dimmer: Option<vitreous_optics::display::dimmer::DimmerDesc>,
    /// How far the display's light may land from where the real world is, degrees, one
    /// standard deviation per axis (`[display] registration_error_deg`); the dimmer's panel
    /// and light are planned for it.
    pub registration_error_deg: f32,
    /// The shadow inducer's parameters.
    pub inducer: Inducer,
    /// The caustic bake (eq. 6): where it is and, once [`Scene::load_caustics`] ran, its
    /// gain map.
    pub caustics: Caustics,
    /// How the object and the light move (`[motion]`; empty: they stand still).
    pub motion: Motion,
    /// `[light] position_m` as written: world, or an offset from the object's position when
    /// [`Motion::light_follows_object`].
    pub light_in_frame_m: Vec3,
    /// Why the scene could not exist as a real room ([`consistency::warnings`]): each names
    /// the fields to change; logged when the scene is loaded.
    pub warnings: Vec<String>,
}

/// How the caustics are made (`[caustics] mode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CausticsMode {
    /// Read from the scene's bake (offline, one pose).
    #[default]
    Baked,
    /// Computed on the GPU for every pose (photon splatting).
    Live,
}

/// `[caustics]`: the scene's caustic gain bake, or live caustics (docs/caustics.md).
#[derive(Clone, Debug, Default)]
pub struct Caustics {
    /// The bake file, resolved against the scene's folder; `None` when the scene names none.
    /// Not read (nor hashed) when the scene loads: only when the caustics are asked for, or
    /// the glass (an object other than a ball in the room) sees the floor's light under it.
    pub bake: Option<PathBuf>,
    /// The gain map, after [`Scene::load_caustics`] (zeros in live mode, filled per pose).
    pub gain: Option<crate::caustics::Bake>,
    /// Baked or live.
    pub mode: CausticsMode,
    /// Side of the live gain map, texels (live mode).
    pub resolution_px: u32,
    /// Photons along each side of the live emission grid (live mode).
    pub photons_per_side: u32,
    /// Radius of the box the live map is smoothed with, texels (live mode; 0: none).
    pub smoothing_px: u32,
    /// Light paths carrying less than this share of their photon's light end (live mode).
    pub min_path_weight: f32,
}

impl Scene {
    /// The files the scene is read from, each with what names it: the scene file itself
    /// (`scene`), every asset ([`Scene::assets`]) and the caustic bake when it names one
    /// (`caustics.bake`).
    pub fn files(&self) -> Vec<(&str, &Path)> {
        let mut files = vec![("scene", self.path.as_path())];
        files.extend(self.assets.iter().map(|(f, p)| (f.as_str(), p.as_path())));
        files.extend(self.caustics.bake.as_deref().map(|p| ("caustics.bake", p)));
        files
    }

    /// Where `[object]` and `[light]` put the object and the light.
    pub fn rest_placement(&self) -> Placement {
        Placement {
            object_position_m: self.object.center_m,
            object_rotation: self.object.rotation,
            light_position_m: self.light.position_m,
        }
    }

    /// Where the object and the light are `time_s` seconds after the first frame.
    pub fn placement_at(&self, time_s: f64) -> Placement {
        self.motion
            .placement_at(time_s, self.rest_placement(), self.light_in_frame_m)
    }

    /// The hash of what a caustic bake of this scene depends on
    /// ([`crate::caustics::inputs_hash`]: the object's mesh, size, place, turn and index of
    /// refraction, the light's position and the floor's rectangle, at rest).
    pub fn caustic_inputs_hash(&self) -> String {
        crate::caustics::inputs_hash(
            &self.object,
            self.light.position_m,
            self.floor.world_from_plane(),
        )
    }

    /// Reads the scene's caustic bake into [`Caustics::gain`], checking that it was baked
    /// for this scene's object, light and floor (its stored hash equals
    /// [`Scene::caustic_inputs_hash`]). Errors name the file: no bake
    /// named, missing, corrupt, or made for another scene; a moving scene is refused. In live
    /// mode no file is read: the gain map is zeros of `[caustics] resolution_px`, which the
    /// renderer fills for each pose (`vitreous_frames::render_desc::enable_live_caustics`).
    pub fn load_caustics(&mut self) -> Result<(), crate::caustics::BakeError> {
        if self.caustics.mode == CausticsMode::Live {
            // The map's size; the renderer fills it for every pose.
            let n = self.caustics.resolution_px;
            self.caustics.gain = Some(crate::caustics::Bake {
                width_px: n,
                height_px: n,
                gain: vec![0.0; n as usize * n as usize],
                light: None,
                inputs_hash: Some(self.caustic_inputs_hash()),
                params: "method=live".into(),
            });
            return Ok(());
        }
        if self.motion.is_animated() {
            return Err(crate::caustics::BakeError::MovingScene {
                scene: self.path.clone(),
            });
        }
        let path =
            self.caustics
                .bake
                .as_ref()
                .ok_or_else(|| crate::caustics::BakeError::NotNamed {
                    scene: self.path.clone(),
                })?;
        let bake = crate::caustics::read_bake(path, &self.caustic_inputs_hash())
            .map_err(|e| e.in_scene(&self.path))?;
        self.caustics.gain = Some(bake);
        Ok(())
    }
}

/// The shadow inducer's parameters (METHOD.md section 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inducer {
    /// k of eq. 4: gain at the shadow edge relative to the floor's luminance.
    pub k: f32,
    /// D of eq. 2: width of the ramp around the shadow, metres.
    pub ramp_width_m: f32,
    /// Side of the floor-space shadow mask and distance field, texels.
    pub resolution_px: u32,
}

impl Default for Inducer {
    /// The paper's HoloLens values on a 512 x 512 mask.
    fn default() -> Inducer {
        Inducer {
            k: 0.3,
            ramp_width_m: 0.14,
            resolution_px: 512,
        }
    }
}

/// `[gaze]`: the fixation-depth filter and the experimenter's gaze-image override.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GazeChoice {
    /// Depth filter (default: eq. 15's 20-sample mean).
    pub filter: FilterKind,
    /// Gaze image: auto, or forced to the surface or the refracted image.
    pub image: GazeOverride,
    /// Where A_p comes from: the fixed `[viewer] pupil_diameter_mm` or the tracker.
    pub pupil: PupilSource,
}

/// Where the object's refractive index came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IorSource {
    /// `object.ior` in the scene file.
    Scene,
    /// The model's KHR_materials_ior.
    Gltf,
    /// Neither: 1.5.
    Default,
}

/// The virtual transparent object.
#[derive(Clone, Debug)]
pub struct Object {
    /// The triangle mesh in model units.
    pub mesh: Mesh,
    /// Model to world: centre the mesh's bounding box on the origin, scale (to the target
    /// diameter), rotate, translate to `position_m`.
    pub world_from_model: Mat4,
    /// World centre of the bounding sphere, metres (the object's `position_m`).
    pub center_m: Vec3,
    /// The object's orientation (`rotation_deg`).
    pub rotation: Quat,
    /// Uniform scale from model units to metres.
    pub scale: f32,
    /// Centre of the mesh's bounding box, model units (moved to `center_m`).
    pub model_center: Vec3,
    /// World radius of the bounding sphere about `center_m`, metres.
    pub radius_m: f32,
    /// Refractive index relative to air.
    pub ior: f32,
    /// Where `ior` came from.
    pub ior_source: IorSource,
    /// How the view ray is refracted through the object (`refraction`; the paper's model by
    /// default).
    pub refraction: vitreous_optics::refraction::Refraction,
    /// Absorption inside the object, world metres: the model's `KHR_materials_volume`
    /// (its distance scaled with the object), each part overridden by `attenuation_distance_m`
    /// and `attenuation_color`; clear glass
    /// ([`vitreous_optics::absorption::Attenuation::NONE`]) without.
    pub attenuation: vitreous_optics::absorption::Attenuation,
    /// Surface texture (sRGB), mapped with the mesh's `TEXCOORD_0`, if any.
    pub surface_texture: Option<Image>,
    /// Fraction of light the surface texture lets through, 0..1 (1 = no visible surface
    /// image; the paper's sticker: 0.8).
    pub surface_transmittance: f32,
    /// The glTF/GLB file.
    pub model_path: PathBuf,
    /// The mesh through which the two-surface refracted image is found, when the object is
    /// not a ball ([`MeshLens::of`]).
    pub lens: Option<std::sync::Arc<MeshLens>>,
}

impl Object {
    /// Model to world with the bounding-box centre at `position_m` and orientation
    /// `rotation`: [`Object::world_from_model`] for another placement.
    pub fn world_from_model_at(&self, position_m: Vec3, rotation: Quat) -> Mat4 {
        model_placement(self.scale, self.model_center, position_m, rotation)
    }

    /// Whether the mesh is a ball: every vertex at one distance from the bounding-box centre
    /// (within 1e-4 of it) with a normal pointing away from the centre, so that the analytic
    /// sphere of [`Object::radius_m`] stands for it exactly.
    pub fn is_ball(&self) -> bool {
        let m = &self.mesh;
        let c = self.model_center;
        let radius = m
            .positions
            .iter()
            .map(|&p| p.distance(c))
            .fold(0.0, f32::max);
        m.positions.iter().zip(&m.normals).all(|(&p, &n)| {
            (p.distance(c) - radius).abs() <= 1e-4 * radius
                && n.normalize_or_zero().dot(p - c)
                    > vitreous_optics::two_surface::RADIAL_NORMAL_COS * p.distance(c)
        })
    }
}

/// Model to world for a mesh scaled by `scale` about its bounding-box centre `model_center`
/// (model units), turned by `rotation` and moved to `position_m`.
pub fn model_placement(scale: f32, model_center: Vec3, position_m: Vec3, rotation: Quat) -> Mat4 {
    Mat4::from_scale_rotation_translation(Vec3::splat(scale), rotation, position_m)
        * Mat4::from_translation(-model_center)
}

/// The point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// World position, metres.
    pub position_m: Vec3,
    /// Dimensionless multiplier on `color`.
    pub intensity: f32,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Fraction of the real floor's light that comes from this light (`[light] share`, 0..=1,
    /// default 1: the paper's assumption that it gives all of it). Eq. 6's caustics add only
    /// this share's concentration: the rest of the floor's light is not focused by the object.
    pub share: f32,
}

/// A registered real-world plane: a photo of the real surface, its physical size and pose.
#[derive(Clone, Debug)]
pub struct RealPlane {
    /// The photo (sRGB), top edge towards the plane's local +y.
    pub photo: Image,
    /// Width (local x) and height (local y), metres.
    pub size_m: Vec2,
    /// Centre and orientation; the visible side faces local +z.
    pub pose: Pose,
}

impl RealPlane {
    /// Maps the unit square `[-0.5, 0.5]^2` at z = 0 (local +y = photo top) onto the plane
    /// in the world.
    pub fn world_from_plane(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(
            self.size_m.extend(1.0),
            self.pose.orientation,
            self.pose.position,
        )
    }

    /// World unit normal of the visible side.
    pub fn normal(&self) -> Vec3 {
        (self.pose.orientation * Vec3::Z).normalize()
    }
}

/// The environment map.
#[derive(Clone, Debug)]
pub struct Environment {
    /// Latitude-longitude map, linear RGBA f32, rows as stored in the file (top row = zenith),
    /// turned by `yaw_deg` (the middle column looks down -z, +x a quarter of the width right).
    pub latlong: Image,
    /// `environment.yaw_deg`: how far the file's map was turned about the vertical at load,
    /// degrees, counter-clockwise seen from above.
    pub yaw_deg: f32,
    /// The map's file.
    pub path: PathBuf,
    /// `environment.cube_map`: reserved; checked to exist and hashed, not decoded.
    pub cube_map_path: Option<PathBuf>,
    /// `environment.room`: the glass traces the floor and background photos as the room it
    /// refracts and reflects; a ray that meets neither sees `latlong`, the world beyond them.
    pub room: bool,
}

/// The wearer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewer {
    /// Interpupillary distance, metres.
    pub ipd_m: f32,
    /// Pupil diameter A_p of eq. 14, metres.
    pub pupil_diameter_m: f32,
    /// Head (between the eyes) position used by synthetic traces and when no trace is
    /// given, metres.
    pub head_position_m: Vec3,
}

impl Viewer {
    /// Left and right eye positions for a head pose: half the IPD along the head's -x / +x.
    pub fn eye_positions_m(&self, head: &Pose) -> [Vec3; 2] {
        let half = Vec3::X * (self.ipd_m / 2.0);
        [head.transform_point(-half), head.transform_point(half)]
    }

    /// Left and right eye positions at the neutral head: the head at `head_position_m`,
    /// looking down -z.
    pub fn neutral_eye_positions_m(&self) -> [Vec3; 2] {
        self.eye_positions_m(&Pose {
            position: self.head_position_m,
            orientation: Quat::IDENTITY,
        })
    }
}

/// Per-eye output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    /// Width of each eye's image, pixels.
    pub width_px: u32,
    /// Height of each eye's image, pixels.
    pub height_px: u32,
    /// Field of view of each eye, radians.
    pub fov: Fov,
    /// Positions along each side of a pixel whose mean is the glass's light there (1..=8):
    /// 1, the pixel's centre (the paper's rendering); n, an n x n grid, as the eye averages
    /// the real glass over the pixel.
    pub glass_samples: u32,
}

/// Rotation from `[x, y, z]` Euler angles in degrees: about world x first, then world y,
/// then world z (extrinsic XYZ; the matrix is `Rz * Ry * Rx`).
pub fn euler_xyz_deg(angles_deg: Vec3) -> Quat {
    let r = angles_deg * (std::f32::consts::PI / 180.0);
    Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_rotates_x_then_y_then_z() {
        let floor = euler_xyz_deg(Vec3::new(-90.0, 0.0, 0.0));
        assert!((floor * Vec3::Z).abs_diff_eq(Vec3::Y, 1e-6));
        assert!((floor * Vec3::Y).abs_diff_eq(Vec3::NEG_Z, 1e-6));
        let q = euler_xyz_deg(Vec3::new(90.0, 90.0, 0.0));
        // x first: +y -> +z; then y: +z -> +x.
        assert!((q * Vec3::Y).abs_diff_eq(Vec3::X, 1e-6));
    }

    #[test]
    fn plane_maps_unit_square_and_faces_its_normal() {
        let plane = RealPlane {
            photo: Image::new(1, 1, PixelData::Srgb8(vec![0; 4])).unwrap(),
            size_m: Vec2::new(2.0, 1.0),
            pose: Pose {
                position: Vec3::new(0.0, -0.5, -1.0),
                orientation: euler_xyz_deg(Vec3::new(-90.0, 0.0, 0.0)),
            },
        };
        let m = plane.world_from_plane();
        assert!(
            m.transform_point3(Vec3::new(0.5, 0.5, 0.0))
                .abs_diff_eq(Vec3::new(1.0, -0.5, -1.5), 1e-6)
        );
        assert!(plane.normal().abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn eyes_are_half_ipd_either_side() {
        let viewer = Viewer {
            ipd_m: 0.064,
            pupil_diameter_m: 0.006,
            head_position_m: Vec3::ZERO,
        };
        let [l, r] = viewer.eye_positions_m(&Pose::IDENTITY);
        assert_eq!(l, Vec3::new(-0.032, 0.0, 0.0));
        assert_eq!(r, Vec3::new(0.032, 0.0, 0.0));
    }
}
