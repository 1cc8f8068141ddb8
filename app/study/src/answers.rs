//! Where a study's answers come from: the experimenter's keyboard (lines typed in the terminal
//! running `vitreous study run`), the controller (the run's two cycle buttons), or a simulated
//! participant whose judgments follow given scale values (rehearsals and tests).

use std::io::BufRead;
use std::sync::mpsc::{Receiver, TryRecvError};

use vitreous_trace::synth::SplitMix64;
use vitreous_trace::{Command, Cycle};

use super::distributions::normal_cdf;
use super::responses::{Answer, Choice, RATING_LIMIT, ResponseKind};

/// Parses what the experimenter typed: `1`, `f`, `former` or `first` (and `2`, `l`, `latter`,
/// `second`) for a forced choice; an integer from -3 to 3 (`+` allowed) for a rating.
pub fn parse_answer(kind: ResponseKind, text: &str) -> Result<Answer, String> {
    let t = text.trim().to_ascii_lowercase();
    match kind {
        ResponseKind::ForcedChoice => match t.as_str() {
            "1" | "f" | "former" | "first" => Ok(Answer::Choice(Choice::First)),
            "2" | "l" | "latter" | "second" => Ok(Answer::Choice(Choice::Second)),
            _ => Err(format!(
                "`{}` is not a forced choice: type 1 (the former) or 2 (the latter)",
                text.trim()
            )),
        },
        ResponseKind::Rating => match t.trim_start_matches('+').parse::<i8>() {
            Ok(v) if v.abs() <= RATING_LIMIT => Ok(Answer::Rating(v)),
            _ => Err(format!(
                "`{}` is not a rating: type an integer from -3 to 3 (positive: the first was \
                 more convincing)",
                text.trim()
            )),
        },
    }
}

/// The answer as the responses file writes it.
pub fn answer_text(answer: Answer) -> String {
    match answer {
        Answer::Choice(Choice::First) => "first".into(),
        Answer::Choice(Choice::Second) => "second".into(),
        Answer::Rating(v) => v.to_string(),
    }
}

/// A participant simulated from scale values: Thurstone's Case V for forced choices
/// (P(first) = Φ(S_first − S_second)), Scheffe's model for ratings (the difference plus unit
/// normal noise, rounded and clipped to -3..3).
#[derive(Debug, Clone)]
pub struct SimulatedObserver {
    /// Each condition's scale value.
    scale: Vec<(String, f64)>,
    /// The random numbers.
    rng: SplitMix64,
}

impl SimulatedObserver {
    /// Parses `NAME=VALUE,NAME=VALUE,...`; every condition of the study must be given.
    pub fn parse(text: &str, conditions: &[String], seed: u64) -> Result<Self, String> {
        let mut scale = Vec::new();
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| format!("`{item}`: expected NAME=VALUE"))?;
            let v: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && v.abs() <= 10.0)
                .ok_or_else(|| format!("`{item}`: the value must be a number from -10 to 10"))?;
            if !conditions.iter().any(|c| c == name.trim()) {
                return Err(format!(
                    "`{}` is not a condition of the study ({})",
                    name.trim(),
                    conditions.join(", ")
                ));
            }
            scale.push((name.trim().to_owned(), v));
        }
        if let Some(missing) = conditions
            .iter()
            .find(|c| !scale.iter().any(|(n, _)| n == *c))
        {
            return Err(format!("no scale value for condition `{missing}`"));
        }
        Ok(SimulatedObserver {
            scale,
            rng: SplitMix64(seed),
        })
    }

    fn value(&self, name: &str) -> f64 {
        self.scale
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0.0, |(_, v)| *v)
    }

    /// Judges one presentation of `first` then `second`.
    pub fn judge(&mut self, kind: ResponseKind, first: &str, second: &str) -> Answer {
        let difference = self.value(first) - self.value(second);
        match kind {
            ResponseKind::ForcedChoice => {
                if self.rng.unit() < normal_cdf(difference) {
                    Answer::Choice(Choice::First)
                } else {
                    Answer::Choice(Choice::Second)
                }
            }
            ResponseKind::Rating => {
                let limit = f64::from(RATING_LIMIT);
                let v = (difference + self.rng.gaussian())
                    .round()
                    .clamp(-limit, limit);
                Answer::Rating(v as i8)
            }
        }
    }
}

