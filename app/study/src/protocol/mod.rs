//! A study protocol (`config/studies/*.toml`): the conditions compared, the scenes they are
//! shown in, how each pair is presented (durations, presentation orders, gaze cues) and the
//! kind of answer. Field reference: docs/study.md.

use std::collections::BTreeSet;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use thiserror::Error;
use toml::Spanned;

use super::responses::ResponseKind;
use vitreous_scene::effects::EffectSet;

/// The longest duration any phase may have, seconds (an hour: beyond it a typo is likelier than
/// a design).
pub const MAX_PHASE_S: f64 = 3600.0;
/// The most conditions a protocol may compare (every ordered pair is a trial).
pub const MAX_CONDITIONS: usize = 12;

/// What the display shows for a condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Show {
    /// The glass with these effects.
    Effects(EffectSet),
    /// Nothing: the display emits no light (the paper's O1, where the experimenter shows a
    /// real object instead).
    Nothing,
}

/// One condition of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// Its name in plans and responses (`O2`, `c`, ...).
    pub name: String,
    /// A description for people.
    pub label: String,
    /// What the display shows.
    pub show: Show,
}

/// One scene the conditions are compared in (the paper's object x floor combinations).
#[derive(Debug, Clone, PartialEq)]
pub struct Stimulus {
    /// Its name in plans and responses.
    pub name: String,
    /// The scene file (resolved against the protocol's folder).
    pub scene: PathBuf,
}

/// Which presentation orders of each pair are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Orders {
    /// Every ordered pair: both presentation orders to every participant (Nakaya's design).
    Both,
    /// Every unordered pair once per participant, its order alternating across participants.
    Balanced,
}

/// How the gaze image (surface or refracted) is chosen while a stimulus is shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GazeCue {
    /// The eye tracker decides (the scene's `[gaze]` settings).
    Tracked,
    /// The experimenter cues the participant to look at the surface image, then the refracted
    /// image, alternating every `period_s`; vitreous switches the gaze image on each cue (the
    /// paper's section 6 procedure).
    Cued {
        /// Seconds between cues.
        period_s: f64,
    },
}

/// Durations of one trial, seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// The first stimulus.
    pub first_s: f64,
    /// The blank between the two.
    pub blank_s: f64,
    /// The second stimulus.
    pub second_s: f64,
    /// From the end of the second stimulus to the next trial, answering included.
    pub interval_s: f64,
}

impl Timing {
    /// The same durations multiplied by `factor`.
    pub fn scaled(self, factor: f64) -> Timing {
        Timing {
            first_s: self.first_s * factor,
            blank_s: self.blank_s * factor,
            second_s: self.second_s * factor,
            interval_s: self.interval_s * factor,
        }
    }
}

/// A checked protocol.
#[derive(Debug, Clone, PartialEq)]
pub struct Protocol {
    /// The file it was read from.
    pub path: PathBuf,
    /// Short name (`visual-effects`).
    pub name: String,
    /// Title for people.
    pub title: String,
    /// The question the participant answers after each pair.
    pub question: String,
    /// Forced choice or rating.
    pub response: ResponseKind,
    /// Which presentation orders are shown.
    pub orders: Orders,
    /// How the gaze image is chosen.
    pub gaze: GazeCue,
    /// Trial durations.
    pub timing: Timing,
    /// The conditions, in file order.
    pub conditions: Vec<Condition>,
    /// The scenes, in file order.
    pub stimuli: Vec<Stimulus>,
}

impl Protocol {
    /// Index of the condition named `name`.
    pub fn condition_index(&self, name: &str) -> Option<usize> {
        self.conditions.iter().position(|c| c.name == name)
    }

    /// Index of the stimulus named `name`.
    pub fn stimulus_index(&self, name: &str) -> Option<usize> {
        self.stimuli.iter().position(|s| s.name == name)
    }

    /// The pairs each participant sees in each stimulus, as condition indices in presentation
    /// order for [`Orders::Both`], or as (lower, higher) for [`Orders::Balanced`].
    pub fn pairs(&self) -> Vec<(usize, usize)> {
        let k = self.conditions.len();
        let mut out = Vec::new();
        for i in 0..k {
            for j in 0..k {
                let wanted = match self.orders {
                    Orders::Both => i != j,
                    Orders::Balanced => i < j,
                };
                if wanted {
                    out.push((i, j));
                }
            }
        }
        out
    }

    /// Trials per participant.
    pub fn trials_per_participant(&self) -> usize {
        self.pairs().len() * self.stimuli.len()
    }

