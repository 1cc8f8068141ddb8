//! The eye tracker's faults: dropouts (`gaze-dropout`) and a clock ahead of the runtime's or
//! behind it (`gaze-clock`), each over a span of display time from the frame it starts at.

use super::super::schedule::Dropout;

/// What the eye tracker does wrong, by runtime time.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct GazeFaults {
    /// Dropouts: from, until (runtime time), how.
    dropouts: Vec<(i64, i64, Dropout)>,
    /// Clocks off: from, until (runtime time), how many nanoseconds ahead (behind: negative).
    leads: Vec<(i64, i64, i64)>,
}

impl GazeFaults {
    /// A dropout of `seconds` from `from_ns`.
    pub(super) fn drop_out(&mut self, from_ns: i64, seconds: f64, kind: Dropout) {
        self.dropouts
            .push((from_ns, from_ns + (seconds * 1e9) as i64, kind));
    }

    /// The tracker's clock `lead_ms` ahead (behind: negative) for `seconds` from `from_ns`.
    pub(super) fn run_ahead(&mut self, from_ns: i64, seconds: f64, lead_ms: i64) {
        let lead_ns = lead_ms * 1_000_000;
        self.leads
            .push((from_ns, from_ns + (seconds * 1e9) as i64, lead_ns));
    }

    /// The dropout at runtime time `time_ns`, and when it started, if any (the newest).
    pub(super) fn dropout_at(&self, time_ns: i64) -> Option<(Dropout, i64)> {
        self.dropouts
            .iter()
            .rev()
            .find(|(from, until, _)| (*from..*until).contains(&time_ns))
            .map(|(from, _, kind)| (*kind, *from))
    }

    /// How far ahead the tracker's clock is at runtime time `time_ns`, nanoseconds (negative:
    /// behind; 0 when it keeps the runtime's time).
    pub(super) fn lead_at(&self, time_ns: i64) -> i64 {
        self.leads
            .iter()
            .rev()
            .find(|(from, until, _)| (*from..*until).contains(&time_ns))
            .map_or(0, |(_, _, lead)| *lead)
    }
}
