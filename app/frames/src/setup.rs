//! What every command does before its frame loop: the eye image size check and the trace to
//! replay (read with its scene edits, or synthesised for the scene).

use std::path::Path;

use anyhow::{Context, Result, bail};
use vitreous_scene::{Scene, synth_params_for};
use vitreous_trace::format::{Recording, TraceSample, read_recording};

/// The largest eye image side accepted, pixels.
pub const MAX_SIZE_PX: u32 = 8192;

/// Refuses eye image sizes the renderer cannot or should not take.
pub fn check_size(width: u32, height: u32) -> Result<()> {
    if !(16..=MAX_SIZE_PX).contains(&width) || !(16..=MAX_SIZE_PX).contains(&height) {
        bail!("eye image size {width}x{height} is outside 16..={MAX_SIZE_PX} pixels per side");
    }
    Ok(())
}

/// Refuses a trace with no samples (its header alone), naming it: there is nothing to
/// `purpose` (`replay`, `analyse`).
pub fn ensure_samples(path: &Path, samples: &[TraceSample], purpose: &str) -> Result<()> {
    if samples.is_empty() {
        bail!(
            "trace {} has no samples: nothing to {purpose}",
            path.display()
        );
    }
    Ok(())
}

/// Loads the trace or synthesises one for the scene.
pub fn load_trace(scene: &Scene, trace: Option<&Path>) -> Result<(Vec<TraceSample>, String)> {
    load_recording(scene, trace).map(|(r, name)| (r.samples, name))
}

/// Loads the trace, with its scene edits and session events, or synthesises one (without
/// either) for the scene; the name to report it by.
pub fn load_recording(scene: &Scene, trace: Option<&Path>) -> Result<(Recording, String)> {
    match trace {
        Some(path) => {
            let recording = read_recording(path).context("reading the trace")?;
            ensure_samples(path, &recording.samples, "replay")?;
            Ok((recording, path.display().to_string()))
        }
        None => {
            tracing::info!("no --trace given: replaying a synthetic trace for the scene");
            let samples = vitreous_trace::synth::synthesize_with_truth(&synth_params_for(scene))
                .context("synthesising a trace for the scene")?
                .samples;
            let recording = Recording {
                samples,
                ..Recording::default()
            };
            Ok((recording, "synthetic".into()))
        }
    }
}
