//! `vitreous reference SCENE`: what a real glass object would look like in the scene, per eye
//! and per saved frame of a trace, from the CPU ray tracer of `vitreous-reference`; beside each,
//! what the eye sees with nothing there. `vitreous compare` then measures the display's
//! see-through previews against it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use vitreous_reference::{
    EyeImage, EyeRecord, FrameReport, OBJECT_SAMPLES_PER_SIDE, PhotonParams, ReferenceSettings,
    Report, render_reference, srgb_rgba,
};
use vitreous_scene::{Placement, Scene, load_scene};
use vitreous_trace::EyeView;
use vitreous_xr::Backend;
use vitreous_xr::null::{NullBackend, NullConfig};

use vitreous_frames::input_files::InputFiles;
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::output::{EYE_NAMES, encode_png, is_frame_file_name, write_atomic};
use vitreous_frames::render_desc::eye_params;
use vitreous_frames::setup::{check_size, load_recording};

/// Most samples per pixel side.
pub const MAX_SAMPLES_PER_SIDE: u32 = 16;

/// Options of `vitreous reference` (docs/cli.md).
#[derive(clap::Args, Debug)]
pub struct ReferenceArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// A trace (head pose, gaze) to follow, as `vitreous replay --trace`: its frames at
    /// --rate, every --save-every'th written. Without one: one frame at the scene's neutral head
    /// (the viewer at `head_position_m`, looking down -z), as `vitreous compare` splits regions.
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// Output folder [default: out/<scene name>-reference].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --trace: stop after N frames [default: 1].
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli_values::parse_frame_count)]
    pub frames: Option<u64>,
    /// With --trace: write frames 0, K, 2K, ... (as `vitreous replay --save-every`).
    #[arg(long, value_name = "K", default_value_t = 30, allow_negative_numbers = true,
          value_parser = crate::cli_values::parse_save_every)]
    pub save_every: u64,
    /// With --trace: the display's frame rate, hertz (as `vitreous replay --rate`).
    #[arg(long, value_name = "HZ", default_value_t = 60.0, allow_negative_numbers = true,
          value_parser = crate::cli_values::number::<f64>)]
    pub rate: f64,
    /// Eye image size [default: the scene's `[output]`].
    #[arg(long, value_name = "WxH", value_parser = crate::cli_values::parse_size,
          allow_hyphen_values = true)]
    pub size: Option<(u32, u32)>,
    /// Which eyes: left, right or both.
    #[arg(long, value_name = "EYE", default_value = "both", value_parser = parse_eyes)]
    pub eye: Eyes,
    /// Samples along each side of a pixel (its light is the mean over N x N positions).
    #[arg(long, value_name = "N", default_value_t = 3, allow_negative_numbers = true,
          value_parser = parse_samples)]
    pub samples: u32,
    /// Samples along each side of a pixel the object may cover (where its bounding sphere,
    /// widened by a pixel, lies): behind glass the light changes within a pixel.
    #[arg(long, value_name = "N", default_value_t = OBJECT_SAMPLES_PER_SIDE,
          allow_negative_numbers = true, value_parser = parse_samples)]
    pub object_samples: u32,
    /// Side of the floor light's texels, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 1.0, allow_negative_numbers = true,
          value_parser = parse_texel_mm)]
    pub texel_mm: f32,
    /// Photons traced from the light per texel of floor under the object's cone.
    #[arg(long, value_name = "N", default_value_t = 64.0, allow_negative_numbers = true,
          value_parser = parse_photons)]
    pub photons_per_texel: f32,
    /// Also write each eye image as OpenEXR (`NNNNNN-EYE.exr`, `NNNNNN-EYE-seen.exr`): linear
    /// RGB in 32-bit floats as traced, light above 1 kept (the PNGs clip it and round to 8
    /// bits), for measuring against another renderer's light.
    #[arg(long)]
    pub exr: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Which eyes are rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eyes {
    /// The left eye only.
    Left,
    /// The right eye only.
    Right,
    /// Both eyes.
    Both,
}

impl Eyes {
    fn indices(self) -> &'static [usize] {
        match self {
            Eyes::Left => &[0],
            Eyes::Right => &[1],
            Eyes::Both => &[0, 1],
        }
    }
}

