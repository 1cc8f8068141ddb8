//! The submitted-frames CSV (`VITREOUS_SIM_SUBMITTED`): one line per `xrEndFrame` the app
//! makes, written and flushed before the frame goes on to the runtime, so a test can check
//! what the app submitted even if the session dies.
//!
//! ```text
//! frame,display_time_ns,blend,layers,layer_types,layer_flags,runtime_blend,focus_distance_m,global_dimmer,session
//! 0,1234567890,additive,1,projection,0x0,opaque,1.5,0.25,0
//! ```
//!
//! `frame` counts the session's `xrEndFrame` calls from 0 and `session` the process's sessions
//! from 0 (an app that makes a new session after a loss appends to the same file); `blend` is
//! the app's
//! `environmentBlendMode`, `runtime_blend` the one forwarded to the runtime; `layer_types`
//! and `layer_flags` (hexadecimal `XrCompositionLayerFlags`) hold one entry per layer,
//! `;`-separated, in submission order. `focus_distance_m` is the `XrFrameEndInfoML` and
//! `global_dimmer` the `XrGlobalDimmerFrameEndInfoML` the app chained to `XrFrameEndInfo`
//! (Magic Leap 2's XR_ML_frame_end_info and XR_ML_global_dimmer, offered with
//! `VITREOUS_SIM_ML_FRAME=1`); empty when the frame had none (the dimmer also when its ENABLED
//! flag was off).

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, LazyLock, Mutex};

use openxr::sys;

use crate::blend;

/// The header line.
pub const HEADER: &str = "frame,display_time_ns,blend,layers,layer_types,layer_flags,runtime_blend,focus_distance_m,global_dimmer,session";

/// One submitted composition layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayerInfo {
    /// The layer's structure type.
    pub ty: sys::StructureType,
    /// Its `layerFlags`.
    pub flags: u64,
}

/// One submitted frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameInfo {
    /// Index of the frame in its session.
    pub frame: u64,
    /// The frame's display time, ns.
    pub display_time_ns: i64,
    /// The app's blend mode.
    pub blend: sys::EnvironmentBlendMode,
    /// The blend mode forwarded to the runtime.
    pub runtime_blend: sys::EnvironmentBlendMode,
    /// The layers.
    pub layers: Vec<LayerInfo>,
    /// The focus distance chained (`XrFrameEndInfoML`), metres.
    pub focus_distance_m: Option<f32>,
    /// The global dimmer chained and enabled (`XrGlobalDimmerFrameEndInfoML`), 0..=1.
    pub global_dimmer: Option<f32>,
    /// The process's session it belongs to, from 0.
    pub session: u64,
}

/// A short name for a composition layer type.
fn layer_type_name(ty: sys::StructureType) -> String {
    use sys::StructureType as S;
    match ty {
        S::COMPOSITION_LAYER_PROJECTION => "projection".to_owned(),
        S::COMPOSITION_LAYER_QUAD => "quad".to_owned(),
        S::COMPOSITION_LAYER_CYLINDER_KHR => "cylinder".to_owned(),
        S::COMPOSITION_LAYER_CUBE_KHR => "cube".to_owned(),
        S::COMPOSITION_LAYER_EQUIRECT_KHR => "equirect".to_owned(),
        S::COMPOSITION_LAYER_EQUIRECT2_KHR => "equirect2".to_owned(),
        S::COMPOSITION_LAYER_PASSTHROUGH_FB => "passthrough_fb".to_owned(),
        other => other.into_raw().to_string(),
    }
}

/// The CSV line of a frame, with its newline.
pub fn line(f: &FrameInfo) -> String {
    let types: Vec<String> = f.layers.iter().map(|l| layer_type_name(l.ty)).collect();
    let flags: Vec<String> = f.layers.iter().map(|l| format!("{:#x}", l.flags)).collect();
    let optional = |v: Option<f32>| v.map_or(String::new(), |v| v.to_string());
    format!(
        "{},{},{},{},{},{},{},{},{},{}\n",
        f.frame,
        f.display_time_ns,
        blend::name(f.blend),
        f.layers.len(),
        types.join(";"),
        flags.join(";"),
        blend::name(f.runtime_blend),
        optional(f.focus_distance_m),
        optional(f.global_dimmer),
        f.session
    )
}

/// The open CSV file.
#[derive(Debug)]
pub struct SubmittedLog {
    /// The file, unbuffered: every line is one write.
    file: File,
}

impl SubmittedLog {
    /// Creates (truncates) the file and writes the header.
    pub fn create(path: &Path) -> io::Result<SubmittedLog> {
        let mut file = File::create(path)?;
        file.write_all(format!("{HEADER}\n").as_bytes())?;
        Ok(SubmittedLog { file })
    }

    /// The process's log at `path`: created (truncated) by the first instance that names it,
    /// shared by every later one, so the sessions of a process go to one file.
    pub fn shared(path: &Path) -> io::Result<Arc<Mutex<SubmittedLog>>> {
        type Open = Vec<(PathBuf, Arc<Mutex<SubmittedLog>>)>;
        static OPEN: LazyLock<Mutex<Open>> = LazyLock::new(|| Mutex::new(Vec::new()));
        let mut open = OPEN.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, log)) = open.iter().find(|(p, _)| p == path) {
            return Ok(log.clone());
        }
        let log = Arc::new(Mutex::new(SubmittedLog::create(path)?));
        open.push((path.to_path_buf(), log.clone()));
        Ok(log)
    }

    /// Appends a frame's line.
    pub fn write(&mut self, frame: &FrameInfo) -> io::Result<()> {
        self.file.write_all(line(frame).as_bytes())?;
        self.file.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_is_one_line_with_layers_separated() {
        let f = FrameInfo {
            frame: 3,
            display_time_ns: 42,
            blend: sys::EnvironmentBlendMode::ALPHA_BLEND,
            runtime_blend: sys::EnvironmentBlendMode::OPAQUE,
            layers: vec![
                LayerInfo {
                    ty: sys::StructureType::COMPOSITION_LAYER_PROJECTION,
                    flags: 0x1 | 0x2,
                },
                LayerInfo {
                    ty: sys::StructureType::COMPOSITION_LAYER_QUAD,
                    flags: 0,
                },
            ],
            focus_distance_m: None,
            global_dimmer: None,
            session: 1,
        };
        assert_eq!(
            line(&f),
            "3,42,alpha_blend,2,projection;quad,0x3;0x0,opaque,,,1\n"
        );
        let empty = FrameInfo {
            layers: vec![],
            focus_distance_m: Some(1.25),
            global_dimmer: Some(0.5),
            ..f
        };
        assert_eq!(line(&empty), "3,42,alpha_blend,0,,,opaque,1.25,0.5,1\n");
    }

    #[test]
    fn the_file_gets_a_header_and_flushed_lines() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        let mut log = SubmittedLog::create(&path).unwrap();
        let f = FrameInfo {
            frame: 0,
            display_time_ns: 1,
            blend: sys::EnvironmentBlendMode::ADDITIVE,
            runtime_blend: sys::EnvironmentBlendMode::OPAQUE,
            layers: vec![LayerInfo {
                ty: sys::StructureType::COMPOSITION_LAYER_PROJECTION,
                flags: 0x2,
            }],
            focus_distance_m: None,
            global_dimmer: None,
            session: 0,
        };
        log.write(&f).unwrap();
        // Read while the log is still open: the line is already there.
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            format!("{HEADER}\n0,1,additive,1,projection,0x2,opaque,,,0\n")
        );
    }
}
