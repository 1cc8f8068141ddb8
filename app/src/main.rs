//! The `vitreous` command: the clap definitions of every subcommand and their dispatch to the
//! library. It passes 600 lines because each option's doc comment is its `--help` text; the
//! work itself is in the library, one module per command.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use vitreous::bench::{BenchOptions, bench};
use vitreous::cli_values::{
    parse_blend, parse_effects, parse_frame_count, parse_frame_count_usize, parse_gaze, parse_size,
};
use vitreous::effects::EffectSet;
use vitreous::error_report::error_text;
use vitreous::gaze::{FilterKind, GazeOverride, PupilSource};
use vitreous::output::ensure_not_input;
use vitreous::replay::{GazeSettings, ReplayOptions, replay};
use vitreous::trace_analyze::{analyze_trace_file, plot_trace_file};
use vitreous::trace_cmd::{self, SynthOptions};
use vitreous_render::Reflection;

/// Perception-based virtual glass for optical see-through headsets.
#[derive(Parser, Debug)]
#[command(name = "vitreous", version, about, long_about = None)]
struct Cli {
    /// Log verbosity (error, warn, info, debug, trace); RUST_LOG overrides.
    #[arg(long, global = true, default_value = "info")]
    log: String,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene on a live OpenXR runtime (a headset, or Monado): Vulkan through
    /// XR_KHR_vulkan_enable2, additive blend when offered, gaze from the headset or a trace.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// End the session after N frames (default: until the runtime or Ctrl-C ends it).
        #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_frame_count)]
        frames: Option<u64>,
        /// Replay gaze from this trace when the headset has no per-eye eye tracker (with
        /// XR_EXT_eye_gaze_interaction's combined ray alone, it decides the gaze image).
        #[arg(long, value_name = "FILE")]
        gaze_trace: Option<PathBuf>,
        /// Gaze source: auto (XR_ML_eye_tracker, then XR_FB_eye_tracking_social, then
        /// XR_EXT_eye_gaze_interaction, then the trace, then manual), or one of ml, fb, ext,
        /// trace, manual (an error when it is not offered).
        #[arg(long, value_name = "SOURCE", value_parser = parse_gaze, default_value = "auto")]
        gaze: vitreous_xr::openxr::GazeChoice,
        /// Record head pose and gaze of every frame into this trace file.
        #[arg(long, value_name = "FILE")]
        record: Option<PathBuf>,
        /// Turn on the Vulkan validation layers and the OpenXR core validation layer; any
        /// Vulkan message fails the run.
        #[arg(long)]
        validate: bool,
        /// Read back a submitted swapchain image and fail unless the object is in it.
        #[arg(long)]
        readback_check: bool,
        /// Blend mode instead of the automatic choice: additive, alpha-blend, opaque.
        #[arg(long, value_parser = parse_blend)]
        blend: Option<vitreous_xr::openxr::Blend>,
        /// Eye image size instead of the runtime's recommended one, e.g. 640x480.
        #[arg(long, value_name = "WxH", value_parser = parse_size)]
        size: Option<(u32, u32)>,
        /// Effects, overriding the scene's (as for replay).
        #[arg(long, value_name = "LIST", value_parser = parse_effects)]
        effects: Option<EffectSet>,
        /// Fixation-depth filter overriding the scene's `[gaze] filter` (as for replay).
        #[arg(long, value_name = "FILTER")]
        filter: Option<FilterKind>,
        /// Where A_p (eq. 13) comes from, overriding the scene's `[gaze] pupil`: paper (the
        /// fixed diameter) or measured (the eye tracker's, smoothed).
        #[arg(long = "pupil", value_name = "SOURCE")]
        pupil_source: Option<PupilSource>,
        /// Folder for summary.json (default: none written).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Read the live controls (`object x 10`, `turn -1`, `place`, `light y 10`,
        /// `register z -1`, one a line) from standard input also when it is not a terminal (a
        /// pipe or fifo); in a terminal they are always read.
        #[arg(long)]
        stdin_controls: bool,
    },
    /// Look around a scene in a desktop window: the frame loop and renderer of `run` with
    /// head and gaze from the mouse and keys (docs/view.md; F1 lists the keys).
    View(vitreous::view::ViewArgs),
    /// Replay a head/eye trace through the frame loop on a Vulkan device and write per-eye
    /// images, see-through previews and summary.json.
    Replay {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Trace to replay (vitreous trace format v1); default: a synthetic trace for the scene.
        #[arg(long)]
        trace: Option<PathBuf>,
        /// Output folder; default out/<scene name>.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Stop after N frames.
        #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_frame_count)]
        frames: Option<u64>,
        /// Save every K-th frame (0: none).
        #[arg(
            long,
            value_name = "K",
            default_value_t = 30,
            allow_negative_numbers = true
        )]
        save_every: u64,
        /// Eye image size overriding the scene's, e.g. 640x480.
        #[arg(long, value_name = "WxH", value_parser = parse_size)]
        size: Option<(u32, u32)>,
        /// Turn on the Vulkan validation layers (with synchronisation validation); any message
        /// fails the run.
        #[arg(long)]
        validate: bool,
        /// Effects, overriding the scene's: none, disparity, defocus, inducer, caustics, all,
        /// or a condition (O2..O5, a, b, c); comma-separated.
        #[arg(long, value_name = "LIST", value_parser = parse_effects)]
        effects: Option<EffectSet>,
        /// Use the Vulkan device whose name contains this.
        #[arg(long)]
        device: Option<String>,
        /// Display frame rate of the replay, hertz.
        #[arg(
            long,
            value_name = "HZ",
            default_value_t = 60.0,
            allow_negative_numbers = true
        )]
        rate: f64,
        /// One frame per trace sample, at the sample's time, instead of --rate: how
        /// `vitreous run` rendered the trace it recorded, so the two compare frame by frame.
        #[arg(long, conflicts_with = "rate")]
        at_samples: bool,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Reflected image with per-eye refraction: a Phong highlight of the scene's light
        /// (the paper's choice) or the environment map with a Fresnel term.
        #[arg(long, value_enum, default_value_t = ReflectionArg::Phong)]
        reflection: ReflectionArg,
        /// Also write each saved eye image under the paper's and under two-surface refraction
        /// beside the CPU ray-traced two-surface refraction layer (for sphere scenes: the
        /// object's bounding sphere is traced).
        #[arg(long)]
        reference: bool,
        /// Gaze image: auto (from the wearer's fixation depth), or forced to surface or
        /// refracted, as the paper's experimenter did; default: the scene's `[gaze] image`.
        #[arg(long, value_name = "IMAGE")]
        gaze_image: Option<GazeOverride>,
        /// Fixation-depth filter: mean20 (eq. 15), median5, one-euro, fixation (the gaze image
        /// decided per fixation), ...; default: the scene's `[gaze] filter` (fixation if it
        /// names none).
        #[arg(long, value_name = "FILTER")]
        filter: Option<FilterKind>,
        /// Pupil diameter A_p overriding the scene's, millimetres (1-9).
        #[arg(long = "pupil-mm", value_name = "MM", allow_negative_numbers = true)]
        pupil_mm: Option<f32>,
        /// Where A_p (eq. 13) comes from, overriding the scene's `[gaze] pupil`: paper (the
        /// fixed diameter) or measured (the trace's pupil diameters, smoothed).
        #[arg(long = "pupil", value_name = "SOURCE")]
        pupil_source: Option<PupilSource>,
    },
    /// Compare the frame time of the baseline and of effect sets, alternated frame by frame
    /// in one process on one device; prints medians, spreads and ratios to the baseline.
    Bench {
        /// Scene file (TOML).
        scene: PathBuf,
        /// An effect set to compare with the baseline (repeatable), e.g. O4 or disparity.
        #[arg(long, value_name = "LIST", value_parser = parse_effects, default_value = "O4")]
        effects: Vec<EffectSet>,
        /// Eye image size (the Magic Leap One's by default).
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "1280x960")]
        size: (u32, u32),
        /// Timed frames per variant.
        #[arg(long, value_name = "N", default_value_t = 60, allow_negative_numbers = true,
              value_parser = parse_frame_count_usize)]
        frames: usize,
        /// Reflected image with per-eye refraction.
        #[arg(long, value_enum, default_value_t = ReflectionArg::Phong)]
        reflection: ReflectionArg,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Turn on validation (for checking, not timing).
        #[arg(long)]
        validate: bool,
        /// Use the Vulkan device whose name contains this.
        #[arg(long)]
        device: Option<String>,
        /// Pupil diameters to sweep for effect sets with defocus, millimetres, e.g. 2,4,6,8.
        #[arg(
            long = "pupil-mm",
            value_name = "MM",
            value_delimiter = ',',
            allow_negative_numbers = true
        )]
        pupils_mm: Vec<f32>,
        /// Also time each variant with the light turning 1 degree about the object every
        /// frame, alternated with the same variant standing still.
        #[arg(long)]
        moving: bool,
        /// Also time each effect set with caustics on a second renderer that computes them
        /// per pose on the GPU, alternated with the scene's bake.
        #[arg(long = "live-caustics")]
        live_caustics: bool,
        /// Also time each variant with two-surface refraction on a second renderer,
        /// alternated with the same variant under the paper's refraction (ratio GPU/paper).
        #[arg(long = "two-surface")]
        two_surface: bool,
    },
    /// Replay a scene again and again in one process (a new Vulkan device and renderer each
    /// pass, validation on) and check that resident memory stays flat and validation silent.
    Soak {
        /// Scene file (TOML).
        #[arg(default_value = "config/scenes/glass-sphere.toml")]
        scene: PathBuf,
        /// How long to keep replaying, minutes.
        #[arg(
            long,
            value_name = "MIN",
            default_value_t = 30.0,
            allow_negative_numbers = true
        )]
        minutes: f64,
        /// Effects (default: the scene's); e.g. all.
        #[arg(long, value_name = "LIST", value_parser = parse_effects)]
        effects: Option<EffectSet>,
        /// Eye image size.
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "640x480")]
        size: (u32, u32),
        /// Frames per pass (at most the scene's 12 s synthetic trace at 60 Hz).
        #[arg(long, value_name = "N", default_value_t = 120, allow_negative_numbers = true,
              value_parser = parse_frame_count)]
        frames: u64,
        /// Write the report (every pass) as JSON here.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// A new Vulkan device and renderer for every pass instead of one for the whole run.
        #[arg(long)]
        recreate: bool,
        /// Validation layers off (to tell the layer's own memory from the driver's).
        #[arg(long)]
        no_validation: bool,
    },
    /// Trace tools.
    Trace {
        #[command(subcommand)]
        command: TraceCommand,
    },
    /// Paired-comparison studies.
    Study {
        #[command(subcommand)]
        command: vitreous::study::cli::StudyCommand,
    },
}

