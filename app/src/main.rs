//! The `vitreous` command: the clap definitions of the subcommands and their dispatch to the
//! library. `run`, `view`, `replay` and `study` define their options beside their code
//! (`run::RunArgs`, `view::ViewArgs`, `replay::ReplayArgs`, `study::cli`), `bake` in the
//! baker's crate (`vitreous_caustics::command`); the work itself is in the libraries, one
//! module per command.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};
use vitreous::bench::{BenchOptions, bench};
use vitreous::cli_values::{
    ReflectionArg, number, parse_effects, parse_frame_count, parse_frame_count_usize,
    parse_growth_percent, parse_kappa_deg, parse_pass_count, parse_pupil_mm, parse_seed,
    parse_size,
};
use vitreous::error_report::error_text;
use vitreous::trace_analyze::{analyze_trace_file, plot_trace_file};
use vitreous::trace_cmd::{self, ImportOptions, SynthOptions};
use vitreous_gaze::FilterKind;
use vitreous_scene::effects::EffectSet;

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
    Run(vitreous::run::RunArgs),
    /// Look around a scene in a desktop window: the frame loop and renderer of `run` with
    /// head and gaze from the mouse and keys (docs/view.md; F1 lists the keys).
    View(vitreous::view::ViewArgs),
    /// Replay a head/eye trace through the frame loop on a Vulkan device and write per-eye
    /// images, see-through previews and summary.json.
    Replay(vitreous::replay::ReplayArgs),
    /// Compare the frame time of the baseline and of effect sets, alternated frame by frame
    /// in one process on one device; prints medians, spreads and ratios to the baseline.
    Bench {
        /// Scene file (TOML).
        scene: PathBuf,
        /// An effect set to compare with the baseline (repeatable), e.g. O4 or disparity.
        #[arg(long, value_name = "LIST", value_parser = parse_effects, default_value = "O4")]
        effects: Vec<EffectSet>,
        /// Eye image size (the Magic Leap One's by default).
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "1280x960",
              allow_hyphen_values = true)]
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
            allow_negative_numbers = true,
            value_parser = parse_pupil_mm
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
        /// Also time each variant with the frame's proof of coverage off (the whole glass
        /// drawn with the environment's lookup), alternated with the same variant drawn as
        /// the proof allows (ratio GPU/unproved).
        #[arg(long)]
        unproved: bool,
    },
    /// Replay a scene again and again in one process (one Vulkan device and renderer for the
    /// run, validation on) and check that resident memory stays flat and validation silent;
    /// several scenes one after another, each on its own device.
    Soak {
        /// Scene files (TOML).
        #[arg(default_value = "config/scenes/glass-sphere.toml")]
        scenes: Vec<PathBuf>,
        /// How long to keep replaying each scene, minutes.
        #[arg(long, value_name = "MIN", default_value_t = 30.0, allow_negative_numbers = true,
              value_parser = number::<f64>)]
        minutes: f64,
        /// Replay each scene this many times instead of for --minutes (2 warm-up passes, then
        /// at least 2 compared).
        #[arg(long, value_name = "N", conflicts_with = "minutes", allow_negative_numbers = true,
              value_parser = parse_pass_count)]
        passes: Option<usize>,
        /// Effects (default: the scene's); e.g. all.
        #[arg(long, value_name = "LIST", value_parser = parse_effects)]
        effects: Option<EffectSet>,
        /// Every effect each scene's assets allow: all, less the caustics where a scene has
        /// neither a bake nor live caustics.
        #[arg(long, conflicts_with = "effects")]
        all_effects: bool,
        /// Largest growth of resident memory after warm-up that passes, percent.
        #[arg(long, value_name = "PERCENT", default_value_t = vitreous_frames::soak::MAX_GROWTH_PERCENT,
              allow_negative_numbers = true, value_parser = parse_growth_percent)]
        max_growth: f64,
        /// Eye image size.
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "640x480",
              allow_hyphen_values = true)]
        size: (u32, u32),
        /// Frames per pass (at most the scene's 12 s synthetic trace at 60 Hz).
        #[arg(long, value_name = "N", default_value_t = 120, allow_negative_numbers = true,
              value_parser = parse_frame_count)]
        frames: u64,
        /// Write the report (every pass) as JSON here; an array of reports for several scenes.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// A new Vulkan device and renderer for every pass instead of one for the whole run.
        #[arg(long)]
        recreate: bool,
        /// Validation layers off (to tell the layer's own memory from the driver's).
        #[arg(long)]
        no_validation: bool,
    },
    /// How far an image is from a reference: FLIP and PSNR over the whole view and, with a
    /// scene, per region (the object's disc, shadow and caustic, inducer ramp, rest).
    Compare(vitreous::compare_cmd::CompareArgs),
    /// What a real glass object would look like in the scene, per eye (CPU ray tracer), beside
    /// what the eye sees with nothing there: the physical reference `compare` measures against.
    Reference(vitreous::reference_cmd::ReferenceArgs),
    /// One picture of what the wearer sees beside a real glass object, with the disc's and the
    /// shadow's FLIP, for `replay --compare-reference` runs side by side.
    Sheet(vitreous::sheet_cmd::SheetArgs),
    /// Bake the caustic gain map G that a scene's glass object throws onto the real floor
    /// (docs/caustics.md), by default into the `bakes` folder beside the scene's folder.
    Bake(vitreous_caustics::command::BakeArgs),
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
        /// fixation[:velocity=..,min_fixation=..,window=..,max_window=..,settle=..],
        /// evidence[:threshold=..,step=..,settle=..,min_separability=..,noise=..,margin=..];
        /// default all.
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
        /// native recording folder; its gaze stream, or without one its eye states' optical
        /// axes). See docs/trace-import.md.
        #[arg(long)]
        from: String,
        /// The recording (file or folder, by format).
        file: PathBuf,
        /// Output trace file.
        #[arg(short, long)]
        out: PathBuf,
        /// Neon, gaze from the eye states (a recording without a gaze stream, or
        /// --eye-state-gaze): the angle kappa, degrees, by which each eye's optical axis is
        /// turned toward the nose to give its line of sight. Default 5, a population mean
        /// for adults, not the wearer's.
        #[arg(long, value_name = "DEGREES", value_parser = parse_kappa_deg, allow_negative_numbers = true)]
        kappa_deg: Option<f64>,
        /// Neon: take the gaze from the eye states' optical axes (turned by kappa) even when
        /// the recording has a gaze stream.
        #[arg(long)]
        eye_state_gaze: bool,
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
        #[arg(long, default_value_t = 12.0, allow_negative_numbers = true,
              value_parser = number::<f32>)]
        duration: f32,
        /// Tracker sample rate, hertz.
        #[arg(long, default_value_t = 30.0, allow_negative_numbers = true,
              value_parser = number::<f32>)]
        rate: f32,
        /// Seconds between gaze switches (0 or less: the gaze stays on the surface point).
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true,
              value_parser = number::<f32>)]
        switch_period: f32,
        /// Random seed (the same seed gives the same trace).
        #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = parse_seed)]
        seed: u64,
    },
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run(args) => vitreous::run::run_command(args),
        Command::View(args) => vitreous::view::run(args),
        Command::Replay(args) => vitreous::replay::replay_command(args),
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
            unproved,
        } => {
            let report = bench(&BenchOptions {
                scene,
                effects,
                size,
                frames,
                warm_up: vitreous::bench::WARM_UP_FRAMES,
                reflection: reflection.into(),
                validate,
                device,
                pupils_mm,
                moving,
                live_caustics,
                two_surface,
                unproved,
            })?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{}", report.table());
            }
            Ok(())
        }
        Command::Soak {
            scenes,
            minutes,
            passes,
            effects,
            all_effects,
            max_growth,
            size,
            frames,
            json,
            recreate,
            no_validation,
        } => {
            use vitreous_frames::soak::{SoakEffects, SoakLength};
            if !(minutes.is_finite() && minutes > 0.0 && minutes <= 7.0 * 24.0 * 60.0) {
                bail!("--minutes must be more than 0 and at most a week, got {minutes}");
            }
            let options = vitreous_frames::soak::SoakOptions {
                scene: PathBuf::new(),
                effects: match (effects, all_effects) {
                    (Some(set), _) => SoakEffects::Set(set),
                    (None, true) => SoakEffects::Available,
                    (None, false) => SoakEffects::Scene,
                },
                length: match passes {
                    Some(n) => SoakLength::Passes(n),
                    None => {
                        SoakLength::Duration(std::time::Duration::from_secs_f64(minutes * 60.0))
                    }
                },
                size,
                frames_per_pass: frames,
                read_back_every: 10,
                validation: !no_validation,
                recreate,
                report: json.clone(),
                max_growth_percent: max_growth,
            };
            vitreous::soak::soak_scenes(&scenes, &options, json.as_deref())
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
                plot_trace_file(&trace, &scene, &filters, &out)?;
                println!("wrote {}", out.display());
                Ok(())
            }
            TraceCommand::Import {
                from,
                file,
                out,
                kappa_deg,
                eye_state_gaze,
            } => {
                let options = ImportOptions {
                    kappa_deg,
                    eye_state_gaze,
                };
                println!("{}", trace_cmd::import(&from, &file, &out, &options)?);
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
        Command::Compare(args) => vitreous::compare_cmd::compare_command(args),
        Command::Reference(args) => vitreous::reference_cmd::reference_command(args),
        Command::Sheet(args) => vitreous::sheet_cmd::sheet_command(args),
        Command::Bake(args) => vitreous_caustics::command::bake_command(args),
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
