//! One participant's trials in one scene, on any backend: [`StudyDirector`] says, frame by
//! frame, which condition is shown (or nothing) and which gaze image is cued, takes the
//! answers, appends each to the responses file at once (flushed and synced, so a crash loses
//! nothing) and logs every phase change with its display time to the timing log.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use vitreous_trace::Command;
use vitreous_trace::session_event::{SessionEvent, TrackingLoss};

use super::answers::{ControllerAnswers, Keyboard, SimulatedObserver, answer_text, parse_answer};
use super::plan::PlannedTrial;
use super::protocol::{GazeCue, Protocol, Timing};
use super::responses::{Answer, ResponseKind};
use super::schedule::{Phase, TrialClock};
use vitreous_gaze::GazeOverride;

/// The columns `vitreous study run` writes to a responses file.
pub const RESPONSE_COLUMNS: &str = "participant,trial,first,second,response,stimulus";
/// The columns of the timing log.
pub const TIMING_COLUMNS: &str =
    "participant,trial,stimulus,event,detail,frame,display_time_s,trial_time_s";

/// A trial already answered in the responses file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Answered {
    /// Line in the responses file.
    pub line: u64,
    /// Trial number.
    pub trial: u64,
    /// Stimulus.
    pub stimulus: String,
    /// Condition shown first.
    pub first: String,
    /// Condition shown second.
    pub second: String,
}

/// The responses file, opened for appending.
pub struct ResponsesFile {
    /// Where it is.
    path: PathBuf,
    /// The open file.
    file: File,
}

impl ResponsesFile {
    /// Opens (or creates, with its header) the responses file and returns the trials of
    /// `participant` already in it. A last line cut off by a crash (no newline) is removed, with
    /// a warning: that trial is asked again.
    pub fn open(path: &Path, participant: &str) -> Result<(ResponsesFile, Vec<Answered>)> {
        let mut answered = Vec::new();
        if path.exists() {
            let mut text = std::fs::read_to_string(path)
                .with_context(|| format!("reading the responses file {}", path.display()))?;
            if !text.is_empty() && !text.ends_with('\n') {
                let keep = text.rfind('\n').map_or(0, |i| i + 1);
                tracing::warn!(
                    "{}: the last line (`{}`) was cut off; removing it: that trial is asked again",
                    path.display(),
                    &text[keep..]
                );
                text.truncate(keep);
                let file = OpenOptions::new()
                    .write(true)
                    .open(path)
                    .with_context(|| format!("opening {}", path.display()))?;
                file.set_len(keep as u64)
                    .with_context(|| format!("truncating {}", path.display()))?;
            }
            answered = read_answered(path, &text, participant)?;
        }
        let fresh = !path.exists() || std::fs::metadata(path).map(|m| m.len() == 0)?;
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("opening the responses file {}", path.display()))?;
        if fresh {
            writeln!(file, "{RESPONSE_COLUMNS}")
                .and_then(|()| file.sync_data())
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok((
            ResponsesFile {
                path: path.to_path_buf(),
                file,
            },
            answered,
        ))
    }

    /// Appends one answer and makes sure it is on disk before returning.
    pub fn append(&mut self, trial: &PlannedTrial, answer: Answer) -> Result<()> {
        let line = format!(
            "{},{},{},{},{},{}\n",
            trial.participant,
            trial.trial,
            trial.first,
            trial.second,
            answer_text(answer),
            trial.stimulus
        );
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.sync_data())
            .with_context(|| format!("writing the answer to {}", self.path.display()))
    }
}

/// The answered trials of `participant` in a responses file written by `study run`.
fn read_answered(path: &Path, text: &str, participant: &str) -> Result<Vec<Answered>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.starts_with('#'));
    match lines.next() {
        None => return Ok(Vec::new()),
        Some((_, header)) if header.trim() == RESPONSE_COLUMNS => {}
        Some((i, header)) => bail!(
            "{}:{}: header `{header}` is not `{RESPONSE_COLUMNS}`: this file was not written by \
             `vitreous study run`; give a new responses file",
            path.display(),
            i + 1
        ),
    }
    let mut out = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let line_no = i as u64 + 1;
        if fields.len() != 6 {
            bail!(
                "{}:{line_no}: {} fields; expected 6 ({RESPONSE_COLUMNS})",
                path.display(),
                fields.len()
            );
        }
        if fields[0] != participant {
            continue;
        }
        let trial = fields[1]
            .parse()
            .with_context(|| format!("{}:{line_no}: trial `{}`", path.display(), fields[1]))?;
        out.push(Answered {
            line: line_no,
            trial,
            stimulus: fields[5].to_owned(),
            first: fields[2].to_owned(),
            second: fields[3].to_owned(),
        });
    }
    Ok(out)
}

