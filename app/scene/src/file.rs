//! The scene file as written: TOML tables deserialised with every leaf spanned, so that
//! checks made after parsing can still point at a line. `docs/config.md` documents each
//! field; [`super::load_scene`] resolves this into a [`super::Scene`]. Fixed-length arrays are
//! read as `Vec` and their length checked on resolving, because serde's arrays ignore extra
//! elements.

use std::fmt;

use serde::Deserialize;
use toml::Spanned;

/// A number where the scene file wants a whole one, kept as written (a fraction, or a whole
/// number beyond 64 bits, as well as one that fits) so that the field's own check can say
/// what it expects, in words, rather than the parser's `expected i64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Whole {
    /// A whole number.
    Int(i128),
    /// A number with a fraction (or an exponent).
    Fraction(f64),
}

impl Whole {
    /// The number as a `u32`, when it is a whole one that fits.
    pub fn to_u32(self) -> Option<u32> {
        match self {
            Whole::Int(n) => u32::try_from(n).ok(),
            Whole::Fraction(_) => None,
        }
    }
}

impl fmt::Display for Whole {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Whole::Int(n) => write!(f, "{n}"),
            Whole::Fraction(x) => write!(f, "{x}"),
        }
    }
}

impl<'de> Deserialize<'de> for Whole {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Whole, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Whole;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a whole number")
            }
            fn visit_i64<E>(self, v: i64) -> Result<Whole, E> {
                Ok(Whole::Int(v.into()))
            }
            fn visit_u64<E>(self, v: u64) -> Result<Whole, E> {
                Ok(Whole::Int(v.into()))
            }
            fn visit_i128<E>(self, v: i128) -> Result<Whole, E> {
                Ok(Whole::Int(v))
            }
            fn visit_u128<E>(self, v: u128) -> Result<Whole, E> {
                Ok(i128::try_from(v).map_or(Whole::Fraction(v as f64), Whole::Int))
            }
            fn visit_f64<E>(self, v: f64) -> Result<Whole, E> {
                Ok(Whole::Fraction(v))
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

/// The whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneFile {
    pub object: ObjectToml,
    pub light: LightToml,
    pub floor: PlaneToml,
    pub background: PlaneToml,
    pub environment: EnvironmentToml,
    #[serde(default)]
    pub viewer: ViewerToml,
    #[serde(default)]
    pub output: OutputToml,
    #[serde(default)]
    pub effects: EffectsToml,
    #[serde(default)]
    pub inducer: InducerToml,
    #[serde(default)]
    pub gaze: GazeToml,
    #[serde(default)]
    pub caustics: CausticsToml,
    #[serde(default)]
    pub motion: MotionToml,
    #[serde(default)]
    pub display: DisplayToml,
}

/// `[display]`: what the display does with the glass's light.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DisplayToml {
    pub compensation: Option<Spanned<String>>,
    pub global_dimmer: Option<Spanned<f32>>,
    pub model: Option<Spanned<String>>,
    pub dimmer_cells: Option<Spanned<Vec<f32>>>,
    pub dimmer_blur_deg: Option<Spanned<f32>>,
    pub dimmer_max: Option<Spanned<f32>>,
    pub registration_error_deg: Option<Spanned<f32>>,
}

/// `[motion]`: keyframes of the object and the light.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MotionToml {
    pub repeat_s: Option<Spanned<f64>>,
    #[serde(default)]
    pub object: Vec<ObjectKeyToml>,
    #[serde(default)]
    pub light: Vec<LightKeyToml>,
}

/// `[[motion.object]]`: one keyframe of the object.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ObjectKeyToml {
    pub time_s: Spanned<f64>,
    pub position_m: Spanned<Vec<f32>>,
    pub rotation_deg: Option<Spanned<Vec<f32>>>,
}

/// `[[motion.light]]`: one keyframe of the light.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightKeyToml {
    pub time_s: Spanned<f64>,
    pub position_m: Spanned<Vec<f32>>,
}

