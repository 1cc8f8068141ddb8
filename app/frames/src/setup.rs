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

/// Reads the scene's caustic bake for the glass where nothing else read it (no condition
/// shows the caustics): through an object other than a ball, in a scene whose photos are the
/// room (`[environment] room`), the glass sees the floor under the object lit as the bake
/// says, its shadow and its caustic (`Bake::light`), rather than the bare photo. A bake that
/// cannot be used, or one made before it stored the floor's light, is a warning, and the
/// glass sees the bare photo.
pub fn load_bake_for_glass(scene: &mut Scene) {
    if !scene.environment.room
        || scene.object.is_ball()
        || scene.caustics.mode != vitreous_scene::CausticsMode::Baked
        || scene.caustics.bake.is_none()
        || scene.motion.is_animated()
    {
        return;
    }
    let unlit = "the glass sees the floor under the object without its shadow and caustic";
    if scene.caustics.gain.is_none()
        && let Err(e) = scene.load_caustics()
    {
        tracing::warn!("{unlit}: {e}");
        return;
    }
    if let (Some(bake), Some(path)) = (&scene.caustics.gain, &scene.caustics.bake)
        && bake.light.is_none()
    {
        tracing::warn!(
            "{unlit}: the caustic bake {} was made before bakes stored the floor's light; bake \
             it again with `vitreous bake {}`",
            path.display(),
            scene.path.display()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped(name: &str) -> Scene {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../config/scenes")
            .join(name);
        vitreous_scene::load_scene(&path).unwrap()
    }

    #[test]
    fn the_glass_reads_the_bake_for_a_mesh_in_the_room_and_not_for_a_ball() {
        // The goblet in the room: its bake read, with the floor's light.
        let mut goblet = shipped("goblet-real.toml");
        assert!(goblet.caustics.gain.is_none());
        load_bake_for_glass(&mut goblet);
        let bake = goblet
            .caustics
            .gain
            .as_ref()
            .expect("the goblet's bake read");
        assert!(
            bake.light.is_some(),
            "the shipped bake holds the floor's light"
        );
        // The ball in the same room keeps the bare photo: nothing read.
        let mut ball = shipped("glass-sphere-real.toml");
        load_bake_for_glass(&mut ball);
        assert!(ball.caustics.gain.is_none());
        // A bake that cannot be read is a warning, not an error: the glass sees the bare photo.
        let mut missing = shipped("goblet-real.toml");
        missing.caustics.bake = Some(missing.path.with_file_name("no-such-bake.exr"));
        load_bake_for_glass(&mut missing);
        assert!(missing.caustics.gain.is_none());
    }
}