/// The trials of the plan still to run: `planned` (one participant's, in order) minus those in
/// `answered`, which must match the plan trial by trial.
pub fn remaining_trials(
    responses: &Path,
    planned: &[PlannedTrial],
    answered: &[Answered],
) -> Result<Vec<PlannedTrial>> {
    for a in answered {
        let Some(p) = planned.iter().find(|p| p.trial == a.trial) else {
            bail!(
                "{}:{}: trial {} is not in the plan for this participant: wrong plan or \
                 participant?",
                responses.display(),
                a.line,
                a.trial
            );
        };
        if (&p.stimulus, &p.first, &p.second) != (&a.stimulus, &a.first, &a.second) {
            bail!(
                "{}:{}: trial {} was {} then {} in {}, but the plan says {} then {} in {}: wrong \
                 plan or participant?",
                responses.display(),
                a.line,
                a.trial,
                a.first,
                a.second,
                a.stimulus,
                p.first,
                p.second,
                p.stimulus
            );
        }
        if answered.iter().filter(|b| b.trial == a.trial).count() > 1 {
            bail!(
                "{}:{}: trial {} is answered twice",
                responses.display(),
                a.line,
                a.trial
            );
        }
    }
    Ok(planned
        .iter()
        .filter(|p| !answered.iter().any(|a| a.trial == p.trial))
        .cloned()
        .collect())
}

/// The timing log: every phase change of every trial with its display time.
pub struct TimingLog {
    /// Where it is.
    path: PathBuf,
    /// The open file.
    out: BufWriter<File>,
}

impl TimingLog {
    /// Opens (or creates, with its header) the log for appending.
    pub fn open(path: &Path) -> Result<TimingLog> {
        let fresh = !path.exists();
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("opening the timing log {}", path.display()))?;
        let mut log = TimingLog {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
        };
        if fresh {
            log.write_line(TIMING_COLUMNS)?;
        }
        Ok(log)
    }

    fn write_line(&mut self, line: &str) -> Result<()> {
        writeln!(self.out, "{line}")
            .and_then(|()| self.out.flush())
            .with_context(|| format!("writing {}", self.path.display()))
    }
}

/// What a frame shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shown {
    /// Index of the protocol condition shown; `None`: nothing is shown.
    pub condition: Option<usize>,
    /// The gaze image cued.
    pub gaze: GazeOverride,
}

/// Where answers come from.
pub struct AnswerSources {
    /// Lines typed by the experimenter.
    pub keyboard: Option<Keyboard>,
    /// A simulated participant, answering as soon as each answer is due.
    pub simulated: Option<SimulatedObserver>,
    /// Whether the controller's buttons can answer (on the OpenXR runtime).
    pub controller: bool,
}

/// The trial under way.
struct Current {
    /// The planned trial.
    trial: PlannedTrial,
    /// Its clock.
    clock: TrialClock,
    /// The phase of the last frame.
    phase: Option<Phase>,
    /// The gaze image cued on the last frame.
    gaze: GazeOverride,
}

/// Runs one participant's trials in one scene; see the module documentation.
pub struct StudyDirector {
    /// Condition names, in protocol order.
    conditions: Vec<String>,
    /// Forced choice or rating.
    kind: ResponseKind,
    /// Gaze cues.
    cue: GazeCue,
    /// Durations (scaled).
    timing: Timing,
    /// The trials still to run, in order.
    trials: std::collections::VecDeque<PlannedTrial>,
    /// The trial under way.
    current: Option<Current>,
    /// Stop after this many answers in this session.
    max_answers: Option<usize>,
    /// Answers recorded in this session.
    answers: usize,
    /// Where answers come from.
    sources: AnswerSources,
    /// Controller button state.
    controller: ControllerAnswers,
    /// Commands received since the last frame.
    commands: Vec<Command>,
    /// Lines typed and not yet used: a line typed before an answer is due answers the next
    /// trial (type-ahead, as a terminal keeps keystrokes).
    typed: std::collections::VecDeque<String>,
    /// The responses file.
    responses: ResponsesFile,
    /// The timing log.
    log: TimingLog,
    /// Display time of the frame before, seconds.
    last_time_s: Option<f64>,
    /// Why the wearer may have missed part of the stimulus since the frame before (a menu,
    /// the headset taken off, a lost session), if anything.
    interruption: Option<String>,
    /// Trials shown again for gaps between frames alone, and how often.
    gap_restarts: std::collections::HashMap<u64, u32>,
}

/// How often one trial is shown again for gaps between frames alone: a display that keeps
/// stalling for longer than [`MAX_STIMULUS_GAP_S`] would otherwise never let the trial end.
pub const MAX_GAP_RESTARTS: u32 = 3;

/// The longest the display may show nothing during a trial's stimuli before the trial is shown
/// again from its start, seconds: a frame or a few late is a glitch, more is a gap the wearer
/// sees (a headset taken off, frames the runtime did not want, a lost session).
pub const MAX_STIMULUS_GAP_S: f64 = 0.3;