/// Lines typed on standard input, read on their own thread.
pub struct Keyboard {
    /// The lines, as typed.
    lines: Receiver<String>,
    /// Whether standard input has ended.
    closed: bool,
}

impl Keyboard {
    /// Starts reading standard input.
    pub fn stdin() -> Keyboard {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in std::io::stdin().lock().lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Keyboard {
            lines: rx,
            closed: false,
        }
    }

    /// Whether standard input has ended (nothing more can be typed).
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// The next line typed, if any.
    pub fn poll(&mut self) -> Option<String> {
        if self.closed {
            return None;
        }
        match self.lines.try_recv() {
            Ok(line) => Some(line),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.closed = true;
                None
            }
        }
    }
}

/// Answers from the controller's two cycle buttons: for a forced choice, the primary (select)
/// answers "the former" and the secondary (menu) "the latter"; for a rating, the primary steps
/// the pending rating (0, 1, 2, 3, -3, -2, -1, 0, ...) and the secondary confirms it.
#[derive(Debug, Default, Clone)]
pub struct ControllerAnswers {
    /// The rating being chosen.
    pending: i8,
}

impl ControllerAnswers {
    /// Clears the pending rating (at the start of each answer).
    pub fn reset(&mut self) {
        self.pending = 0;
    }

    /// Turns a command into an answer, or into a message about the pending rating.
    pub fn command(&mut self, kind: ResponseKind, command: Command) -> Option<Result<Answer, i8>> {
        let Command::Cycle(cycle) = command else {
            return None;
        };
        Some(match (kind, cycle) {
            (ResponseKind::ForcedChoice, Cycle::Primary) => Ok(Answer::Choice(Choice::First)),
            (ResponseKind::ForcedChoice, Cycle::Secondary) => Ok(Answer::Choice(Choice::Second)),
            (ResponseKind::Rating, Cycle::Primary) => {
                self.pending = if self.pending == RATING_LIMIT {
                    -RATING_LIMIT
                } else {
                    self.pending + 1
                };
                Err(self.pending)
            }
            (ResponseKind::Rating, Cycle::Secondary) => Ok(Answer::Rating(self.pending)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_answers_parse_by_kind() {
        let fc = ResponseKind::ForcedChoice;
        assert_eq!(parse_answer(fc, " 1 "), Ok(Answer::Choice(Choice::First)));
        assert_eq!(
            parse_answer(fc, "Latter"),
            Ok(Answer::Choice(Choice::Second))
        );
        assert!(parse_answer(fc, "3").is_err());
        let r = ResponseKind::Rating;
        assert_eq!(parse_answer(r, "+2"), Ok(Answer::Rating(2)));
        assert_eq!(parse_answer(r, "-3"), Ok(Answer::Rating(-3)));
        assert!(parse_answer(r, "4").unwrap_err().contains("-3 to 3"));
        assert!(parse_answer(r, "first").is_err());
    }

    #[test]
    fn the_controller_steps_and_confirms_a_rating() {
        let mut c = ControllerAnswers::default();
        let r = ResponseKind::Rating;
        let step = Command::Cycle(Cycle::Primary);
        let confirm = Command::Cycle(Cycle::Secondary);
        let steps: Vec<_> = (0..5).map(|_| c.command(r, step).unwrap()).collect();
        assert_eq!(steps, vec![Err(1), Err(2), Err(3), Err(-3), Err(-2)]);
        assert_eq!(c.command(r, confirm), Some(Ok(Answer::Rating(-2))));
        c.reset();
        assert_eq!(c.command(r, confirm), Some(Ok(Answer::Rating(0))));
        assert_eq!(
            c.command(ResponseKind::ForcedChoice, confirm),
            Some(Ok(Answer::Choice(Choice::Second)))
        );
        assert_eq!(c.command(r, Command::Rotate(0.1)), None);
    }

    #[test]
    fn a_simulated_observer_needs_every_condition() {
        let names = vec!["a".to_owned(), "b".to_owned()];
        assert!(SimulatedObserver::parse("a=0,b=1", &names, 1).is_ok());
        assert!(
            SimulatedObserver::parse("a=0", &names, 1)
                .unwrap_err()
                .contains("`b`")
        );
        assert!(SimulatedObserver::parse("a=0,b=1,z=2", &names, 1).is_err());
        assert!(SimulatedObserver::parse("a=0,b=nan", &names, 1).is_err());
    }
}
