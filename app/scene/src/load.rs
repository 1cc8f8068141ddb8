//! Reading a scene file: the TOML parsed into its raw shape ([`SceneFile`]), every field
//! range-checked with its line and column, every asset read, decoded and hashed, and the
//! result resolved into a [`Scene`].
//!
//! Over 600 lines because every `[table]` of the scene file is checked here, field by field, in
//! the order of the file (the `[motion]` keyframes included): one place that knows the file's
//! shape and the line of each field. The decoding of assets lives in `image.rs` and `mesh.rs`.

use std::path::{Component, Path, PathBuf};

use glam::{Mat4, Quat, Vec2, Vec3};
use sha2::{Digest, Sha256};
use toml::Spanned;
use vitreous_optics::absorption::Attenuation;
use vitreous_optics::live_caustics::{
    DEFAULT_RESOLUTION_PX as DEFAULT_LIVE_RESOLUTION_PX, LiveCausticsDesc, MAX_PHOTONS_PER_SIDE,
    MAX_SMOOTHING_PX,
};
use vitreous_trace::{Fov, Pose};

use super::error::Source;
use super::file::{LightFrame, PlaneToml, SceneFile, Whole};
use super::mesh::VolumeAttenuation;
use super::{
    Caustics, CausticsMode, Environment, GazeChoice, Image, Inducer, IorSource, Light, MeshLens,
    Object, Output, RealPlane, Scene, SceneError, Viewer, euler_xyz_deg,
};
use super::{file, image, latlong, mesh};
use crate::effects::EffectSet;
use crate::files::{DiskFiles, SceneFiles};
use vitreous_gaze::{FilterKind, FilterParseError, GazeOverride, PupilSource};

mod display;
mod object;

/// The most positions along each side of a pixel `[output] glass_samples` takes (64 per pixel).
pub const MAX_GLASS_SAMPLES: u32 = 8;

/// Loads a scene file and every asset it names, checking ranges and decoding everything.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_from(path, &DiskFiles)
}

/// [`load_scene`] with the scene file and its assets read from `files`; paths are resolved
/// and normalised as on disk before `files` is asked. A glTF model's external buffers are
/// still read from the file system, next to where `files` says the model is.
pub fn load_scene_from(path: &Path, files: &dyn SceneFiles) -> Result<Scene, SceneError> {
    let bytes = files
        .read_bounded(
            path,
            file::MAX_SCENE_FILE_BYTES,
            "a scene file is a short TOML text",
        )
        .map_err(|error| SceneError::Read {
            path: path.to_path_buf(),
            error,
        })?;
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => text,
        Err(e) => {
            let src = Source {
                file: path,
                text: std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default(),
            };
            return Err(SceneError::Syntax {
                at: src.location(e.valid_up_to()),
                field: "(top level)".into(),
                message: "the file is not valid UTF-8".into(),
            });
        }
    };
    let mut loader = Loader {
        files,
        src: Source { file: path, text },
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        hasher: Sha256::new(),
        assets: Vec::new(),
    };
    loader.hash_part("scene", &bytes);
    let raw: SceneFile = toml::from_str(text).map_err(|e| loader.src.toml_error(&e))?;
    let scene = loader.resolve(raw)?;
    for warning in &scene.warnings {
        tracing::warn!("{}: {warning}", path.display());
    }
    Ok(scene)
}

pub(super) struct Loader<'a> {
    files: &'a dyn SceneFiles,
    pub(super) src: Source<'a>,
    dir: PathBuf,
    hasher: Sha256,
    /// Every asset read so far, with the field that names it.
    assets: Vec<(String, PathBuf)>,
}

/// Both bounds of a range included.
const CLOSED: (bool, bool) = (false, false);

/// Largest accepted coordinate magnitude, metres.
const MAX_COORD_M: f32 = 1000.0;

