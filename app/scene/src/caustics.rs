//! The caustics bake file (paper Sec. 3.1.2, eq. 6; docs/caustics.md): a single-channel linear
//! f32 OpenEXR image of the caustic gain G, ZIP compressed, row 0 = the floor photo's top edge,
//! with the hash of its inputs (the object, the light and the floor: [`inputs_hash`]) and the
//! bake parameters as text attributes. Written by the baker
//! (`vitreous-caustics`, which re-exports this module, run as `vitreous bake`) and read by the
//! renderer's app.

use std::path::{Path, PathBuf};

use exr::prelude::*;
use thiserror::Error;

use crate::files::{DiskFiles, SceneFiles};

mod inputs;
pub use inputs::inputs_hash;

/// Name of the header attribute holding the hash of the bake's inputs ([`inputs_hash`]).
pub const INPUTS_HASH_ATTRIBUTE: &str = "vitreous_caustic_inputs_hash";
/// Name of the attribute that bakes made before [`INPUTS_HASH_ATTRIBUTE`] hold instead: the
/// hash of the whole scene file and its assets, which any edit changed.
pub const SCENE_HASH_ATTRIBUTE: &str = "vitreous_scene_hash";
/// Name of the header attribute holding the bake parameters (`key=value; ...`).
pub const PARAMS_ATTRIBUTE: &str = "vitreous_caustics_params";
/// Name of the channel holding the gain.
pub const GAIN_CHANNEL: &str = "Y";
/// Name of the channel holding the floor's light with the object over its light without it,
/// `E_with / E_without` (the shadow and the caustic both; absent from bakes made before it).
pub const LIGHT_CHANNEL: &str = "light_ratio";

/// A caustic gain map for one scene's floor.
#[derive(Clone, Debug, PartialEq)]
pub struct Bake {
    /// Width, texels (floor local x, left to right).
    pub width_px: u32,
    /// Height, texels (row 0 = the floor photo's top edge, floor local +y).
    pub height_px: u32,
    /// Relative caustic gain G >= 0 per texel, row-major: the corrected caustic overlay is
    /// `G * L_r` (eq. 6) where `L_r` is the floor photo's linear luminance at that texel.
    pub gain: Vec<f32>,
    /// The point light's irradiance on the floor with the object over that without it,
    /// `E_with / E_without >= 0` per texel, row-major as `gain` (below 1 in the shadow, above
    /// in the caustic): what the glass sees of the floor under it. `None` in a bake made before
    /// it was stored (and in live mode).
    pub light: Option<Vec<f32>>,
    /// [`inputs_hash`] of the object, light and floor it was baked for; `None` in a bake made
    /// before bakes stored it (such a bake is refused: [`BakeError::Outdated`]).
    pub inputs_hash: Option<String>,
    /// The bake parameters, `key=value; ...` text.
    pub params: String,
}

impl Bake {
    /// Gain at texel `(x, y)` (y = 0 at the photo top), 0 outside the map.
    pub fn gain_at(&self, x_px: u32, y_px: u32) -> f32 {
        if x_px >= self.width_px || y_px >= self.height_px {
            return 0.0;
        }
        self.gain[y_px as usize * self.width_px as usize + x_px as usize]
    }

    /// Bilinear gain at floor texture coordinates (u right, v down, both 0..1, v = 0 at the
    /// photo top; plane-local `(x, y)` = `(u - 0.5, 0.5 - v)`), clamped to the edge.
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        let x = (u * self.width_px as f32 - 0.5).clamp(0.0, (self.width_px - 1) as f32);
        let y = (v * self.height_px as f32 - 0.5).clamp(0.0, (self.height_px - 1) as f32);
        let (x0, y0) = (x.floor() as u32, y.floor() as u32);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let g = |dx: u32, dy: u32| {
            self.gain_at(
                (x0 + dx).min(self.width_px - 1),
                (y0 + dy).min(self.height_px - 1),
            )
        };
        (g(0, 0) * (1.0 - fx) + g(1, 0) * fx) * (1.0 - fy)
            + (g(0, 1) * (1.0 - fx) + g(1, 1) * fx) * fy
    }
}