#[derive(Subcommand, Debug)]
enum TraceCommand {
    /// Report, for the default depth filter and each alternative, the gaze-image switch
    /// latency and the number of switches on a trace (paper eq. 15 and its alternatives).
    Analyze {
        /// The trace.
        trace: PathBuf,
        /// Scene giving the surface and refracted image distances.
        #[arg(long)]
        scene: PathBuf,
        /// Filters to compare (repeatable): mean20, mean:N, median5, median:N,
        /// one-euro[:min_cutoff=..,beta=..,d_cutoff=..,pre_median=..],
        /// fixation[:velocity=..,min_fixation=..,window=..,max_window=..,settle=..]; default all.
        #[arg(long = "filter", value_name = "FILTER")]
        filters: Vec<FilterKind>,
        /// Write the figures as JSON on stdout instead of the tables.
        #[arg(long)]
        json: bool,
    },
    /// Plot raw and filtered fixation depth over time with the gaze-image decisions (like
    /// the paper's Fig. 11).
    Plot {
        /// The trace.
        trace: PathBuf,
        /// Scene giving the surface and refracted image distances.
        #[arg(long)]
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        out: PathBuf,
        /// Filters to draw (repeatable); default all.
        #[arg(long = "filter", value_name = "FILTER")]
        filters: Vec<FilterKind>,
    },
    /// Import a recording from another tool into the vitreous trace format.
    Import {
        /// Recording format: sranipal (HTC Vive Pro Eye SRanipal CSV export), tobii-g3
        /// (Tobii Pro Glasses 3 recording folder or its gazedata.gz), neon (Pupil Labs Neon
        /// native recording folder). See docs/trace-import.md.
        #[arg(long)]
        from: String,
        /// The recording (file or folder, by format).
        file: PathBuf,
        /// Output trace file.
        #[arg(short, long)]
        out: PathBuf,
    },
    /// Synthesise a trace for a scene: the head at the viewer's position, the gaze
    /// alternating between the object's surface and the refracted background, tracker noise
    /// and blinks.
    Synth {
        /// Scene the trace is for.
        #[arg(long, default_value = "config/scenes/visual-effects.toml")]
        scene: PathBuf,
        /// Output trace file.
        #[arg(short, long)]
        out: PathBuf,
        /// Length, seconds.
        #[arg(long, default_value_t = 12.0, allow_negative_numbers = true)]
        duration: f32,
        /// Tracker sample rate, hertz.
        #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
        rate: f32,
        /// Seconds between gaze switches.
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
        switch_period: f32,
        /// Random seed (the same seed gives the same trace).
        #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
        seed: u64,
    },
}