fn parse_eyes(s: &str) -> std::result::Result<Eyes, String> {
    match s {
        "left" => Ok(Eyes::Left),
        "right" => Ok(Eyes::Right),
        "both" => Ok(Eyes::Both),
        _ => Err(format!("expected left, right or both, found {s:?}")),
    }
}

fn parse_samples(s: &str) -> std::result::Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if (1..=MAX_SAMPLES_PER_SIDE).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected samples per pixel side between 1 and {MAX_SAMPLES_PER_SIDE}, found {s:?}"
        )),
    }
}

fn parse_texel_mm(s: &str) -> std::result::Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && (0.05..=50.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "expected a texel side between 0.05 and 50 mm, found {s:?}"
        )),
    }
}

fn parse_photons(s: &str) -> std::result::Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && (1.0..=4096.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "expected photons per texel between 1 and 4096, found {s:?}"
        )),
    }
}

/// One eye's camera in `reference.json`, from its view.
pub fn eye_record(view: &EyeView) -> EyeRecord {
    let f = view.fov;
    EyeRecord {
        position_m: view.pose.position.to_array(),
        orientation_xyzw: view.pose.orientation.to_array(),
        fov_rad: [
            f.angle_left_rad,
            f.angle_right_rad,
            f.angle_up_rad,
            f.angle_down_rad,
        ],
    }
}