/// Why a bake file cannot be used.
#[derive(Debug, Error)]
pub enum BakeError {
    /// No file at the path.
    #[error("no caustics bake at {path}{}; bake it with `{}`", named_by(.scene), rebake(.scene, .path))]
    Missing {
        /// The path looked for.
        path: PathBuf,
        /// The scene that names it, when known.
        scene: Option<PathBuf>,
    },
    /// The file exists but cannot be read.
    #[error("cannot read the caustics bake {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The file is not a valid gain EXR.
    #[error(
        "the caustics bake {path}{} is corrupt or not a caustics bake: {reason}; bake it again \
         with `{}`",
        named_by(.scene),
        rebake(.scene, .path)
    )]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
        /// The scene that names it, when known.
        scene: Option<PathBuf>,
    },
    /// Baked for another object, light or floor (or one of them changed since).
    #[error(
        "the caustics bake {path}{} was baked for another object, light or floor (inputs hash \
         {found}, the scene's is {expected}): the model, the object's size, place, turn or index \
         of refraction, the light or the floor changed since; re-bake with `{}`",
        named_by(.scene),
        rebake(.scene, .path)
    )]
    WrongScene {
        /// The file.
        path: PathBuf,
        /// The hash of the scene's caustic inputs.
        expected: String,
        /// The hash stored in the file.
        found: String,
        /// The scene that names it, when known.
        scene: Option<PathBuf>,
    },
    /// Made by an earlier version, which stored the whole scene's hash, not its inputs'.
    #[error(
        "the caustics bake {path}{} was made by an earlier vitreous: it holds the hash of the \
         whole scene file (`{SCENE_HASH_ATTRIBUTE}`), not of the caustic's inputs \
         (`{INPUTS_HASH_ATTRIBUTE}`); re-bake with `{}`",
        named_by(.scene),
        rebake(.scene, .path)
    )]
    Outdated {
        /// The file.
        path: PathBuf,
        /// The scene that names it, when known.
        scene: Option<PathBuf>,
    },
    /// The scene names no bake (`[caustics] bake`) but the caustics were asked for.
    #[error(
        "the scene {scene} names no caustics bake: add `[caustics] bake = \"../bakes/<name>.exr\"` \
         and bake it with `vitreous bake {scene}`"
    )]
    NotNamed {
        /// The scene file.
        scene: PathBuf,
    },
    /// The scene moves (`[motion]`), and a bake holds one pose of the object and the light.
    #[error(
        "the scene {scene} moves its object or light ([motion]), and a caustics bake holds only \
         one pose: render it without caustics (e.g. --effects inducer)"
    )]
    MovingScene {
        /// The scene file.
        scene: PathBuf,
    },
    /// Writing failed.
    #[error("cannot write the caustics bake {path}: {reason}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The encoder's or operating system's reason.
        reason: String,
    },
}

/// Writes `bake` to `path` (channel `Y` as f32, and `light_ratio` as f16 when it has the
/// light; ZIP, deterministic byte for byte), whole or not at all.
pub fn write_bake(path: &Path, bake: &Bake) -> std::result::Result<(), BakeError> {
    let inputs_hash = bake
        .inputs_hash
        .as_deref()
        .ok_or_else(|| BakeError::Write {
            path: path.to_path_buf(),
            reason: "the bake has no inputs hash".to_owned(),
        })?;
    write_with_hash(path, bake, (INPUTS_HASH_ATTRIBUTE, inputs_hash))
}

