//! The command line of `vitreous replay`.

use std::path::PathBuf;

use anyhow::{Context, Result};

use super::{Fields, GazeSettings, ReplayOptions, replay};
use crate::cli_values::{
    ReflectionArg, number, parse_effects, parse_frame_count, parse_pupil_mm, parse_save_every,
    parse_size,
};
use vitreous_frames::setup::check_size;
use vitreous_gaze::{FilterKind, GazeOverride, PupilSource};
use vitreous_scene::effects::EffectSet;

/// Options of `vitreous replay` (docs/cli.md).
#[derive(clap::Args, Debug)]
pub struct ReplayArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Trace to replay (vitreous trace format v1); default: a synthetic trace for the scene.
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Output folder; default out/<scene name>.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Stop after N frames.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_frame_count)]
    pub frames: Option<u64>,
    /// Save every K-th frame (0: none).
    #[arg(long, value_name = "K", default_value_t = 30, allow_negative_numbers = true,
          value_parser = parse_save_every)]
    pub save_every: u64,
    /// Eye image size overriding the scene's, e.g. 640x480.
    #[arg(long, value_name = "WxH", value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<(u32, u32)>,
    /// Turn on the Vulkan validation layers (with synchronisation validation); any message
    /// fails the run.
    #[arg(long)]
    pub validate: bool,
    /// Effects, overriding the scene's: none, disparity, defocus, inducer, caustics, all,
    /// or a condition (O2..O5, a, b, c); comma-separated.
    #[arg(long, value_name = "LIST", value_parser = parse_effects)]
    pub effects: Option<EffectSet>,
    /// Use the Vulkan device whose name contains this.
    #[arg(long)]
    pub device: Option<String>,
    /// Display frame rate of the replay, hertz.
    #[arg(long, value_name = "HZ", default_value_t = 60.0, allow_negative_numbers = true,
          value_parser = number::<f64>)]
    pub rate: f64,
    /// One frame per trace sample, at the sample's time, instead of --rate: how
    /// `vitreous run` rendered the trace it recorded, so the two compare frame by frame.
    #[arg(long, conflicts_with = "rate")]
    pub at_samples: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Reflected image with per-eye refraction: a Phong highlight of the scene's light
    /// (the paper's choice) or the environment map with a Fresnel term.
    #[arg(long, value_enum, default_value_t = ReflectionArg::Phong)]
    pub reflection: ReflectionArg,
    /// Also write each saved eye image under the paper's and under two-surface refraction
    /// beside the sphere check's two-surface refraction layer, computed on the CPU (for
    /// sphere scenes: the object's bounding sphere is traced). `--reference` is its old name.
    #[arg(long, alias = "reference")]
    pub sphere_check: bool,
    /// Also render the physical reference of every saved frame (as `vitreous reference`:
    /// `NNNNNN-left-real.png`, `NNNNNN-left-seen.png`) and report in summary.json ꟻLIP and
    /// PSNR per region of what the eye sees (the display's light over the seen image) against
    /// it, beside the seen image's and the additive limit's.
    #[arg(long)]
    pub compare_reference: bool,
    /// With --compare-reference: also measure what the eye sees with the display's light and
    /// its dimmer's panel misregistered by each of these angles (degrees, comma-separated,
    /// each above 0 and at most 10), shifted right, left, down and up in turn.
    #[arg(long, value_name = "DEG,...", requires = "compare_reference", value_delimiter = ',',
          value_parser = parse_shift_angle)]
    pub compare_shift_deg: Vec<f32>,
    /// Gaze image: auto (from the wearer's fixation depth), or forced to surface or
    /// refracted, as the paper's experimenter did; default: the scene's `[gaze] image`.
    #[arg(long, value_name = "IMAGE")]
    pub gaze_image: Option<GazeOverride>,
    /// Gaze-image decision: evidence (accumulated evidence weighed by the tracker's noise),
    /// fixation (decided per fixation), or a fixation-depth filter: mean20 (eq. 15), median5,
    /// one-euro, ...; default: the scene's `[gaze] filter` (evidence if it names none).
    #[arg(long, value_name = "FILTER")]
    pub filter: Option<FilterKind>,
    /// Pupil diameter A_p overriding the scene's, millimetres (1-9).
    #[arg(long = "pupil-mm", value_name = "MM", allow_negative_numbers = true,
          value_parser = parse_pupil_mm)]
    pub pupil_mm: Option<f32>,
    /// Where A_p (eq. 13) comes from, overriding the scene's `[gaze] pupil`: paper (the
    /// fixed diameter) or measured (the trace's pupil diameters, smoothed).
    #[arg(long = "pupil", value_name = "SOURCE")]
    pub pupil_source: Option<PupilSource>,
    /// The field of view each eye is drawn with: the scene's (`[output]`), or, from a
    /// recording's views lines (trace version 1.5), the headset's; with `recorded` and no
    /// --size the image is the scene's width and as high as makes its pixels square.
    #[arg(long, value_enum, default_value_t = Fields::Scene)]
    pub fields: Fields,
}