impl StudyDirector {
    /// A director for `trials` (one participant, one stimulus, unanswered, in order).
    pub fn new(
        protocol: &Protocol,
        time_scale: f64,
        trials: Vec<PlannedTrial>,
        max_answers: Option<usize>,
        sources: AnswerSources,
        responses: ResponsesFile,
        log: TimingLog,
    ) -> StudyDirector {
        StudyDirector {
            conditions: protocol.conditions.iter().map(|c| c.name.clone()).collect(),
            kind: protocol.response,
            cue: match protocol.gaze {
                GazeCue::Cued { period_s } => GazeCue::Cued {
                    period_s: period_s * time_scale,
                },
                GazeCue::Tracked => GazeCue::Tracked,
            },
            timing: protocol.timing.scaled(time_scale),
            trials: trials.into(),
            current: None,
            max_answers,
            answers: 0,
            sources,
            controller: ControllerAnswers::default(),
            commands: Vec::new(),
            typed: Default::default(),
            responses,
            log,
            last_time_s: None,
            interruption: None,
            gap_restarts: Default::default(),
        }
    }

    /// What happened to the session since the frame before: a menu over the display, the
    /// headset taken off, a lost session or lost head orientation keep the wearer from seeing
    /// the stimulus, so a trial that was showing its stimuli starts again (at the next frame).
    pub fn session_events(&mut self, events: &[SessionEvent]) {
        for event in events {
            let interrupts = matches!(
                event,
                SessionEvent::Unfocused
                    | SessionEvent::Focused
                    | SessionEvent::Ended
                    | SessionEvent::Resumed
                    | SessionEvent::Lost(_)
                    | SessionEvent::Reconnected { .. }
                    | SessionEvent::TrackingLost(TrackingLoss::Orientation)
            );
            if interrupts {
                self.interruption
                    .get_or_insert_with(|| event.fields().0.to_owned());
            }
        }
    }

    /// Starts the trial under way again from its first stimulus when the wearer may have missed
    /// part of its stimuli since the frame before: an interruption the session said, or a gap
    /// of more than [`MAX_STIMULUS_GAP_S`] between frames. Its answer is still asked once.
    fn restart_if_interrupted(&mut self, frame: u64, time_s: f64) -> Result<()> {
        let gap_s = self.last_time_s.map_or(0.0, |t| time_s - t);
        self.last_time_s = Some(time_s);
        let showing = self.current.as_ref().and_then(|c| {
            matches!(c.phase, Some(Phase::First | Phase::Blank | Phase::Second))
                .then_some(c.trial.trial)
        });
        let said = self.interruption.take();
        let Some(trial) = showing else {
            return Ok(());
        };
        let why = match said {
            Some(why) => why,
            None if gap_s > MAX_STIMULUS_GAP_S => {
                let n = self.gap_restarts.entry(trial).or_default();
                if *n >= MAX_GAP_RESTARTS {
                    tracing::warn!(
                        "trial {trial}: the display stalled for {gap_s:.2} s again; the trial \
                         goes on (shown again {MAX_GAP_RESTARTS} times for stalls already)"
                    );
                    return Ok(());
                }
                *n += 1;
                format!("gap {gap_s:.2} s")
            }
            None => return Ok(()),
        };
        let cur = self.current.as_ref().expect("a trial is showing");
        tracing::warn!(
            "trial {}: interrupted during its stimuli ({why}): shown again from the start",
            cur.trial.trial
        );
        self.event(frame, time_s, "interrupted", &why)?;
        let cur = self.current.take().expect("a trial is showing");
        self.trials.push_front(cur.trial);
        Ok(())
    }

    /// Whether every trial is answered (or the session's answer limit is reached).
    pub fn done(&self) -> bool {
        let limit = self.max_answers.is_some_and(|m| self.answers >= m);
        limit || (self.trials.is_empty() && self.current.is_none())
    }

    /// Answers recorded in this session.
    pub fn answers(&self) -> usize {
        self.answers
    }

    /// Gives back the responses file and the answer sources (for the next block).
    pub fn into_parts(self) -> (ResponsesFile, AnswerSources) {
        (self.responses, self.sources)
    }

    /// A controller command, handled on the next frame.
    pub fn command(&mut self, command: Command) {
        self.commands.push(command);
    }

