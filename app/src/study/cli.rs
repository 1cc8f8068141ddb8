//! `vitreous study ...`: the command-line definitions of the study commands and what each does.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Subcommand;

use super::run::{StudyRunOptions, run_study, timing_log_path};
use crate::cli_values::{number, parse_blend, parse_gaze, parse_seed, parse_size, whole_number};
use crate::run::RunOptions;
use vitreous_frames::input_files::InputFiles;
use vitreous_frames::output::write_atomic;
use vitreous_study::plan::{MAX_PARTICIPANTS, plan, write_plan};
use vitreous_study::protocol::Protocol;

/// The study subcommands.
#[derive(Subcommand, Debug)]
pub enum StudyCommand {
    /// Write every participant's trial order for a protocol: every pair in the protocol's
    /// presentation orders, randomised per participant from the seed and balanced across
    /// participants (Williams designs); the same seed gives the same plan.
    Plan {
        /// The protocol (config/studies/*.toml).
        protocol: PathBuf,
        /// Number of participants (named p01, p02, ...).
        #[arg(long, value_name = "N", allow_negative_numbers = true,
              value_parser = parse_participants)]
        participants: usize,
        /// Seed of the randomisation.
        #[arg(long, value_name = "S", allow_negative_numbers = true, value_parser = parse_seed)]
        seed: u64,
        /// The plan file to write (CSV).
        #[arg(short, long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Run one participant's trials: stimuli on the protocol's clock, blanks between, answers
    /// from the keyboard (type 1/2, or -3..3, then Enter) or the controller, each appended to
    /// the responses file at once; a restart resumes at the first unanswered trial.
    Run {
        /// The protocol (config/studies/*.toml).
        protocol: PathBuf,
        /// The plan written by `vitreous study plan`.
        #[arg(long, value_name = "FILE")]
        plan: PathBuf,
        /// The participant whose trials to run (as named in the plan).
        #[arg(long, value_name = "ID")]
        participant: String,
        /// The responses file, appended to (default: responses.csv); the timing log goes beside
        /// it as <name>-timing.csv.
        #[arg(long, value_name = "FILE", default_value = "responses.csv")]
        responses: PathBuf,
        /// Headless on the null backend (lavapipe or any Vulkan device) instead of the OpenXR
        /// runtime, replaying --trace or a synthetic trace of each scene.
        #[arg(long)]
        dry_run: bool,
        /// In a desktop window instead (the `vitreous view` simulator: head and gaze from the
        /// mouse, or --trace played), answers typed in the terminal.
        #[arg(long, conflicts_with = "dry_run")]
        view: bool,
        /// Window size of --view.
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "960x540",
              allow_hyphen_values = true)]
        window: (u32, u32),
        /// The trace a dry run replays, or --view plays.
        #[arg(long, value_name = "FILE")]
        trace: Option<PathBuf>,
        /// Display rate of a dry run, Hz.
        #[arg(long, value_name = "HZ", default_value_t = 30.0, requires = "dry_run",
              allow_negative_numbers = true, value_parser = number::<f64>)]
        rate: f64,
        /// Every protocol duration multiplied by F (rehearsals and tests; logged with each
        /// event's times).
        #[arg(long, value_name = "F", default_value_t = 1.0, allow_negative_numbers = true,
              value_parser = number::<f64>)]
        time_scale: f64,
        /// Stop after N answers (the next run resumes).
        #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_trials)]
        trials: Option<usize>,
        /// A simulated participant answers instead, from scale values NAME=VALUE,... (Case V
        /// choices, or ratings of the difference plus unit normal noise).
        #[arg(long, value_name = "SCALE")]
        simulate: Option<String>,
        /// Seed of the simulated participant.
        #[arg(long, value_name = "S", default_value_t = 1, allow_negative_numbers = true,
              value_parser = parse_seed)]
        seed: u64,
        /// Do not read answers from the keyboard (controller or --simulate only).
        #[arg(long)]
        no_keyboard: bool,
        /// Vulkan validation (and OpenXR core validation); any message fails the run.
        #[arg(long)]
        validate: bool,
        /// Eye image size, e.g. 640x480 (default: the runtime's, or the scene's in a dry run).
        #[arg(long, value_name = "WxH", value_parser = parse_size, allow_hyphen_values = true)]
        size: Option<(u32, u32)>,
        /// Blend mode instead of the automatic choice: additive, alpha-blend, opaque.
        #[arg(long, value_parser = parse_blend)]
        blend: Option<vitreous_trace::Blend>,
        /// Gaze source (as for `vitreous run`).
        #[arg(long, value_name = "SOURCE", value_parser = parse_gaze, default_value = "auto")]
        gaze: vitreous_xr::openxr::GazeChoice,
        /// Gaze replayed from this trace when the headset has no per-eye eye tracker.
        #[arg(long, value_name = "FILE")]
        gaze_trace: Option<PathBuf>,
        /// On the headset: a folder where each block's session writes, in a folder named after
        /// its stimulus, its summary.json, frames.csv and the recording of its head and gaze
        /// (recorded.trace, as `vitreous run --record`).
        #[arg(long, value_name = "DIR", conflicts_with_all = ["dry_run", "view"])]
        out: Option<PathBuf>,
    },
    /// Analyse a responses file (participant,trial,first,second,response[,stimulus]): forced
    /// choices with Thurstone's Case V and Mosteller's chi-square, -3..3 ratings with Nakaya's
    /// variant of Scheffe's method (ANOVA, yardsticks from the studentized range); each
    /// stimulus on its own.
    Analyze {
        /// The responses file (CSV).
        responses: PathBuf,
        /// Write the results as JSON on stdout instead of the tables.
        #[arg(long)]
        json: bool,
        /// Also draw the scale values in the paper's style (PNG).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
}