/// [`write_bake`] with the hash under the attribute given (a test writes a bake as earlier
/// versions did).
fn write_with_hash(
    path: &Path,
    bake: &Bake,
    (attribute, hash): (&str, &str),
) -> std::result::Result<(), BakeError> {
    let write_err = |reason: String| BakeError::Write {
        path: path.to_path_buf(),
        reason,
    };
    let text = |s: &str| {
        Text::new_or_none(s)
            .ok_or_else(|| write_err(format!("attribute text {s:?} is not Latin-1")))
    };
    let size = (bake.width_px as usize, bake.height_px as usize);
    if bake.gain.len() != size.0 * size.1 {
        return Err(write_err(format!(
            "{} gain values for {} x {} texels",
            bake.gain.len(),
            size.0,
            size.1
        )));
    }
    let mut channels = vec![AnyChannel::new(
        GAIN_CHANNEL,
        FlatSamples::F32(bake.gain.clone()),
    )];
    if let Some(light) = &bake.light {
        if light.len() != bake.gain.len() {
            return Err(write_err(format!(
                "{} light ratios for {} x {} texels",
                light.len(),
                size.0,
                size.1
            )));
        }
        // Half floats: the renderer samples them so, and a ratio needs no more.
        channels.push(AnyChannel::new(
            LIGHT_CHANNEL,
            FlatSamples::F16(light.iter().map(|&r| f16::from_f32(r)).collect()),
        ));
    }
    // One custom attribute per attribute map: exr keeps them in hash maps, and a single
    // entry per map keeps the header's byte order fixed.
    let mut layer_attributes = LayerAttributes::default();
    layer_attributes.other.insert(
        text(PARAMS_ATTRIBUTE)?,
        AttributeValue::Text(text(&bake.params)?),
    );
    let layer = Layer::new(
        size,
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let mut image = Image::from_layer(layer);
    image
        .attributes
        .other
        .insert(text(attribute)?, AttributeValue::Text(text(hash)?));
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| write_err(e.to_string()))?;
    }
    // Encoded in memory, then written through a temporary file renamed into place: an
    // interrupted bake leaves the old file or none, never a half-written one.
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| write_err(e.to_string()))?;
    vitreous_trace::atomic_file::write(path, bytes.get_ref()).map_err(|e| write_err(e.to_string()))
}

/// ` (named by <scene>)` when the scene is known.
fn named_by(scene: &Option<PathBuf>) -> String {
    scene
        .as_ref()
        .map_or(String::new(), |s| format!(" (named by {})", s.display()))
}

/// The command that bakes `path` for `scene` (a placeholder when the scene is not known).
fn rebake(scene: &Option<PathBuf>, path: &Path) -> String {
    let scene = scene
        .as_ref()
        .map_or("<scene.toml>".to_owned(), |s| s.display().to_string());
    format!("vitreous bake {scene} -o {}", path.display())
}

impl BakeError {
    /// The error with the scene that names the bake, so that its message names the scene and
    /// gives the exact command that bakes it again.
    pub fn in_scene(self, scene: &Path) -> BakeError {
        let named = Some(scene.to_path_buf());
        match self {
            BakeError::Missing { path, .. } => BakeError::Missing { path, scene: named },
            BakeError::Corrupt { path, reason, .. } => BakeError::Corrupt {
                path,
                reason,
                scene: named,
            },
            BakeError::WrongScene {
                path,
                expected,
                found,
                ..
            } => BakeError::WrongScene {
                path,
                expected,
                found,
                scene: named,
            },
            BakeError::Outdated { path, .. } => BakeError::Outdated { path, scene: named },
            other => other,
        }
    }
}

/// Reads a bake and checks it was baked for the inputs with hash `expected_inputs_hash`
/// ([`inputs_hash`], [`crate::Scene::caustic_inputs_hash`]).
pub fn read_bake(path: &Path, expected_inputs_hash: &str) -> std::result::Result<Bake, BakeError> {
    let bake = read_bake_unchecked(path)?;
    match &bake.inputs_hash {
        None => Err(BakeError::Outdated {
            path: path.to_path_buf(),
            scene: None,
        }),
        Some(found) if found != expected_inputs_hash => Err(BakeError::WrongScene {
            path: path.to_path_buf(),
            expected: expected_inputs_hash.to_owned(),
            found: found.clone(),
            scene: None,
        }),
        Some(_) => Ok(bake),
    }
}

/// Reads a bake without checking which scene it belongs to (for comparisons).
pub fn read_bake_unchecked(path: &Path) -> std::result::Result<Bake, BakeError> {
    let corrupt = |reason: String| BakeError::Corrupt {
        path: path.to_path_buf(),
        reason,
        scene: None,
    };
    let bytes = DiskFiles
        .read_bounded(path, MAX_BAKE_BYTES, "the largest bake is smaller")
        .map_err(|source| match source.kind() {
            std::io::ErrorKind::NotFound => BakeError::Missing {
                path: path.to_path_buf(),
                scene: None,
            },
            std::io::ErrorKind::InvalidData => corrupt(source.to_string()),
            _ => BakeError::Io {
                path: path.to_path_buf(),
                source,
            },
        })?;
    decode_bake(&bytes).map_err(corrupt)
}