    /// Reads and checks a protocol file.
    pub fn read(path: &Path) -> Result<Protocol, ProtocolError> {
        let text = std::fs::read_to_string(path).map_err(|source| ProtocolError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Protocol::parse(path, &text)
    }

    /// Parses and checks protocol text; `path` names it in messages and anchors relative scene
    /// paths.
    pub fn parse(path: &Path, text: &str) -> Result<Protocol, ProtocolError> {
        let file: File = toml::from_str(text).map_err(|e| ProtocolError::Syntax {
            path: path.to_path_buf(),
            line: e.span().map_or(0, |s| line_of(text, s.start)),
            message: e.message().to_owned(),
        })?;
        let bad = |span: Range<usize>, field: &str, message: String| ProtocolError::Field {
            path: path.to_path_buf(),
            line: line_of(text, span.start),
            field: field.to_owned(),
            message,
        };
        let timing = Timing {
            first_s: duration(&file.timing.first_s, "timing.first_s", &bad)?,
            blank_s: duration(&file.timing.blank_s, "timing.blank_s", &bad)?,
            second_s: duration(&file.timing.second_s, "timing.second_s", &bad)?,
            interval_s: duration(&file.timing.interval_s, "timing.interval_s", &bad)?,
        };
        for (field, value) in [
            ("timing.first_s", &file.timing.first_s),
            ("timing.second_s", &file.timing.second_s),
        ] {
            if *value.get_ref() == 0.0 {
                return Err(bad(
                    value.span(),
                    field,
                    "a stimulus must be shown: > 0 s".into(),
                ));
            }
        }
        let gaze = match (file.study.gaze.get_ref().as_str(), &file.study.cue_period_s) {
            ("tracked", None) => GazeCue::Tracked,
            ("tracked", Some(p)) => {
                return Err(bad(
                    p.span(),
                    "study.cue_period_s",
                    "only with gaze = \"cued\"".into(),
                ));
            }
            ("cued", period) => {
                let period_s = match period {
                    Some(p) => duration(p, "study.cue_period_s", &bad)?,
                    None => {
                        return Err(bad(
                            file.study.gaze.span(),
                            "study.cue_period_s",
                            "gaze = \"cued\" needs cue_period_s (seconds between cues)".into(),
                        ));
                    }
                };
                if period_s == 0.0 {
                    return Err(bad(
                        file.study.gaze.span(),
                        "study.cue_period_s",
                        "must be > 0 s".into(),
                    ));
                }
                GazeCue::Cued { period_s }
            }
            (other, _) => {
                return Err(bad(
                    file.study.gaze.span(),
                    "study.gaze",
                    format!("`{other}`: expected \"tracked\" or \"cued\""),
                ));
            }
        };
        let response = match file.study.response.get_ref().as_str() {
            "forced-choice" => ResponseKind::ForcedChoice,
            "rating" => ResponseKind::Rating,
            other => {
                return Err(bad(
                    file.study.response.span(),
                    "study.response",
                    format!("`{other}`: expected \"forced-choice\" or \"rating\""),
                ));
            }
        };
        let mut names = BTreeSet::new();
        let mut conditions = Vec::new();
        for (i, c) in file.condition.iter().enumerate() {
            let field = |f: &str| format!("condition[{i}].{f}");
            check_name(&c.name, &field("name"), &bad)?;
            if !names.insert(c.name.get_ref().clone()) {
                return Err(bad(
                    c.name.span(),
                    &field("name"),
                    format!("`{}` names two conditions", c.name.get_ref()),
                ));
            }
            let show = if c.effects.get_ref() == "nothing" {
                Show::Nothing
            } else {
                let set = EffectSet::parse(c.effects.get_ref())
                    .map_err(|e| bad(c.effects.span(), &field("effects"), e.to_string()))?;
                set.ensure_implemented()
                    .map_err(|e| bad(c.effects.span(), &field("effects"), e.to_string()))?;
                Show::Effects(set)
            };
            conditions.push(Condition {
                name: c.name.get_ref().clone(),
                label: c.label.clone().unwrap_or_default(),
                show,
            });
        }
        if conditions.len() < 2 || conditions.len() > MAX_CONDITIONS {
            return Err(ProtocolError::Count {
                path: path.to_path_buf(),
                what: "[[condition]]",
                found: conditions.len(),
                expected: "2 to 12",
            });
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let mut stimulus_names = BTreeSet::new();
        let mut stimuli = Vec::new();
        for (i, s) in file.stimulus.iter().enumerate() {
            let field = |f: &str| format!("stimulus[{i}].{f}");
            check_name(&s.name, &field("name"), &bad)?;
            if !stimulus_names.insert(s.name.get_ref().clone()) {
                return Err(bad(
                    s.name.span(),
                    &field("name"),
                    format!("`{}` names two stimuli", s.name.get_ref()),
                ));
            }
            let scene = base.join(s.scene.get_ref());
            if !scene.is_file() {
                return Err(bad(
                    s.scene.span(),
                    &field("scene"),
                    format!("no scene file at {}", scene.display()),
                ));
            }
            stimuli.push(Stimulus {
                name: s.name.get_ref().clone(),
                scene,
            });
        }
        if stimuli.is_empty() {
            return Err(ProtocolError::Count {
                path: path.to_path_buf(),
                what: "[[stimulus]]",
                found: 0,
                expected: "at least 1",
            });
        }
        Ok(Protocol {
            path: path.to_path_buf(),
            name: file.study.name,
            title: file.study.title.unwrap_or_default(),
            question: file.study.question,
            response,
            orders: file.study.orders,
            gaze,
            timing,
            conditions,
            stimuli,
        })
    }
}

/// A duration field: finite, >= 0, at most [`MAX_PHASE_S`].
fn duration(
    value: &Spanned<f64>,
    field: &str,
    bad: &impl Fn(Range<usize>, &str, String) -> ProtocolError,
) -> Result<f64, ProtocolError> {
    let v = *value.get_ref();
    if v.is_finite() && (0.0..=MAX_PHASE_S).contains(&v) {
        Ok(v)
    } else {
        Err(bad(
            value.span(),
            field,
            format!("{v}: expected seconds from 0 to {MAX_PHASE_S}"),
        ))
    }
}

/// A name usable in CSV files: letters, digits, `-`, `_`, `.`, `+`; not empty.
fn check_name(
    name: &Spanned<String>,
    field: &str,
    bad: &impl Fn(Range<usize>, &str, String) -> ProtocolError,
) -> Result<(), ProtocolError> {
    let n = name.get_ref();
    if n.is_empty()
        || !n
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.+".contains(c))
    {
        return Err(bad(
            name.span(),
            field,
            format!("`{n}`: use letters, digits and - _ . + only"),
        ));
    }
    Ok(())
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> u64 {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count() as u64
        + 1
}

/// Errors reading a protocol.
#[derive(Debug, Error)]
pub enum ProtocolError {
    /// The file could not be read.
    #[error("reading the study protocol {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Not TOML, an unknown key, a missing key or a value of the wrong type.
    #[error("{}:{line}: {message}", path.display())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line (0: unknown).
        line: u64,
        /// What the TOML reader said.
        message: String,
    },
    /// A value out of its range.
    #[error("{}:{line}: {field}: {message}", path.display())]
    Field {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The field, e.g. `condition[2].effects`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Too few or too many conditions or stimuli.
    #[error("{}: {found} {what} tables; expected {expected}", path.display())]
    Count {
        /// The file.
        path: PathBuf,
        /// Which table.
        what: &'static str,
        /// How many there are.
        found: usize,
        /// How many there may be.
        expected: &'static str,
    },
}

/// The file as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    /// `[study]`.
    study: StudyTable,
    /// `[timing]`.
    timing: TimingTable,
    /// `[[condition]]`.
    #[serde(default)]
    condition: Vec<ConditionTable>,
    /// `[[stimulus]]`.
    #[serde(default)]
    stimulus: Vec<StimulusTable>,
}

/// `[study]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyTable {
    /// Short name.
    name: String,
    /// Title.
    title: Option<String>,
    /// The question asked after each pair.
    question: String,
    /// `forced-choice` or `rating`.
    response: Spanned<String>,
    /// `both` or `balanced`.
    orders: Orders,
    /// `tracked` or `cued`.
    gaze: Spanned<String>,
    /// Seconds between gaze cues.
    cue_period_s: Option<Spanned<f64>>,
}

/// `[timing]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimingTable {
    /// First stimulus.
    first_s: Spanned<f64>,
    /// Blank.
    blank_s: Spanned<f64>,
    /// Second stimulus.
    second_s: Spanned<f64>,
    /// Interval after the second stimulus.
    interval_s: Spanned<f64>,
}

/// `[[condition]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConditionTable {
    /// Name.
    name: Spanned<String>,
    /// Description.
    label: Option<String>,
    /// An effect set (`O5`, `c`, `defocus,disparity`) or `nothing`.
    effects: Spanned<String>,
}

/// `[[stimulus]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StimulusTable {
    /// Name.
    name: Spanned<String>,
    /// Scene file, relative to the protocol.
    scene: Spanned<String>,
}

#[cfg(test)]
mod tests;