/// `--participants N`: 1 to [`MAX_PARTICIPANTS`].
fn parse_participants(s: &str) -> std::result::Result<usize, String> {
    whole_number(s, 1..=MAX_PARTICIPANTS as u64, "participants").map(|n| n as usize)
}

/// `--trials N`: at least 1.
fn parse_trials(s: &str) -> std::result::Result<usize, String> {
    let n = whole_number(s, 1..=u64::MAX, "trials")?;
    usize::try_from(n).map_err(|_| format!("{n} trials is more than this machine can count"))
}

/// Runs a study subcommand.
pub fn run(command: StudyCommand) -> Result<()> {
    match command {
        StudyCommand::Plan {
            protocol,
            participants,
            seed,
            out,
        } => {
            InputFiles::new()
                .add(&protocol, "PROTOCOL")
                .check_file("--out", &out)?;
            let protocol = Protocol::read(&protocol)?;
            let trials = plan(&protocol, participants, seed);
            let mut bytes = Vec::new();
            write_plan(&mut bytes, &protocol, seed, &trials).context("formatting the plan")?;
            write_atomic(&out, &bytes)?;
            println!(
                "{}: {participants} participants x {} trials ({} pairs x {} stimuli), seed {seed}",
                out.display(),
                protocol.trials_per_participant(),
                protocol.pairs().len(),
                protocol.stimuli.len()
            );
            Ok(())
        }
        StudyCommand::Run {
            protocol,
            plan,
            participant,
            responses,
            dry_run,
            view,
            window,
            trace,
            rate,
            time_scale,
            trials,
            simulate,
            seed,
            no_keyboard,
            validate,
            size,
            blend,
            gaze,
            gaze_trace,
            out,
        } => {
            let mut inputs = InputFiles::new();
            inputs.add(&protocol, "PROTOCOL").add(&plan, "--plan");
            for (path, option) in [(&trace, "--trace"), (&gaze_trace, "--gaze-trace")] {
                if let Some(path) = path {
                    inputs.add(path, option);
                }
            }
            inputs.check_file("--responses", &responses)?;
            if let Some(out) = &out {
                inputs.check_file("--out", out)?;
            }
            inputs.check_file("the timing log", &timing_log_path(&responses))?;
            if let Some((w, h)) = size {
                vitreous_frames::setup::check_size(w, h)?;
            }
            if trace.is_some() && !(dry_run || view) {
                bail!(
                    "--trace is for --dry-run or --view (on a headset, --gaze-trace replays gaze)"
                );
            }
            let summary = run_study(&StudyRunOptions {
                protocol,
                plan,
                participant: participant.clone(),
                responses: responses.clone(),
                dry_run,
                view: view.then_some(window),
                trace,
                frame_rate_hz: rate,
                size,
                time_scale,
                max_answers: trials,
                keyboard: !no_keyboard && simulate.is_none(),
                simulate,
                seed,
                validate,
                out,
                run: RunOptions {
                    gaze,
                    gaze_trace,
                    blend,
                    size,
                    ..RunOptions::default()
                },
            })?;
            println!(
                "participant {participant}: {} answered now, {} before, {} of {} trials left; \
                 responses in {}",
                summary.answered_now,
                summary.answered_before,
                summary.remaining,
                summary.planned,
                responses.display()
            );
            Ok(())
        }
        StudyCommand::Analyze {
            responses,
            json,
            plot,
        } => {
            let analysis = vitreous_study::report::analyze_file(&responses)?;
            if let Some(path) = &plot {
                InputFiles::new()
                    .add(&responses, "RESPONSES")
                    .check_file("--plot", path)?;
                let png = super::plot::plot(&analysis)?;
                write_atomic(path, &png)?;
            }
            if json {
                let mut out = std::io::stdout().lock();
                serde_json::to_writer_pretty(&mut out, &analysis.to_json())?;
                writeln!(out)?;
            } else {
                print!("{analysis}");
            }
            Ok(())
        }
    }
}