/// The largest side of a bake, texels: what the baker makes and the reader accepts.
pub const MAX_BAKE_SIDE_PX: u32 = 16384;

/// The largest bake file read, bytes: the largest map's f32 gains uncompressed, and room for
/// its header and chunk table.
pub const MAX_BAKE_BYTES: u64 = (MAX_BAKE_SIDE_PX as u64).pow(2) * 4 + (16 << 20);

/// Decodes a bake from the bytes of its EXR file; `Err` says what is wrong with them. Each
/// layer's size is checked (1..=[`MAX_BAKE_SIDE_PX`] texels per side) before any samples are
/// read, and a panic of the EXR decoder on hostile input becomes an error.
pub fn decode_bake(bytes: &[u8]) -> std::result::Result<Bake, String> {
    std::panic::catch_unwind(|| decode_unguarded(bytes)).unwrap_or_else(|_| {
        Err("the OpenEXR decoder failed on this file (internal panic)".to_owned())
    })
}

/// [`decode_bake`] without the guard against the decoder's panics.
fn decode_unguarded(bytes: &[u8]) -> std::result::Result<Bake, String> {
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| format!("bad OpenEXR header: {e}"))?;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.width(), header.layer_size.height());
        let side = 1..=MAX_BAKE_SIDE_PX as usize;
        if !side.contains(&w) || !side.contains(&h) {
            return Err(format!(
                "its layer is {w} x {h} texels; a bake has 1..={MAX_BAKE_SIDE_PX} per side"
            ));
        }
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| e.to_string())?;
    let attr_text = |map: &std::collections::HashMap<Text, AttributeValue>, name: &str| {
        map.iter().find_map(|(k, v)| match v {
            AttributeValue::Text(t) if k.eq(name) => Some(t.to_string()),
            _ => None,
        })
    };
    let layer = &image.layer_data;
    let attribute = |name: &str| {
        attr_text(&image.attributes.other, name)
            .or_else(|| attr_text(&layer.attributes.other, name))
    };
    let inputs_hash = attribute(INPUTS_HASH_ATTRIBUTE);
    if inputs_hash.is_none() && attribute(SCENE_HASH_ATTRIBUTE).is_none() {
        return Err(format!("it has no `{INPUTS_HASH_ATTRIBUTE}` attribute"));
    }
    let params = attr_text(&layer.attributes.other, PARAMS_ATTRIBUTE)
        .or_else(|| attr_text(&image.attributes.other, PARAMS_ATTRIBUTE))
        .unwrap_or_default();
    let (w, h) = (layer.size.width(), layer.size.height());
    // A channel's samples as f32, checked: as many as texels, finite and >= 0.
    let samples = |name: &str, what: &str| -> std::result::Result<Option<Vec<f32>>, String> {
        let Some(channel) = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
        else {
            return Ok(None);
        };
        let values: Vec<f32> = match &channel.sample_data {
            FlatSamples::F32(v) => v.clone(),
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
            FlatSamples::U32(_) => return Err(format!("the {what} channel holds integers")),
        };
        if values.len() != w * h || w == 0 || h == 0 {
            return Err(format!("{} samples for {w} x {h} texels", values.len()));
        }
        if let Some(bad) = values.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
            return Err(format!(
                "it holds a {what} of {bad}; they are finite and >= 0"
            ));
        }
        Ok(Some(values))
    };
    let gain = samples(GAIN_CHANNEL, "gain")?
        .ok_or_else(|| format!("it has no `{GAIN_CHANNEL}` channel"))?;
    let light = samples(LIGHT_CHANNEL, "light ratio")?;
    Ok(Bake {
        width_px: w as u32,
        height_px: h as u32,
        gain,
        light,
        inputs_hash,
        params,
    })
}

#[cfg(test)]
mod tests;
