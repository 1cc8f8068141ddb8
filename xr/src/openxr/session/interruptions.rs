//! What a real headset does to a running session and how the session takes it: which failed
//! calls cost one frame and which end the session, the counts `summary.json` reports, and the
//! events handed to the app ([`SessionEvent`]), frames not rendered for one reason in a row
//! folded into one.

use std::collections::BTreeMap;

use openxr as xr;
use vitreous_trace::session_event::{Loss, NotRendered, SessionEvent};

use super::super::OpenXrError;

/// How many frames in a row may fail with a runtime failure before the session gives up: a
/// runtime that fails every call is not coming back by itself.
pub(super) const MAX_FAILED_FRAMES_IN_A_ROW: u32 = 30;

/// What a failed call means for the session.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Severity {
    /// The frame is left (images released, ended with no layers) and the session goes on:
    /// `XR_ERROR_RUNTIME_FAILURE` from one call.
    Frame,
    /// The session (or the runtime) is gone: the session ends, and the app may start anew.
    Lost(Loss),
    /// Anything else: an error of the app's or of a runtime it cannot work with.
    Fatal,
}

/// The severity of an error of the session.
pub(super) fn severity(e: &OpenXrError) -> Severity {
    match e {
        OpenXrError::Call { result, .. } => match *result {
            xr::sys::Result::ERROR_RUNTIME_FAILURE => Severity::Frame,
            xr::sys::Result::ERROR_SESSION_LOST => Severity::Lost(Loss::Session),
            xr::sys::Result::ERROR_INSTANCE_LOST => Severity::Lost(Loss::Instance),
            _ => Severity::Fatal,
        },
        _ => Severity::Fatal,
    }
}

/// The session's account of what went wrong and what it did (`summary.json`'s
/// `interruptions`). Every frame xrWaitFrame handed out is either submitted with its layer or
/// counted once here as not rendered (by the runtime's word, lost tracking, the exit) or
/// abandoned (the session's report).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Interruptions {
    /// Frames xrWaitFrame handed out.
    pub frames_waited: u64,
    /// Frames not rendered because the head's orientation was not tracked.
    pub not_rendered_tracking: u64,
    /// Frames not rendered while the session walked to its end after the app asked to exit.
    pub not_rendered_exiting: u64,
    /// Frames drawn at the last tracked head position (orientation tracked).
    pub frames_position_held: u64,
    /// Frames whose located head or eye pose was marked valid but was not usable (a position
    /// not finite, an orientation not a unit quaternion): taken as lost tracking.
    pub frames_unusable_pose: u64,
    /// Frames whose views' field of view was marked valid but was none (not finite, not left
    /// of right and below up, or a right angle or more from straight ahead): not drawn.
    pub frames_unusable_field: u64,
    /// Times head tracking lost the position, and the orientation.
    pub tracking_losses: [u64; 2],
    /// Display periods the runtime moved past with no frame waited for (the app was late).
    pub late_periods: u64,
    /// Times the runtime stopped the running session (the headset taken off).
    pub pauses: u64,
    /// Times the session was begun again after that.
    pub resumes: u64,
    /// Times the running session lost the input focus (a system menu).
    pub unfocused: u64,
    /// Swapchain image waits that timed out and were waited for again.
    pub image_wait_timeouts: u64,
    /// Calls that failed with `XR_ERROR_RUNTIME_FAILURE`, by name: each cost its frame.
    pub failed_calls: BTreeMap<&'static str, u64>,
    /// What was lost, when the session ended that way.
    pub lost: Option<Loss>,
}