/// `[caustics]`: the scene's caustic bake (eq. 6).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CausticsToml {
    pub bake: Option<Spanned<String>>,
    pub mode: Option<Spanned<String>>,
    pub resolution_px: Option<Spanned<Whole>>,
    pub photons_per_side: Option<Spanned<Whole>>,
    pub smoothing_px: Option<Spanned<Whole>>,
    pub min_path_weight: Option<Spanned<f32>>,
}

/// `[gaze]`: how the gaze image is chosen for defocus.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GazeToml {
    pub filter: Option<Spanned<String>>,
    pub image: Option<Spanned<String>>,
    pub pupil: Option<Spanned<String>>,
}

/// `[object]`: the virtual transparent object.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ObjectToml {
    pub model: Spanned<String>,
    pub diameter_m: Option<Spanned<f32>>,
    pub scale: Option<Spanned<f32>>,
    pub position_m: Spanned<Vec<f32>>,
    pub rotation_deg: Option<Spanned<Vec<f32>>>,
    pub ior: Option<Spanned<f32>>,
    pub refraction: Option<Spanned<String>>,
    pub surface_texture: Option<Spanned<String>>,
    pub surface_transmittance: Option<Spanned<f32>>,
    pub attenuation_distance_m: Option<Spanned<f32>>,
    pub attenuation_color: Option<Spanned<Vec<f32>>>,
}

/// Which frame `[light] position_m` is given in.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub(crate) enum LightFrame {
    /// World (scene) coordinates.
    #[default]
    World,
    /// Offset from the object's position, world axes.
    Object,
}

/// `[light]`: the point light.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightToml {
    pub position_m: Spanned<Vec<f32>>,
    #[serde(default)]
    pub frame: LightFrame,
    pub intensity: Option<Spanned<f32>>,
    pub color: Option<Spanned<Vec<f32>>>,
    pub share: Option<Spanned<f32>>,
}

/// `[floor]` and `[background]`: a registered real-world plane.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlaneToml {
    pub photo: Spanned<String>,
    pub size_m: Spanned<Vec<f32>>,
    pub position_m: Spanned<Vec<f32>>,
    pub rotation_deg: Option<Spanned<Vec<f32>>>,
}

/// `[environment]`: the environment map of the baseline method.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct EnvironmentToml {
    pub map: Spanned<String>,
    pub cube_map: Option<Spanned<String>>,
    pub room: Option<Spanned<bool>>,
    pub yaw_deg: Option<Spanned<f32>>,
}

/// `[viewer]`: the wearer.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ViewerToml {
    pub ipd_mm: Option<Spanned<f32>>,
    pub pupil_diameter_mm: Option<Spanned<f32>>,
    pub head_position_m: Option<Spanned<Vec<f32>>>,
}

/// `[output]`: per-eye image size and field of view.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct OutputToml {
    pub width_px: Option<Spanned<Whole>>,
    pub height_px: Option<Spanned<Whole>>,
    pub horizontal_fov_deg: Option<Spanned<f32>>,
    pub vertical_fov_deg: Option<Spanned<f32>>,
    pub glass_samples: Option<Spanned<Whole>>,
}

/// `[effects]`: the perception-based effects to render.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct EffectsToml {
    pub set: Option<Spanned<String>>,
}

/// `[inducer]`: the shadow inducer's parameters (eq. 2-4).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct InducerToml {
    pub k: Option<Spanned<f32>>,
    pub ramp_width_m: Option<Spanned<f32>>,
    pub resolution_px: Option<Spanned<Whole>>,
}

/// Largest scene file read, bytes: a scene is a short TOML text, and a huge file (a model or
/// a recording named by mistake) must not be read whole into memory.
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

/// Largest asset file read (model, photo, environment map), bytes: far above any image within
/// the pixel limit or any model an eye-level scene needs.
pub const MAX_ASSET_FILE_BYTES: u64 = 256 << 20;