impl Loader<'_> {
    fn hash_part(&mut self, label: &str, bytes: &[u8]) {
        self.hasher.update((label.len() as u64).to_le_bytes());
        self.hasher.update(label.as_bytes());
        self.hasher.update((bytes.len() as u64).to_le_bytes());
        self.hasher.update(bytes);
    }

    /// Resolves an asset path against the scene's folder and reads (and hashes) it.
    fn read_asset(
        &mut self,
        field: &str,
        rel: &Spanned<String>,
    ) -> Result<(PathBuf, Vec<u8>), SceneError> {
        if rel.get_ref().trim().is_empty() {
            return Err(self.src.invalid(
                rel.span(),
                field,
                "expected a file path, found an empty string",
            ));
        }
        let path = normalize(&self.dir.join(rel.get_ref()));
        let bytes = self
            .files
            .read_bounded(
                &path,
                file::MAX_ASSET_FILE_BYTES,
                "models, photos and maps are accepted up to that size",
            )
            .map_err(|e| {
                let reason = match e.kind() {
                    std::io::ErrorKind::NotFound => "file not found".to_owned(),
                    _ => format!("cannot read: {e}"),
                };
                self.src.asset(rel.span(), field, &path, reason)
            })?;
        self.hash_part(field, &bytes);
        self.assets.push((field.to_owned(), path.clone()));
        Ok((path, bytes))
    }

    fn photo(&mut self, field: &str, rel: &Spanned<String>) -> Result<Image, SceneError> {
        let (path, bytes) = self.read_asset(field, rel)?;
        image::decode_photo(&bytes)
            .map_err(|reason| self.src.asset(rel.span(), field, &path, reason))
    }

    /// Exactly `N` numbers.
    fn array<const N: usize>(
        &self,
        field: &str,
        v: &Spanned<Vec<f32>>,
    ) -> Result<[f32; N], SceneError> {
        <[f32; N]>::try_from(v.get_ref().as_slice()).map_err(|_| {
            self.src.invalid(
                v.span(),
                field,
                format!(
                    "expected an array of {N} numbers, found {}",
                    v.get_ref().len()
                ),
            )
        })
    }

    pub(super) fn vec3(&self, field: &str, v: &Spanned<Vec<f32>>) -> Result<Vec3, SceneError> {
        let value = Vec3::from_array(self.array(field, v)?);
        if !value.is_finite() || value.abs().max_element() > MAX_COORD_M {
            return Err(self.src.invalid(
                v.span(),
                field,
                format!("expected finite coordinates within ±{MAX_COORD_M} m, found {value}"),
            ));
        }
        Ok(value)
    }

    pub(super) fn rotation(
        &self,
        field: &str,
        v: Option<&Spanned<Vec<f32>>>,
    ) -> Result<Quat, SceneError> {
        let Some(v) = v else {
            return Ok(Quat::IDENTITY);
        };
        let [x, y, z] = self.array(field, v)?;
        if ![x, y, z].iter().all(|a| a.is_finite() && a.abs() <= 360.0) {
            return Err(self.src.invalid(
                v.span(),
                field,
                format!("expected three angles in -360..=360 degrees, found [{x}, {y}, {z}]"),
            ));
        }
        Ok(euler_xyz_deg(Vec3::new(x, y, z)))
    }

    /// A number within `lo..=hi` (each bound exclusive where `open` says so), `default`
    /// when absent.
    fn number(
        &self,
        field: &str,
        v: Option<&Spanned<f32>>,
        default: f32,
        (lo, hi): (f32, f32),
        (lo_open, hi_open): (bool, bool),
    ) -> Result<f32, SceneError> {
        let Some(v) = v else {
            return Ok(default);
        };
        let x = *v.get_ref();
        let above = if lo_open { x > lo } else { x >= lo };
        let below = if hi_open { x < hi } else { x <= hi };
        if !(x.is_finite() && above && below) {
            let lower = if lo_open { ">" } else { ">=" };
            let upper = if hi_open { "<" } else { "<=" };
            return Err(self.src.invalid(
                v.span(),
                field,
                format!("expected a number {lower} {lo} and {upper} {hi}, found {x}"),
            ));
        }
        Ok(x)
    }

    fn resolve(mut self, raw: SceneFile) -> Result<Scene, SceneError> {
        let object = self.object(&raw.object)?;

        let light_offset = self.vec3("light.position_m", &raw.light.position_m)?;
        let light = Light {
            position_m: match raw.light.frame {
                LightFrame::World => light_offset,
                LightFrame::Object => object.center_m + light_offset,
            },
            intensity: self.number(
                "light.intensity",
                raw.light.intensity.as_ref(),
                1.0,
                (0.0, 1.0e6),
                CLOSED,
            )?,
            color: match &raw.light.color {
                None => Vec3::ONE,
                Some(c) => {
                    let v = Vec3::from_array(self.array("light.color", c)?);
                    if !v.is_finite() || v.min_element() < 0.0 || v.max_element() > 1000.0 {
                        return Err(self.src.invalid(
                            c.span(),
                            "light.color",
                            format!("expected linear RGB components in 0..=1000, found {v}"),
                        ));
                    }
                    v
                }
            },
            share: self.number(
                "light.share",
                raw.light.share.as_ref(),
                1.0,
                (0.0, 1.0),
                CLOSED,
            )?,
        };

        let motion = self.motion(&raw.motion, raw.light.frame, object.rotation)?;
        let floor = self.plane("floor", &raw.floor)?;
        let background = self.plane("background", &raw.background)?;

        let (env_path, env_bytes) = self.read_asset("environment.map", &raw.environment.map)?;
        let latlong = image::decode_hdr(&env_bytes).map_err(|r| {
            self.src
                .asset(raw.environment.map.span(), "environment.map", &env_path, r)
        })?;
        let yaw_deg = self.number(
            "environment.yaw_deg",
            raw.environment.yaw_deg.as_ref(),
            0.0,
            (-360.0, 360.0),
            CLOSED,
        )?;
        let latlong = latlong::turned_about_vertical(latlong, yaw_deg);
        let cube_map_path = match &raw.environment.cube_map {
            Some(rel) => Some(self.read_asset("environment.cube_map", rel)?.0),
            None => None,
        };
        let room = raw.environment.room.as_ref().is_some_and(|r| *r.get_ref());
        let environment = Environment {
            latlong,
            path: env_path,
            cube_map_path,
            room,
            yaw_deg,
        };

        let v = &raw.viewer;
        let viewer = Viewer {
            ipd_m: self.number(
                "viewer.ipd_mm",
                v.ipd_mm.as_ref(),
                63.0,
                (40.0, 90.0),
                CLOSED,
            )? / 1000.0,
            pupil_diameter_m: self.number(
                "viewer.pupil_diameter_mm",
                v.pupil_diameter_mm.as_ref(),
                6.0,
                (1.0, 9.0),
                CLOSED,
            )? / 1000.0,
            head_position_m: match &v.head_position_m {
                Some(p) => self.vec3("viewer.head_position_m", p)?,
                None => Vec3::ZERO,
            },
        };

        let o = &raw.output;
        let pixels = |field: &str, v: Option<&Spanned<Whole>>, default: u32| {
            self.count(field, v, default, 16..=8192, "pixels")
        };
        let width_px = pixels("output.width_px", o.width_px.as_ref(), 1280)?;
        let height_px = pixels("output.height_px", o.height_px.as_ref(), 960)?;
        let h_deg = self.number(
            "output.horizontal_fov_deg",
            o.horizontal_fov_deg.as_ref(),
            40.0,
            (1.0, 170.0),
            CLOSED,
        )?;
        let v_deg = self.number(
            "output.vertical_fov_deg",
            o.vertical_fov_deg.as_ref(),
            30.0,
            (1.0, 170.0),
            CLOSED,
        )?;
        let glass_samples = self.count(
            "output.glass_samples",
            o.glass_samples.as_ref(),
            1,
            1..=MAX_GLASS_SAMPLES,
            "positions along each side of a pixel",
        )?;
        let output = Output {
            width_px,
            height_px,
            fov: Fov::symmetric(h_deg.to_radians(), v_deg.to_radians()),
            glass_samples,
        };

        let effects = match &raw.effects.set {
            None => EffectSet::NONE,
            Some(s) => EffectSet::parse(s.get_ref())
                .map_err(|e| self.src.invalid(s.span(), "effects.set", e.to_string()))?,
        };

        let inducer = self.inducer(&raw.inducer)?;
        let live_default = LiveCausticsDesc::default();
        let caustics = Caustics {
            bake: match &raw.caustics.bake {
                None => None,
                Some(rel) if rel.get_ref().trim().is_empty() => {
                    return Err(self.src.invalid(
                        rel.span(),
                        "caustics.bake",
                        "expected a file path, found an empty string",
                    ));
                }
                Some(rel) => Some(normalize(&self.dir.join(rel.get_ref()))),
            },
            gain: None,
            mode: match &raw.caustics.mode {
                None => CausticsMode::Baked,
                Some(m) => match m.get_ref().as_str() {
                    "baked" => CausticsMode::Baked,
                    "live" => CausticsMode::Live,
                    other => {
                        return Err(self.src.invalid(
                            m.span(),
                            "caustics.mode",
                            format!("expected baked or live, found '{other}'"),
                        ));
                    }
                },
            },
            resolution_px: self.count(
                "caustics.resolution_px",
                raw.caustics.resolution_px.as_ref(),
                DEFAULT_LIVE_RESOLUTION_PX,
                16..=4096,
                "texels",
            )?,
            photons_per_side: self.count(
                "caustics.photons_per_side",
                raw.caustics.photons_per_side.as_ref(),
                live_default.photons_per_side,
                1..=MAX_PHOTONS_PER_SIDE,
                "photons",
            )?,
            smoothing_px: self.count(
                "caustics.smoothing_px",
                raw.caustics.smoothing_px.as_ref(),
                live_default.smoothing_px,
                0..=MAX_SMOOTHING_PX,
                "texels",
            )?,
            min_path_weight: self.number(
                "caustics.min_path_weight",
                raw.caustics.min_path_weight.as_ref(),
                live_default.min_path_weight,
                (0.0, 1.0),
                (true, true),
            )?,
        };
        let gaze = GazeChoice {
            filter: match &raw.gaze.filter {
                None => FilterKind::default(),
                Some(f) => f.get_ref().parse().map_err(|e: FilterParseError| {
                    self.src.invalid(f.span(), "gaze.filter", e.to_string())
                })?,
            },
            image: match &raw.gaze.image {
                None => GazeOverride::Auto,
                Some(i) => i.get_ref().parse().map_err(|_| {
                    self.src.invalid(
                        i.span(),
                        "gaze.image",
                        format!(
                            "expected auto, surface or refracted, found '{}'",
                            i.get_ref()
                        ),
                    )
                })?,
            },
            pupil: match &raw.gaze.pupil {
                None => PupilSource::default(),
                Some(p) => p.get_ref().parse().map_err(|_| {
                    self.src.invalid(
                        p.span(),
                        "gaze.pupil",
                        format!("expected paper or measured, found '{}'", p.get_ref()),
                    )
                })?,
            },
        };

        let display = self.display(
            &raw.display,
            [
                (output.fov.angle_right_rad - output.fov.angle_left_rad).to_degrees(),
                (output.fov.angle_up_rad - output.fov.angle_down_rad).to_degrees(),
            ],
        )?;
        let hash = self
            .hasher
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        let warnings = crate::consistency::warnings(
            &object,
            &light,
            &floor,
            &background,
            viewer.head_position_m,
            &motion,
            light_offset,
        );
        Ok(Scene {
            path: self.src.file.to_path_buf(),
            hash,
            assets: std::mem::take(&mut self.assets),
            object,
            light,
            floor,
            background,
            environment,
            viewer,
            output,
            effects,
            inducer,
            gaze,
            compensation: display.compensation,
            global_dimmer: display.global_dimmer,
            dimmer: display.dimmer,
            registration_error_deg: display.registration_error_deg,
            caustics,
            warnings,
            motion,
            light_in_frame_m: light_offset,
        })
    }

    /// A whole number of `unit` within `range`, `default` when absent; anything else (a
    /// fraction, a number out of range) is refused with the range in words.
    fn count(
        &self,
        field: &str,
        v: Option<&Spanned<Whole>>,
        default: u32,
        range: std::ops::RangeInclusive<u32>,
        unit: &str,
    ) -> Result<u32, SceneError> {
        let Some(v) = v else {
            return Ok(default);
        };
        match v.get_ref().to_u32() {
            Some(n) if range.contains(&n) => Ok(n),
            _ => Err(self.src.invalid(
                v.span(),
                field,
                format!(
                    "expected a whole number of {unit} from {} to {}, found {}",
                    range.start(),
                    range.end(),
                    v.get_ref()
                ),
            )),
        }
    }

    fn inducer(&self, raw: &file::InducerToml) -> Result<Inducer, SceneError> {
        let default = Inducer::default();
        let resolution_px = self.count(
            "inducer.resolution_px",
            raw.resolution_px.as_ref(),
            default.resolution_px,
            16..=4096,
            "texels",
        )?;
        Ok(Inducer {
            k: self.number("inducer.k", raw.k.as_ref(), default.k, (0.0, 10.0), CLOSED)?,
            ramp_width_m: self.number(
                "inducer.ramp_width_m",
                raw.ramp_width_m.as_ref(),
                default.ramp_width_m,
                (0.0, 100.0),
                (true, false),
            )?,
            resolution_px,
        })
    }

    fn plane(&mut self, table: &str, raw: &PlaneToml) -> Result<RealPlane, SceneError> {
        let photo = self.photo(&format!("{table}.photo"), &raw.photo)?;
        let size = Vec2::from_array(self.array(&format!("{table}.size_m"), &raw.size_m)?);
        if !size.is_finite() || size.min_element() <= 0.0 || size.max_element() > 100.0 {
            return Err(self.src.invalid(
                raw.size_m.span(),
                &format!("{table}.size_m"),
                format!("expected [width, height] each > 0 and <= 100 m, found {size}"),
            ));
        }
        let position = self.vec3(&format!("{table}.position_m"), &raw.position_m)?;
        let orientation =
            self.rotation(&format!("{table}.rotation_deg"), raw.rotation_deg.as_ref())?;
        Ok(RealPlane {
            photo,
            size_m: size,
            pose: Pose {
                position,
                orientation,
            },
        })
    }
}

/// Removes `.` and `name/..` pairs without touching the file system (so that error
/// messages show `config/models/x.glb`, not `config/scenes/../models/x.glb`).
fn normalize(path: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => match out.last() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                Some(Component::RootDir | Component::Prefix(_)) => {}
                _ => out.push(c),
            },
            other => out.push(other),
        }
    }
    if out.is_empty() {
        PathBuf::from(".")
    } else {
        out.iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_folds_parent_components() {
        assert_eq!(
            normalize(Path::new("config/scenes/../models/a.glb")),
            PathBuf::from("config/models/a.glb")
        );
        assert_eq!(normalize(Path::new("../x/./y")), PathBuf::from("../x/y"));
    }
}