impl Interruptions {
    /// The counts of a run whose session was followed by `later`'s; what was lost is the
    /// later's.
    pub fn then(&mut self, later: &Interruptions) {
        self.frames_waited += later.frames_waited;
        self.not_rendered_tracking += later.not_rendered_tracking;
        self.not_rendered_exiting += later.not_rendered_exiting;
        self.frames_position_held += later.frames_position_held;
        self.frames_unusable_pose += later.frames_unusable_pose;
        self.frames_unusable_field += later.frames_unusable_field;
        self.tracking_losses[0] += later.tracking_losses[0];
        self.tracking_losses[1] += later.tracking_losses[1];
        self.late_periods += later.late_periods;
        self.pauses += later.pauses;
        self.resumes += later.resumes;
        self.unfocused += later.unfocused;
        self.image_wait_timeouts += later.image_wait_timeouts;
        for (call, n) in &later.failed_calls {
            *self.failed_calls.entry(call).or_default() += n;
        }
        self.lost = later.lost;
    }
}

/// The events for the app since the last frame handed out, frames not rendered folded.
#[derive(Clone, Debug, Default)]
pub(super) struct Pending {
    /// The events, oldest first.
    events: Vec<SessionEvent>,
    /// Frames not rendered in a row so far, and why.
    run: Option<(NotRendered, u64)>,
}

impl Pending {
    /// One more frame not rendered for `reason`.
    pub(super) fn not_rendered(&mut self, reason: NotRendered) {
        match &mut self.run {
            Some((r, n)) if *r == reason => *n += 1,
            _ => {
                self.fold();
                self.run = Some((reason, 1));
            }
        }
    }

    /// An event.
    pub(super) fn push(&mut self, event: SessionEvent) {
        self.fold();
        self.events.push(event);
    }

    /// Every event so far, taken out.
    pub(super) fn take(&mut self) -> Vec<SessionEvent> {
        self.fold();
        std::mem::take(&mut self.events)
    }

    /// Ends the run of frames not rendered (as one event).
    fn fold(&mut self) {
        if let Some((reason, frames)) = self.run.take() {
            self.events
                .push(SessionEvent::NotRendered { reason, frames });
        }
    }

    /// Logs each new event as it is handed out.
    pub(super) fn log(events: &[SessionEvent]) {
        for e in events {
            match e {
                SessionEvent::NotRendered { .. } | SessionEvent::Late { .. } => {
                    tracing::info!("{e}")
                }
                _ => tracing::warn!("{e}"),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_not_rendered_for_one_reason_in_a_row_are_one_event() {
        let mut p = Pending::default();
        p.not_rendered(NotRendered::Runtime);
        p.not_rendered(NotRendered::Runtime);
        p.push(SessionEvent::Ended);
        p.not_rendered(NotRendered::Tracking);
        p.not_rendered(NotRendered::Failed);
        assert_eq!(
            p.take(),
            [
                SessionEvent::NotRendered {
                    reason: NotRendered::Runtime,
                    frames: 2
                },
                SessionEvent::Ended,
                SessionEvent::NotRendered {
                    reason: NotRendered::Tracking,
                    frames: 1
                },
                SessionEvent::NotRendered {
                    reason: NotRendered::Failed,
                    frames: 1
                },
            ]
        );
        assert!(p.take().is_empty());
    }

    #[test]
    fn a_runtime_failure_costs_a_frame_and_a_loss_ends_the_session() {
        let call = |result| OpenXrError::Call {
            call: "xrLocateViews",
            result,
        };
        assert_eq!(
            severity(&call(xr::sys::Result::ERROR_RUNTIME_FAILURE)),
            Severity::Frame
        );
        assert_eq!(
            severity(&call(xr::sys::Result::ERROR_SESSION_LOST)),
            Severity::Lost(Loss::Session)
        );
        assert_eq!(
            severity(&call(xr::sys::Result::ERROR_INSTANCE_LOST)),
            Severity::Lost(Loss::Instance)
        );
        assert_eq!(
            severity(&call(xr::sys::Result::ERROR_CALL_ORDER_INVALID)),
            Severity::Fatal
        );
        assert_eq!(
            severity(&OpenXrError::FrameOrder("twice".into())),
            Severity::Fatal
        );
    }
}
