//! The protocol's clock for one trial: first stimulus, blank, second stimulus, then a blank
//! display until the answer is in and the interval since the second stimulus has passed.
//!
//! Times are display times (the backend's predicted display time of each frame), so a stimulus
//! starts on the first frame that will be *seen* at or after its start, and each phase lasts
//! from that frame to the first frame displayed at or after its end: on a 60 Hz display a 3 s
//! stimulus is shown for 3 s rounded up to whole frames.

use super::protocol::{GazeCue, Timing};
use vitreous_gaze::GazeOverride;

/// How far past a boundary a display time counts as past it, seconds.
const PHASE_EPSILON_S: f64 = 1e-6;

/// Where a trial stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// The first condition is shown.
    First,
    /// Nothing is shown between the two.
    Blank,
    /// The second condition is shown.
    Second,
    /// Nothing is shown; waiting for the answer.
    Answer,
    /// Answered; nothing is shown until the interval has passed.
    Rest,
    /// The trial is over.
    Done,
}

impl Phase {
    /// The name written to the trial log.
    pub fn name(self) -> &'static str {
        match self {
            Phase::First => "first",
            Phase::Blank => "blank",
            Phase::Second => "second",
            Phase::Answer => "answer",
            Phase::Rest => "rest",
            Phase::Done => "done",
        }
    }

    /// Whether a condition is shown.
    pub fn shows(self) -> bool {
        matches!(self, Phase::First | Phase::Second)
    }
}

/// One trial's clock.
#[derive(Debug, Clone, Copy)]
pub struct TrialClock {
    /// Durations (already scaled).
    timing: Timing,
    /// Display time the trial started at, seconds.
    start_s: f64,
    /// Display time of the frame on which the answer arrived.
    answered_s: Option<f64>,
}

impl TrialClock {
    /// A trial starting at display time `start_s`.
    pub fn new(timing: Timing, start_s: f64) -> TrialClock {
        TrialClock {
            timing,
            start_s,
            answered_s: None,
        }
    }

    /// Display time the trial started at.
    pub fn start_s(&self) -> f64 {
        self.start_s
    }

    /// Seconds since the trial started.
    pub fn elapsed_s(&self, time_s: f64) -> f64 {
        time_s - self.start_s
    }

    /// Seconds since the trial started, a microsecond late: display times are whole
    /// nanoseconds, and a frame displayed exactly at a phase's end must not stay in the phase
    /// by a rounding error of the subtraction.
    fn elapsed_for_phase_s(&self, time_s: f64) -> f64 {
        self.elapsed_s(time_s) + PHASE_EPSILON_S
    }

    /// Marks the trial answered at display time `time_s`.
    pub fn answer(&mut self, time_s: f64) {
        self.answered_s.get_or_insert(time_s);
    }

    /// Whether the answer is in.
    pub fn answered(&self) -> bool {
        self.answered_s.is_some()
    }

    /// The phase at display time `time_s`.
    pub fn phase(&self, time_s: f64) -> Phase {
        let t = self.elapsed_for_phase_s(time_s);
        let Timing {
            first_s,
            blank_s,
            second_s,
            interval_s,
        } = self.timing;
        let second_end = first_s + blank_s + second_s;
        if t < first_s {
            Phase::First
        } else if t < first_s + blank_s {
            Phase::Blank
        } else if t < second_end {
            Phase::Second
        } else if !self.answered() {
            Phase::Answer
        } else if t < second_end + interval_s {
            Phase::Rest
        } else {
            Phase::Done
        }
    }

    /// The gaze image cued at display time `time_s` while a stimulus is shown: with cues, the
    /// surface image first, then the refracted image, alternating every period from the start
    /// of each stimulus; without cues, the eye tracker's choice.
    pub fn gaze(&self, cue: GazeCue, time_s: f64) -> GazeOverride {
        let GazeCue::Cued { period_s } = cue else {
            return GazeOverride::Auto;
        };
        let t = self.elapsed_for_phase_s(time_s);
        let since = match self.phase(time_s) {
            Phase::First => t,
            Phase::Second => t - self.timing.first_s - self.timing.blank_s,
            _ => return GazeOverride::Auto,
        };
        if (since / period_s).floor() as i64 % 2 == 0 {
            GazeOverride::Surface
        } else {
            GazeOverride::Refracted
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPER: Timing = Timing {
        first_s: 3.0,
        blank_s: 2.0,
        second_s: 3.0,
        interval_s: 30.0,
    };

    #[test]
    fn phases_follow_the_protocol_clock() {
        let mut c = TrialClock::new(PAPER, 100.0);
        let at = |c: &TrialClock, t: f64| c.phase(100.0 + t);
        assert_eq!(at(&c, 0.0), Phase::First);
        assert_eq!(at(&c, 2.999), Phase::First);
        assert_eq!(at(&c, 3.0), Phase::Blank);
        assert_eq!(at(&c, 5.0), Phase::Second);
        assert_eq!(at(&c, 7.999), Phase::Second);
        assert_eq!(at(&c, 8.0), Phase::Answer);
        assert_eq!(at(&c, 1000.0), Phase::Answer, "waits for the answer");
        c.answer(110.0);
        assert_eq!(at(&c, 10.0), Phase::Rest);
        assert_eq!(at(&c, 37.999), Phase::Rest);
        assert_eq!(
            at(&c, 38.0),
            Phase::Done,
            "interval counted from the second's end"
        );
        let mut late = TrialClock::new(PAPER, 0.0);
        late.answer(50.0);
        assert_eq!(
            late.phase(50.0),
            Phase::Done,
            "a late answer ends the trial at once"
        );
    }

    #[test]
    fn cues_alternate_from_each_stimulus_start() {
        let t = Timing {
            first_s: 20.0,
            blank_s: 10.0,
            second_s: 20.0,
            interval_s: 30.0,
        };
        let c = TrialClock::new(t, 0.0);
        let cue = GazeCue::Cued { period_s: 5.0 };
        assert_eq!(c.gaze(cue, 0.0), GazeOverride::Surface);
        assert_eq!(c.gaze(cue, 5.0), GazeOverride::Refracted);
        assert_eq!(c.gaze(cue, 19.0), GazeOverride::Refracted);
        assert_eq!(c.gaze(cue, 25.0), GazeOverride::Auto, "blank");
        assert_eq!(
            c.gaze(cue, 30.0),
            GazeOverride::Surface,
            "second starts on surface"
        );
        assert_eq!(c.gaze(cue, 36.0), GazeOverride::Refracted);
        assert_eq!(c.gaze(GazeCue::Tracked, 1.0), GazeOverride::Auto);
    }
}
