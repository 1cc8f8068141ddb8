//! The command line of `vitreous view`.

use std::path::PathBuf;

use anyhow::Result;
use vitreous_render::Reflection;

use super::{EyesShown, ViewOptions, view};
use crate::cli_values::{parse_effects, parse_frame_count, parse_size};
use vitreous_gaze::FilterKind;
use vitreous_scene::effects::EffectSet;

/// Options of `vitreous view` (docs/view.md).
#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// Scene file (TOML); saving it, or an asset it names, reloads it.
    pub scene: PathBuf,
    /// Window size, e.g. 960x540.
    #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "960x540",
          allow_hyphen_values = true)]
    pub window: (u32, u32),
    /// Render the eye images at this fraction of their part of the window (0.25-1) and scale
    /// them up: faster on a CPU device.
    #[arg(long, value_name = "F", default_value_t = 1.0, allow_negative_numbers = true,
          value_parser = crate::cli_values::number::<f32>)]
    pub render_scale: f32,
    /// End after N frames (default: when the window is closed or Esc is pressed).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_frame_count)]
    pub frames: Option<u64>,
    /// Write the last picture shown as PNG when the session ends.
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// Timed input events (docs/view.md): `FRAME key 3`, `FRAME move 0.4 0.5`, ...
    #[arg(long, value_name = "FILE")]
    pub script: Option<PathBuf>,
    /// Effects to start with, overriding the scene's (as for replay).
    #[arg(long, value_name = "LIST", value_parser = parse_effects)]
    pub effects: Option<EffectSet>,
    /// Eyes shown: both (side by side), left or right.
    #[arg(long, value_parser = ["both", "left", "right"], default_value = "both")]
    pub eyes: String,
    /// Start with the see-through preview (the display's light added to the real world's).
    #[arg(long)]
    pub preview: bool,
    /// Start without the overlay (H shows it).
    #[arg(long)]
    pub no_overlay: bool,
    /// Start with the reflected image drawn as the environment map with a Fresnel term
    /// instead of the Phong highlight (F switches).
    #[arg(long)]
    pub environment_reflection: bool,
    /// Gaze filter overriding the scene's `[gaze] filter` (G steps through some).
    #[arg(long, value_name = "FILTER")]
    pub filter: Option<FilterKind>,
    /// Turn on the Vulkan validation layers; any message fails the session.
    #[arg(long)]
    pub validate: bool,
    /// Use the Vulkan device whose name contains this.
    #[arg(long)]
    pub device: Option<String>,
    /// Folder for summary.json (default: none written).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Play a recorded trace (v1) instead of the mouse and keys: K pauses, L steps, J and
    /// Shift+L seek.
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Record each frame's head pose and gaze as a trace (v1) that `vitreous replay
    /// --at-samples` renders again.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

/// Runs `vitreous view` and prints its summary line.
pub fn run(args: ViewArgs) -> Result<()> {
    let _signals = vitreous_frames::interrupt::watch();
    let summary = view(&ViewOptions {
        scene: args.scene,
        window: args.window,
        render_scale: args.render_scale,
        frames: args.frames,
        screenshot: args.screenshot,
        script: args.script,
        effects: args.effects,
        eyes: EyesShown::parse(&args.eyes).unwrap_or_default(),
        preview: args.preview,
        overlay: !args.no_overlay,
        reflection: if args.environment_reflection {
            Reflection::EnvironmentFresnel
        } else {
            Reflection::Phong
        },
        filter: args.filter,
        validate: args.validate,
        device: args.device,
        out: args.out,
        trace: args.trace,
        record: args.record,
    })?;
    println!("{}", summary.summary_line());
    if let Some(shot) = &summary.screenshot {
        println!("wrote {shot}");
    }
    Ok(())
}
