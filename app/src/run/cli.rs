//! The command line of `vitreous run`.

use std::path::PathBuf;

use anyhow::Result;

use super::{RECONNECT_S_DEFAULT, RECONNECT_S_MAX, RunOptions, run};
use crate::cli_values::{parse_blend, parse_effects, parse_frame_count, parse_gaze, parse_size};
use vitreous_gaze::{FilterKind, PupilSource};
use vitreous_scene::effects::EffectSet;

/// Options of `vitreous run` (docs/cli.md).
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// End the session after N frames (default: until the runtime or Ctrl-C ends it).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_frame_count)]
    pub frames: Option<u64>,
    /// Replay gaze from this trace when the headset has no per-eye eye tracker (with
    /// XR_EXT_eye_gaze_interaction's combined ray alone, it decides the gaze image).
    #[arg(long, value_name = "FILE")]
    pub gaze_trace: Option<PathBuf>,
    /// Gaze source: auto (XR_ML_eye_tracker, then XR_FB_eye_tracking_social, then
    /// XR_EXT_eye_gaze_interaction, then the trace, then manual), or one of ml, fb, ext,
    /// trace, manual (an error when it is not offered).
    #[arg(long, value_name = "SOURCE", value_parser = parse_gaze, default_value = "auto")]
    pub gaze: vitreous_xr::openxr::GazeChoice,
    /// Record head pose and gaze of every frame into this trace file.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Turn on the Vulkan validation layers and the OpenXR core validation layer; any
    /// Vulkan message fails the run.
    #[arg(long)]
    pub validate: bool,
    /// Read back a submitted swapchain image and fail unless the object is in it.
    #[arg(long)]
    pub readback_check: bool,
    /// Blend mode instead of the automatic choice: additive, alpha-blend, opaque.
    #[arg(long, value_parser = parse_blend)]
    pub blend: Option<vitreous_trace::Blend>,
    /// Eye image size instead of the runtime's recommended one, e.g. 640x480 (16-8192 per
    /// side; the runtime's maximum bounds it).
    #[arg(long, value_name = "WxH", value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<(u32, u32)>,
    /// Effects, overriding the scene's (as for replay).
    #[arg(long, value_name = "LIST", value_parser = parse_effects)]
    pub effects: Option<EffectSet>,
    /// Fixation-depth filter overriding the scene's `[gaze] filter` (as for replay).
    #[arg(long, value_name = "FILTER")]
    pub filter: Option<FilterKind>,
    /// Where A_p (eq. 13) comes from, overriding the scene's `[gaze] pupil`: paper (the
    /// fixed diameter) or measured (the eye tracker's, smoothed).
    #[arg(long = "pupil", value_name = "SOURCE")]
    pub pupil_source: Option<PupilSource>,
    /// Folder for summary.json (default: none written).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Read the live controls (`object x 10`, `turn -1`, `place`, `light y 10`,
    /// `register z -1`, one a line) from standard input also when it is not a terminal (a
    /// pipe or fifo); in a terminal they are always read.
    #[arg(long)]
    pub stdin_controls: bool,
    /// After a lost session or a lost runtime (the headset disconnected, the runtime
    /// restarted), wait up to this many seconds for it to come back and go on in a new
    /// session; 0 ends the run at the loss.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = parse_reconnect_s, default_value_t = RECONNECT_S_DEFAULT)]
    pub reconnect_s: f64,
}

/// Parses `--reconnect-s`: seconds from 0 to [`RECONNECT_S_MAX`].
fn parse_reconnect_s(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && (0.0..=RECONNECT_S_MAX).contains(v))
        .ok_or_else(|| format!("expected seconds from 0 to {RECONNECT_S_MAX}, got `{s}`"))
}

/// Runs the session `args` describe and prints its report.
pub fn run_command(args: RunArgs) -> Result<()> {
    // Before the runtime starts (which would clamp it to what it offers, silently).
    if let Some((w, h)) = args.size {
        vitreous_frames::setup::check_size(w, h)?;
    }
    let s = run(&RunOptions::from(args))?;
    print!("{}", s.report());
    Ok(())
}

impl From<RunArgs> for RunOptions {
    fn from(a: RunArgs) -> RunOptions {
        RunOptions {
            scene: a.scene,
            frames: a.frames,
            gaze_trace: a.gaze_trace,
            gaze: a.gaze,
            record: a.record,
            validate: a.validate,
            readback_check: a.readback_check,
            blend: a.blend,
            size: a.size,
            effects: a.effects,
            filter: a.filter,
            pupil_source: a.pupil_source,
            out: a.out,
            stdin_controls: a.stdin_controls,
            reconnect_s: Some(a.reconnect_s),
            ..Default::default()
        }
    }
}