    /// What frame `frame`, displayed at `time_s`, shows; records answers that came in.
    pub fn frame(&mut self, frame: u64, time_s: f64) -> Result<Shown> {
        self.restart_if_interrupted(frame, time_s)?;
        let commands = std::mem::take(&mut self.commands);
        if let Some(k) = &mut self.sources.keyboard {
            while let Some(line) = k.poll() {
                self.typed.push_back(line);
            }
        }
        loop {
            if self.done() {
                return Ok(Shown {
                    condition: None,
                    gaze: GazeOverride::Auto,
                });
            }
            if self.current.is_none() {
                let trial = self.trials.pop_front().expect("not done: a trial remains");
                tracing::info!(
                    "trial {} ({}): {} then {}",
                    trial.trial,
                    trial.stimulus,
                    trial.first,
                    trial.second
                );
                self.current = Some(Current {
                    trial,
                    clock: TrialClock::new(self.timing, time_s),
                    phase: None,
                    gaze: GazeOverride::Auto,
                });
            }
            let phase = self
                .current
                .as_ref()
                .expect("set above")
                .clock
                .phase(time_s);
            self.enter(phase, frame, time_s)?;
            match phase {
                Phase::Answer => {
                    let typed_out = self.typed.is_empty()
                        && self.sources.keyboard.as_ref().is_none_or(Keyboard::closed);
                    if typed_out && self.sources.simulated.is_none() && !self.sources.controller {
                        bail!(
                            "trial {}: an answer is due but nothing can give it: standard input \
                             is closed (or --no-keyboard) and there is no controller; type the \
                             answers, or pass --simulate",
                            self.current.as_ref().expect("trial under way").trial.trial
                        );
                    }
                    if let Some(answer) = self.take_answer(&commands) {
                        let cur = self.current.as_mut().expect("trial under way");
                        self.responses.append(&cur.trial, answer)?;
                        cur.clock.answer(time_s);
                        self.answers += 1;
                        let text = answer_text(answer);
                        tracing::info!("trial {}: answer {text} recorded", cur.trial.trial);
                        self.event(frame, time_s, "answered", &text)?;
                        continue;
                    }
                }
                Phase::Done => {
                    self.current = None;
                    continue;
                }
                _ => {}
            }
            let cur = self.current.as_mut().expect("trial under way");
            let condition = match phase {
                Phase::First => Some(&cur.trial.first),
                Phase::Second => Some(&cur.trial.second),
                _ => None,
            }
            .and_then(|name| self.conditions.iter().position(|c| c == name));
            let gaze = cur.clock.gaze(self.cue, time_s);
            if phase.shows() && gaze != cur.gaze && gaze != GazeOverride::Auto {
                cur.gaze = gaze;
                tracing::info!("cue: look at the {gaze} image");
                self.event(frame, time_s, "cue", &gaze.to_string())?;
            }
            return Ok(Shown { condition, gaze });
        }
    }

    /// Logs `phase` if it is new for the current trial, and prompts for the answer.
    fn enter(&mut self, phase: Phase, frame: u64, time_s: f64) -> Result<()> {
        let cur = self.current.as_mut().expect("trial under way");
        if cur.phase == Some(phase) {
            return Ok(());
        }
        cur.phase = Some(phase);
        cur.gaze = GazeOverride::Auto;
        let detail = match phase {
            Phase::First => cur.trial.first.clone(),
            Phase::Second => cur.trial.second.clone(),
            _ => String::new(),
        };
        if phase == Phase::Answer {
            self.controller.reset();
            let how = match self.kind {
                ResponseKind::ForcedChoice => "1 = the former, 2 = the latter",
                ResponseKind::Rating => "-3..3, positive: the first was more convincing",
            };
            tracing::info!("trial {}: answer now ({how})", cur.trial.trial);
        }
        self.event(frame, time_s, phase.name(), &detail)
    }

    /// The answer given, from the simulated participant, the controller (since the last
    /// frame) or the keyboard (the oldest line not used yet), in that order.
    fn take_answer(&mut self, commands: &[Command]) -> Option<Answer> {
        let cur = self.current.as_ref()?;
        if let Some(sim) = &mut self.sources.simulated {
            return Some(sim.judge(self.kind, &cur.trial.first, &cur.trial.second));
        }
        for &c in commands {
            match self.controller.command(self.kind, c) {
                Some(Ok(answer)) => return Some(answer),
                Some(Err(pending)) => tracing::info!("rating {pending:+} (menu button confirms)"),
                None => {}
            }
        }
        while let Some(line) = self.typed.pop_front() {
            match parse_answer(self.kind, &line) {
                Ok(answer) => return Some(answer),
                Err(message) => tracing::warn!("{message}"),
            }
        }
        None
    }

    fn event(&mut self, frame: u64, time_s: f64, event: &str, detail: &str) -> Result<()> {
        let cur = self.current.as_ref().expect("trial under way");
        let line = format!(
            "{},{},{},{event},{detail},{frame},{time_s:.6},{:.6}",
            cur.trial.participant,
            cur.trial.trial,
            cur.trial.stimulus,
            cur.clock.elapsed_s(time_s)
        );
        self.log.write_line(&line)
    }
}

#[cfg(test)]
mod tests;
