//! Whether a predicted display time can be a frame's. Every clock of the app (the scene's
//! motion, the gaze filters, a study's phases) and the recording run on display times, which
//! must go forward with the world's time; runtimes have answered times that do not: negative
//! ones (a SteamVR release), the frame before's again, and a jump of weeks ahead after a
//! refocus (a streaming runtime's pacer). A frame at such a time is left undrawn
//! ([`Session::leave_bad_time`]); the periods between usable frames the app was late for are
//! counted ([`Session::note_lateness`]).

use std::fmt;
use std::time::{Duration, Instant};

use openxr as xr;
use vitreous_trace::session_event::{NotRendered, SessionEvent};

use super::Session;
use super::interruptions::MAX_FAILED_FRAMES_IN_A_ROW;
use crate::openxr::{OpenXrError, Result, XrContext};

/// How far a display time may run ahead of the world's time since the newest usable frame:
/// more is a clock that jumped (a frame is predicted a few periods ahead; a session resumed after
/// minutes has both clocks advanced alike).
pub(super) const MAX_AHEAD: Duration = Duration::from_secs(10);

/// Why a predicted display time cannot be a frame's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum BadTime {
    /// Zero or negative.
    NotPositive,
    /// Not after the newest usable frame's (nanoseconds).
    NotAfter(i64),
    /// Ahead of the newest usable frame's by this many seconds more than the world's time moved.
    Ahead(f64),
}

impl fmt::Display for BadTime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BadTime::NotPositive => f.write_str("not a time a frame can have"),
            BadTime::NotAfter(last) => write!(f, "not after the frame before's {last} ns"),
            BadTime::Ahead(s) => write!(f, "{s:.1} s further ahead than the world's time moved"),
        }
    }
}

/// Why `display_ns`, predicted `now`, cannot be a frame's after the newest usable frame
/// `last` (its display time and when it was predicted), if it cannot.
pub(super) fn bad_display_time(
    display_ns: i64,
    last: Option<(i64, Instant)>,
    now: Instant,
) -> Option<BadTime> {
    if display_ns <= 0 {
        return Some(BadTime::NotPositive);
    }
    let (last_ns, at) = last?;
    if display_ns <= last_ns {
        return Some(BadTime::NotAfter(last_ns));
    }
    let moved = now.saturating_duration_since(at);
    let ahead_ns = display_ns - last_ns - moved.as_nanos().min(i64::MAX as u128) as i64;
    (ahead_ns > MAX_AHEAD.as_nanos() as i64).then_some(BadTime::Ahead(ahead_ns as f64 * 1e-9))
}

impl Session {
    /// A begun frame the runtime predicted at a display time no frame can have
    /// ([`bad_display_time`]). Nothing of it is drawn, recorded or timed by it: it is ended
    /// with no layers, where a runtime may refuse its own time (`XR_ERROR_TIME_INVALID`, then
    /// no error of the session's), and counted as a failed xrWaitFrame; more than
    /// [`MAX_FAILED_FRAMES_IN_A_ROW`] frames failing in a row end the run.
    pub(super) fn leave_bad_time(&mut self, frame: &xr::FrameState, bad: BadTime) -> Result<()> {
        let time = frame.predicted_display_time;
        match self.stream.end(time, self.blend, &[]) {
            Ok(()) | Err(xr::sys::Result::ERROR_TIME_INVALID) => {}
            Err(result) => return Err(result).xr("xrEndFrame"),
        }
        // The periods waited stay as they were: the next usable frame is not late for them.
        let period = frame.predicted_display_period.as_nanos();
        if period > 0 {
            self.last_waited_ns = self.last_waited_ns.map(|last| last + period);
        }
        let failed = self
            .report
            .interruptions
            .failed_calls
            .entry("xrWaitFrame")
            .or_default();
        if *failed == 0 {
            tracing::warn!(
                "xrWaitFrame predicted display time {} ns, {bad}: the frame is left undrawn \
                 (counted as a failed xrWaitFrame)",
                time.as_nanos()
            );
        }
        *failed += 1;
        self.report.frames_abandoned += 1;
        self.pending.not_rendered(NotRendered::Failed);
        self.failed_in_a_row += 1;
        if self.failed_in_a_row > MAX_FAILED_FRAMES_IN_A_ROW {
            return Err(OpenXrError::Unsupported(format!(
                "{MAX_FAILED_FRAMES_IN_A_ROW} frames in a row failed; the last: xrWaitFrame \
                 predicted display time {} ns, {bad}",
                time.as_nanos()
            )));
        }
        Ok(())
    }

    /// Counts the display periods the runtime moved past since the frame waited before (none
    /// across a stop of the session).
    pub(super) fn note_lateness(&mut self, frame: &xr::FrameState) {
        let display = frame.predicted_display_time.as_nanos();
        let period = frame.predicted_display_period.as_nanos();
        if let (Some(before), true) = (self.last_waited_ns, period > 0) {
            let periods = ((display - before) as f64 / period as f64).round() as i64 - 1;
            if periods > 0 {
                self.report.interruptions.late_periods += periods as u64;
                self.pending.push(SessionEvent::Late {
                    periods: periods as u64,
                });
            }
        }
        self.last_waited_ns = Some(display);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_that_go_forward_with_the_world_are_a_frames() {
        let at = Instant::now();
        let later = at + Duration::from_millis(50);
        let last = Some((5_000_000_000, at));
        // The first frame, and the next one period on.
        assert_eq!(bad_display_time(1, None, at), None);
        assert_eq!(bad_display_time(5_050_000_000, last, later), None);
        // A session resumed after ten minutes off: both clocks moved.
        let resumed = at + Duration::from_secs(600);
        assert_eq!(
            bad_display_time(605_000_000_000, last, resumed),
            None,
            "display time moved with the world"
        );
        // A frame a few periods late is still a frame.
        assert_eq!(bad_display_time(5_250_000_000, last, later), None);
    }

    #[test]
    fn negative_repeated_and_jumped_times_are_not() {
        let at = Instant::now();
        let later = at + Duration::from_millis(50);
        let last = Some((5_000_000_000, at));
        assert_eq!(
            bad_display_time(-17_855_724_683_963_200, last, later),
            Some(BadTime::NotPositive)
        );
        assert_eq!(bad_display_time(0, None, at), Some(BadTime::NotPositive));
        assert_eq!(
            bad_display_time(5_000_000_000, last, later),
            Some(BadTime::NotAfter(5_000_000_000))
        );
        assert_eq!(
            bad_display_time(4_000_000_000, last, later),
            Some(BadTime::NotAfter(5_000_000_000))
        );
        // 27.6 days ahead 50 ms later; 11 s ahead too; 9 s is a slow frame, not a jump.
        let weeks = 5_000_000_000 + 2_384_640_000_000_000;
        assert!(matches!(
            bad_display_time(weeks, last, later),
            Some(BadTime::Ahead(s)) if s > 2.38e6
        ));
        assert!(matches!(
            bad_display_time(5_000_000_000 + 11_100_000_000, last, later),
            Some(BadTime::Ahead(s)) if (s - 11.05).abs() < 1e-6
        ));
        assert_eq!(bad_display_time(14_000_000_000, last, later), None);
    }
}
