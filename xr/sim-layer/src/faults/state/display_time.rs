//! Display times no frame can have (`bad-time`): what the app is shown for its newest frame
//! while the fault lasts, and the true time its `xrEndFrame` at that time is ended at
//! underneath.

use super::Faults;
use crate::faults::schedule::BadTime;

impl Faults {
    /// The display time the app is shown for the frame truly displayed at `display_ns`: a
    /// bad one while a bad-time fault lasts (negative, or the frame before's again).
    pub(super) fn falsify_time(&mut self, display_ns: i64) {
        let shown = match self.bad_time_left {
            (n, kind) if n > 0 => {
                self.bad_time_left.0 -= 1;
                self.log.push(("bad-time", kind.name().to_owned()));
                let shown = match kind {
                    BadTime::Negative => -display_ns,
                    BadTime::Repeat => self.shown_ns.unwrap_or(display_ns),
                    BadTime::Ahead => display_ns + BadTime::AHEAD_NS,
                };
                self.falsified = Some((shown, display_ns, kind));
                shown
            }
            _ => {
                self.falsified = None;
                display_ns
            }
        };
        self.shown_ns = Some(shown);
    }

    /// The bad display time the app is shown for its newest frame, if it is one.
    pub fn shown_display(&self) -> Option<i64> {
        self.falsified.map(|(shown, _, _)| shown)
    }

    /// For the app's `xrEndFrame` at `display_ns`: when that is the bad time it was shown, the
    /// true one (which the runtime gets) and how it was bad.
    pub fn end_time(&mut self, display_ns: i64) -> Option<(i64, BadTime)> {
        match self.falsified {
            Some((shown, truth, kind)) if shown == display_ns => {
                self.falsified = None;
                Some((truth, kind))
            }
            _ => None,
        }
    }
}