/// Replays what `args` describe and prints where the output went (default
/// `out/<scene name>`).
pub fn replay_command(a: ReplayArgs) -> Result<()> {
    let out = match a.out {
        Some(out) => out,
        None => {
            let stem = a
                .scene
                .file_stem()
                .context("the scene path has no file name")?;
            PathBuf::from("out").join(stem)
        }
    };
    if let Some((w, h)) = a.size {
        check_size(w, h)?;
    }
    let summary = replay(&ReplayOptions {
        scene: a.scene,
        trace: a.trace,
        out: out.clone(),
        frames: a.frames,
        save_every: a.save_every,
        size: a.size,
        validate: a.validate,
        effects: a.effects,
        device: a.device,
        frame_rate_hz: a.rate,
        at_samples: a.at_samples,
        progress: !a.quiet,
        reflection: a.reflection.into(),
        sphere_check: a.sphere_check,
        compare_reference: a.compare_reference,
        compare_shifts_deg: a.compare_shift_deg,
        gaze: GazeSettings {
            filter: a.filter,
            image: a.gaze_image,
            pupil_mm: a.pupil_mm,
            pupil_source: a.pupil_source,
        },
        fields: a.fields,
    })?;
    println!("{}", summary.summary_line());
    if let Some(s) = &summary.separability {
        println!("{}", s.line());
    }
    println!("{}", written_line(&summary.saved, &out));
    Ok(())
}

/// What a replay wrote into `out`, `saved` the files besides `summary.json`: the images
/// counted, every other file named (`frames/reference.json`).
fn written_line(saved: &[String], out: &std::path::Path) -> String {
    let images = saved.iter().filter(|f| f.ends_with(".png")).count();
    let mut files: Vec<&str> = saved
        .iter()
        .filter(|f| !f.ends_with(".png"))
        .map(String::as_str)
        .collect();
    files.push("summary.json");
    let last = files.pop().unwrap_or_default();
    let mut parts = vec![format!(
        "{images} image{}",
        if images == 1 { "" } else { "s" }
    )];
    parts.extend(files.iter().map(|f| f.to_string()));
    format!("wrote {} and {last} to {}", parts.join(", "), out.display())
}

/// One angle of `--compare-shift-deg`.
fn parse_shift_angle(s: &str) -> std::result::Result<f32, String> {
    let limit = vitreous_optics::display::registration::MAX_SHIFT_DEG;
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= limit => Ok(v),
        _ => Err(format!(
            "expected angles above 0 and at most {limit} degrees, found {s:?}"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_written_line_counts_images_and_names_other_files() {
        let out = std::path::Path::new("out/x");
        let saved = ["frames/000000-left.png", "frames/reference.json"].map(String::from);
        assert_eq!(
            written_line(&saved, out),
            "wrote 1 image, frames/reference.json and summary.json to out/x"
        );
        assert_eq!(
            written_line(&[], out),
            "wrote 0 images and summary.json to out/x"
        );
    }
}