/// How the reflected image is drawn.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum ReflectionArg {
    /// Phong highlight of the scene's point light.
    Phong,
    /// Environment map in the mirror direction, weighted by the Fresnel term.
    Environment,
}

impl From<ReflectionArg> for Reflection {
    fn from(r: ReflectionArg) -> Reflection {
        match r {
            ReflectionArg::Phong => Reflection::Phong,
            ReflectionArg::Environment => Reflection::EnvironmentFresnel,
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run {
            scene,
            frames,
            gaze_trace,
            gaze,
            record,
            validate,
            readback_check,
            blend,
            size,
            effects,
            filter,
            pupil_source,
            out,
            stdin_controls,
        } => {
            if let Some(record) = &record {
                let mut inputs = vec![scene.as_path()];
                inputs.extend(gaze_trace.as_deref());
                ensure_not_input(record, "--record", &inputs)?;
            }
            let s = vitreous::run::run(&vitreous::run::RunOptions {
                scene,
                frames,
                gaze_trace,
                gaze,
                record,
                validate,
                readback_check,
                blend,
                size,
                effects,
                filter,
                pupil_source,
                out,
                stdin_controls,
                ..Default::default()
            })?;
            print!("{}", s.report());
            Ok(())
        }
        Command::View(args) => vitreous::view::run(args),
        Command::Replay {
            scene,
            trace,
            out,
            frames,
            save_every,
            size,
            validate,
            effects,
            device,
            rate,
            at_samples,
            quiet,
            reflection,
            reference,
            gaze_image,
            filter,
            pupil_mm,
            pupil_source,
        } => {
            let out = match out {
                Some(out) => out,
                None => {
                    let stem = scene
                        .file_stem()
                        .context("the scene path has no file name")?;
                    PathBuf::from("out").join(stem)
                }
            };
            if let Some((w, h)) = size {
                vitreous::replay::check_size(w, h)?;
            }
            let summary = replay(&ReplayOptions {
                scene,
                trace,
                out: out.clone(),
                frames,
                save_every,
                size,
                validate,
                effects,
                device,
                frame_rate_hz: rate,
                at_samples,
                progress: !quiet,
                reflection: reflection.into(),
                reference,
                gaze: GazeSettings {
                    filter,
                    image: gaze_image,
                    pupil_mm,
                    pupil_source,
                },
            })?;
            println!("{}", summary.summary_line());
            println!(
                "wrote {} images and summary.json to {}",
                summary.saved.len(),
                out.display()
            );
            Ok(())
        }
        Command::Bench {
            scene,
            effects,
            size,
            frames,
            reflection,
            json,
            validate,
            device,
            pupils_mm,
            moving,
            live_caustics,
            two_surface,
        } => {
            let report = bench(&BenchOptions {
                scene,
                effects,
                size,
                frames,
                reflection: reflection.into(),
                validate,
                device,
                pupils_mm,
                moving,
                live_caustics,
                two_surface,
            })?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{}", report.table());
            }
            Ok(())
        }
        Command::Soak {
            scene,
            minutes,
            effects,
            size,
            frames,
            json,
            recreate,
            no_validation,
        } => {
            if !(minutes.is_finite() && minutes > 0.0 && minutes <= 7.0 * 24.0 * 60.0) {
                bail!("--minutes must be more than 0 and at most a week, got {minutes}");
            }
            let options = vitreous::soak::SoakOptions {
                scene,
                effects,
                duration: std::time::Duration::from_secs_f64(minutes * 60.0),
                size,
                frames_per_pass: frames,
                read_back_every: 10,
                validation: !no_validation,
                recreate,
            };
            let report = vitreous::soak::soak(&options, |p| eprintln!("soak: {p}"))?;
            if let Some(path) = &json {
                let bytes = serde_json::to_vec_pretty(&report)?;
                vitreous::output::write_atomic(path, &bytes)?;
            }
            println!("{}", report.summary_line());
            report.verdict()
        }
        Command::Trace { command } => match command {
            TraceCommand::Analyze {
                trace,
                scene,
                filters,
                json,
            } => {
                let report = analyze_trace_file(&trace, &scene, &filters)?;
                if json {
                    println!("{}", serde_json::to_string_pretty(&report.to_json())?);
                } else {
                    print!("{report}");
                }
                Ok(())
            }
            TraceCommand::Plot {
                trace,
                scene,
                out,
                filters,
            } => {
                ensure_not_input(&out, "--out", &[&trace, &scene])?;
                plot_trace_file(&trace, &scene, &filters, &out)?;
                println!("wrote {}", out.display());
                Ok(())
            }
            TraceCommand::Import { from, file, out } => {
                ensure_not_input(&out, "-o", &[&file])?;
                println!("{}", trace_cmd::import(&from, &file, &out)?);
                Ok(())
            }
            TraceCommand::Synth {
                scene,
                out,
                duration,
                rate,
                switch_period,
                seed,
            } => {
                if !scene.exists() {
                    bail!(
                        "scene {} not found; pass --scene SCENE (the trace is made for a scene)",
                        scene.display()
                    );
                }
                ensure_not_input(&out, "-o", &[&scene])?;
                let options = SynthOptions {
                    duration_s: duration,
                    rate_hz: rate,
                    switch_period_s: switch_period,
                    seed,
                };
                println!("{}", trace_cmd::synth(&scene, &options, &out)?);
                Ok(())
            }
        },
        Command::Study { command } => vitreous::study::cli::run(command),
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // One paragraph, like every other error: clap's own text without its trailer.
            let text = e.to_string();
            let first = text.split("\n\n").next().unwrap_or_default().trim();
            eprintln!("{first} (see --help)");
            return ExitCode::from(2);
        }
        Err(e) => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(format!("{},naga=warn", cli.log)));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .init();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}
