//! Whether the eye tracker is giving usable samples. A tracker drops out (glare, a slipped
//! headset, a tracker that stalls): no new sample, no valid eye, or the tracker's own LOW
//! confidence in its vergence. For longer than a blink, that is said once (the gaze decision
//! holds its last image meanwhile: the filters take no evidence from such samples), and its end
//! with how long it lasted. A blink or closed eyes that the tracker reports as such are the
//! wearer's, not a dropout.

use vitreous_trace::{FrameInput, GazeBehaviour, SessionEvent, TrackerConfidence};

/// How long the tracker may give no usable sample before it counts as lost, seconds: longer
/// than a blink (100-400 ms).
pub const DROPOUT_S: f64 = 0.5;

/// The tracker's dropouts over a session (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GazeWatch {
    /// The newest sample time seen, nanoseconds.
    newest_ns: Option<i64>,
    /// Display time of the last frame with a usable sample (or the wearer's blink).
    last_usable_ns: Option<i64>,
    /// Whether the tracker counts as lost now.
    lost: bool,
    /// Display time of the frame before, nanoseconds.
    previous_ns: Option<i64>,
    /// Dropouts so far.
    pub dropouts: u64,
    /// The longest, milliseconds (from the last usable sample to the next).
    pub longest_ms: u64,
    /// Frames drawn while the tracker was lost (the gaze decision held).
    pub frames_held: u64,
}

impl GazeWatch {
    /// Looks at a frame's gaze; the dropout's start or end, when this frame brings one.
    pub fn observe(&mut self, frame: &FrameInput) -> Option<SessionEvent> {
        // Time without frames (the headset taken off, frames not rendered) is not the
        // tracker's: the wait for a usable sample counts frame time only.
        if let Some(gap) = self
            .previous_ns
            .replace(frame.time_ns)
            .map(|p| frame.time_ns - p)
            .filter(|g| *g as f64 * 1e-9 > DROPOUT_S)
        {
            self.last_usable_ns = self.last_usable_ns.map(|t| t + gap);
        }
        let fresh = frame
            .gaze
            .filter(|g| self.newest_ns.is_none_or(|n| g.sample_time_ns > n));
        if let Some(g) = fresh {
            self.newest_ns = Some(g.sample_time_ns);
        }
        let usable = fresh.is_some_and(|g| {
            let wearer = g.report.is_some_and(|r| {
                matches!(
                    r.behaviour,
                    GazeBehaviour::Blink | GazeBehaviour::EyesClosed
                )
            });
            let sure = g
                .report
                .is_none_or(|r| r.confidence != TrackerConfidence::Low);
            wearer || (g.left.valid && g.right.valid && sure)
        });
        if usable {
            let since = self.last_usable_ns.replace(frame.time_ns);
            if std::mem::take(&mut self.lost) {
                let after_ms = since.map_or(0, |t| ((frame.time_ns - t).max(0) / 1_000_000) as u64);
                self.longest_ms = self.longest_ms.max(after_ms);
                return Some(SessionEvent::GazeBack { after_ms });
            }
            return None;
        }
        // Not watched until the tracker gave a usable sample (a session without one has none).
        let since = self.last_usable_ns?;
        if self.lost {
            self.frames_held += 1;
            return None;
        }
        if (frame.time_ns - since) as f64 * 1e-9 > DROPOUT_S {
            self.lost = true;
            self.dropouts += 1;
            self.frames_held += 1;
            return Some(SessionEvent::GazeLost);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use vitreous_trace::{GazeRay, GazeSample, TrackerReport};

    use super::*;
    use crate::test_frame::test_frame;

    fn frame(
        time_ms: i64,
        sample_ms: i64,
        valid: bool,
        report: Option<TrackerReport>,
    ) -> FrameInput {
        let mut f = test_frame();
        f.time_ns = time_ms * 1_000_000;
        let ray = GazeRay {
            valid,
            ..GazeRay::INVALID
        };
        f.gaze = Some(GazeSample {
            report,
            left: ray,
            right: ray,
            ..GazeSample::none(sample_ms * 1_000_000)
        });
        f
    }

    #[test]
    fn a_dropout_longer_than_a_blink_is_said_once_with_its_end() {
        let mut w = GazeWatch::default();
        assert_eq!(w.observe(&frame(0, 0, true, None)), None);
        // A 300 ms blink: nothing.
        assert_eq!(w.observe(&frame(300, 300, false, None)), None);
        assert_eq!(w.observe(&frame(350, 350, true, None)), None);
        // Stale samples (the tracker stalled) for 600 ms: lost once, held, then back.
        let mut seen = Vec::new();
        for t in (400..=1000).step_by(50) {
            seen.extend(w.observe(&frame(t, 350, true, None)));
        }
        assert_eq!(seen, [SessionEvent::GazeLost]);
        assert_eq!(
            w.observe(&frame(1050, 1050, true, None)),
            Some(SessionEvent::GazeBack { after_ms: 700 })
        );
        assert_eq!((w.dropouts, w.longest_ms), (1, 700));
        assert!(w.frames_held >= 3);
    }

    #[test]
    fn low_confidence_drops_out_and_the_wearers_closed_eyes_do_not() {
        let report = |confidence, behaviour| {
            Some(TrackerReport {
                confidence,
                behaviour,
            })
        };
        let mut w = GazeWatch::default();
        w.observe(&frame(0, 0, true, None));
        let closed = report(TrackerConfidence::Low, GazeBehaviour::EyesClosed);
        for t in (50..2000).step_by(50) {
            assert_eq!(w.observe(&frame(t, t, false, closed)), None, "{t} ms");
        }
        let unsure = report(TrackerConfidence::Low, GazeBehaviour::Fixation);
        let events: Vec<_> = (2000..3000)
            .step_by(50)
            .filter_map(|t| w.observe(&frame(t, t, true, unsure)))
            .collect();
        assert_eq!(events, [SessionEvent::GazeLost]);
    }

    #[test]
    fn time_without_frames_is_not_the_trackers() {
        let mut w = GazeWatch::default();
        w.observe(&frame(0, 0, true, None));
        // The headset off for 3 s; the first frame after it has a stale sample, the next a
        // fresh one.
        assert_eq!(w.observe(&frame(3000, 0, true, None)), None);
        assert_eq!(w.observe(&frame(3050, 3050, true, None)), None);
        assert_eq!(w.dropouts, 0);
    }

    #[test]
    fn a_session_without_gaze_is_never_lost() {
        let mut w = GazeWatch::default();
        let mut f = test_frame();
        for t in 0..100 {
            f.time_ns = t * 100_000_000;
            f.gaze = None;
            assert_eq!(w.observe(&f), None);
        }
        assert_eq!(w.dropouts, 0);
    }
}