/// Runs `vitreous reference`.
pub fn reference_command(args: ReferenceArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    for warning in &scene.warnings {
        tracing::warn!("{warning}");
    }
    let (width, height) = args
        .size
        .unwrap_or((scene.output.width_px, scene.output.height_px));
    check_size(width, height)?;
    if !(args.rate.is_finite() && (1.0..=1000.0).contains(&args.rate)) {
        bail!("--rate must be between 1 and 1000 Hz, got {}", args.rate);
    }
    if args.trace.is_none() && args.frames.is_some() {
        bail!("--frames needs --trace: without one the reference is the neutral head only");
    }
    let out = args.out.clone().unwrap_or_else(|| {
        let name = args
            .scene
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("out").join(format!("{name}-reference"))
    });
    let frames = frames_to_render(&scene, &args)?;
    let mut inputs = InputFiles::new();
    inputs.add_scene(&scene, "SCENE");
    if let Some(trace) = &args.trace {
        inputs.add(trace, "--trace");
    }
    inputs.check_folder("--out", &out, &[], &|p| {
        p.to_str().is_some_and(is_frame_file_name)
    })?;
    std::fs::create_dir_all(&out)
        .with_context(|| format!("creating output folder {}", out.display()))?;
    let settings = ReferenceSettings {
        samples_per_side: args.samples,
        object_samples_per_side: args.object_samples,
        photons: PhotonParams {
            texel_m: args.texel_mm / 1000.0,
            photons_per_texel: args.photons_per_texel,
            seed: 0,
        },
    };
    let progress = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new((frames.len() * args.eye.indices().len()) as u64);
        bar.set_style(
            ProgressStyle::with_template("{spinner} reference [{bar:30}] {pos}/{len} eyes {eta}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    };
    let mut reports = Vec::new();
    for frame in &frames {
        let started = Instant::now();
        let eyes = args.eye.indices();
        let cameras: Vec<_> = eyes.iter().map(|&e| eye_params(&frame.views[e])).collect();
        let rendered = render_reference(
            &scene,
            &cameras,
            &frame.placement,
            (width, height),
            &settings,
        )?;
        let mut files = Vec::new();
        for (k, &eye) in eyes.iter().enumerate() {
            for (suffix, image) in [("", &rendered.real[k]), ("-seen", &rendered.seen[k])] {
                let stem = format!("{:06}-{}{suffix}", frame.index, EYE_NAMES[eye]);
                write_png(&out.join(format!("{stem}.png")), image)?;
                files.push(format!("{stem}.png"));
                if args.exr {
                    write_exr(&out.join(format!("{stem}.exr")), image)?;
                    files.push(format!("{stem}.exr"));
                }
            }
            progress.inc(1);
        }
        let (count, noise) = (rendered.photons, rendered.noise);
        reports.push(FrameReport {
            frame: frame.index,
            time_ns: frame.time_ns,
            eyes: frame.views.each_ref().map(eye_record),
            object_position_m: frame.placement.object_position_m.to_array(),
            object_rotation_xyzw: frame.placement.object_rotation.to_array(),
            light_position_m: frame.placement.light_position_m.to_array(),
            photons: count,
            floor_light_noise: noise,
            files,
            seconds: started.elapsed().as_secs_f64(),
        });
    }
    progress.finish_and_clear();
    let trace = args
        .trace
        .as_ref()
        .map_or("neutral head".into(), |t| t.display().to_string());
    let report = Report::new(
        &scene,
        &args.scene,
        trace,
        (width, height),
        &settings,
        reports,
    );
    let json = serde_json::to_vec_pretty(&report).context("encoding reference.json")?;
    write_atomic(&out.join("reference.json"), &json)?;
    for f in &report.frames {
        println!(
            "frame {}: {} photons, floor light noise {:.4}, {:.1} s",
            f.frame, f.photons, f.floor_light_noise, f.seconds
        );
    }
    println!("wrote {}", out.display());
    Ok(())
}

/// A frame to render: its index and time, both eyes' cameras and where the object and light are.
struct Frame {
    index: u64,
    time_ns: i64,
    views: [EyeView; 2],
    placement: Placement,
}

/// The frames the reference renders: the neutral head without a trace; else the trace's
/// frames at the rate that are saved, placed as the replay places them.
fn frames_to_render(scene: &Scene, args: &ReferenceArgs) -> Result<Vec<Frame>> {
    let Some(trace) = &args.trace else {
        let views = scene
            .viewer
            .neutral_eye_positions_m()
            .map(|p: Vec3| EyeView {
                pose: vitreous_trace::Pose {
                    position: p,
                    orientation: Quat::IDENTITY,
                },
                fov: scene.output.fov,
            });
        return Ok(vec![Frame {
            index: 0,
            time_ns: 0,
            views,
            placement: scene.rest_placement(),
        }]);
    };
    let (recording, name) = load_recording(scene, Some(trace.as_path()))?;
    let edits = recording.edits;
    let mut backend = NullBackend::new(
        recording.samples,
        NullConfig {
            frame_rate_hz: args.rate,
            max_frames: Some(args.frames.unwrap_or(1)),
            fov: scene.output.fov,
            ipd_m: scene.viewer.ipd_m,
            at_samples: false,
        },
    )
    .with_context(|| format!("replaying {name}"))?
    .with_views(recording.views);
    let mut motion = MotionClock::new(scene);
    let mut edits = std::collections::VecDeque::from(edits);
    let mut frames = Vec::new();
    while let Some(input) = backend.wait_frame()? {
        while let Some(edit) = edits.front()
            && edit.time_ns <= input.time_ns
        {
            motion.replay_edit(edit, input.index);
            edits.pop_front();
        }
        let placement = motion
            .placement(input.time_ns)
            .unwrap_or_else(|| scene.rest_placement());
        if args.save_every > 0 && input.index.is_multiple_of(args.save_every) {
            frames.push(Frame {
                index: input.index,
                time_ns: input.time_ns,
                views: input.views,
                placement,
            });
        }
        backend.end_frame(&input)?;
    }
    if frames.is_empty() {
        bail!("--save-every {} writes none of the frames", args.save_every);
    }
    Ok(frames)
}

/// Writes a linear eye image as an sRGB PNG.
pub fn write_png(path: &Path, image: &EyeImage) -> Result<()> {
    let png = encode_png(&srgb_rgba(image), image.window.width, image.window.height)?;
    write_atomic(path, &png)
}

/// Writes a linear eye image as OpenEXR (RGB, 32-bit floats, lossless), encoded in memory and
/// then written whole.
pub fn write_exr(path: &Path, image: &EyeImage) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let width = image.window.width as usize;
    let pixels = SpecificChannels::rgb(|at: Vec2<usize>| {
        let p = image.rgb[at.y() * width + at.x()];
        (p.x, p.y, p.z)
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_channels((width, image.window.height as usize), pixels)
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .with_context(|| format!("encoding {} as OpenEXR", path.display()))?;
    write_atomic(path, bytes.get_ref())
}
