//! What happens to a live session between two frames handed to the app: what real headsets do
//! (the wearer takes the headset off, a system menu takes the focus, the session or the runtime
//! is lost, tracking is lost, the runtime says not to render, frames come late). A backend
//! hands them out after each frame (`vitreous-xr`'s `Backend::take_events`); the app counts
//! them, logs them and records them as a trace's event lines (version 1.4), and the null
//! backend hands a recording's events out again with the frames they came with.

use std::fmt;

/// Why frames the runtime handed out were not rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NotRendered {
    /// The runtime said not to (`shouldRender` false: the session not visible).
    Runtime,
    /// The head's orientation was not tracked: a world-locked object would be drawn in the
    /// wrong place.
    Tracking,
    /// A runtime call failed while the frame was prepared or submitted: the frame was left
    /// (its images released, ended with no layers) and the session went on.
    Failed,
}

/// What was lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Loss {
    /// The session (`XR_SESSION_STATE_LOSS_PENDING`, `XR_ERROR_SESSION_LOST`).
    Session,
    /// The runtime (`XrEventDataInstanceLossPending`, `XR_ERROR_INSTANCE_LOST`).
    Instance,
}

/// What head tracking lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TrackingLoss {
    /// The position: frames are drawn at the last tracked position with the tracked
    /// orientation.
    Position,
    /// The orientation (and position): frames are not drawn.
    Orientation,
}

/// Something that happened to a session between two frames (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SessionEvent {
    /// Frames the runtime handed out that the app did not render, and why.
    NotRendered {
        /// Why.
        reason: NotRendered,
        /// How many, in a row.
        frames: u64,
    },
    /// Display periods the runtime moved past with no frame of the app's (it was late).
    Late {
        /// How many periods.
        periods: u64,
    },
    /// The runtime stopped the session (the headset taken off, the device asleep): the app
    /// ended it and waits for the runtime to make it ready again.
    Ended,
    /// The session was begun again.
    Resumed,
    /// The session lost the input focus (a system menu): no controller input.
    Unfocused,
    /// The session has the input focus again.
    Focused,
    /// The session or the runtime was lost.
    Lost(Loss),
    /// A new instance and session after a loss.
    Reconnected {
        /// How long the app waited for the runtime to come back, milliseconds.
        waited_ms: u64,
    },
    /// Head tracking was lost.
    TrackingLost(TrackingLoss),
    /// Head tracking is back.
    TrackingBack,
    /// The reference space changed (the wearer recentred): the scene is placed again.
    Recentred,
    /// The eye tracker gave no usable sample for long enough to count as lost; the gaze
    /// decision is held.
    GazeLost,
    /// The eye tracker is back.
    GazeBack {
        /// How long it was lost, milliseconds.
        after_ms: u64,
    },
}

/// The words of every event kind, as a trace's event lines name them.
pub const EVENT_KINDS: [&str; 13] = [
    "not-rendered",
    "late",
    "session-ended",
    "session-resumed",
    "unfocused",
    "focused",
    "lost",
    "reconnected",
    "tracking-lost",
    "tracking-back",
    "recentred",
    "gaze-lost",
    "gaze-back",
];

impl SessionEvent {
    /// The event as a trace's event line holds it: kind, reason (empty when the kind has
    /// none) and count (frames, periods or milliseconds; 0 when the kind has none).
    pub fn fields(&self) -> (&'static str, &'static str, u64) {
        match *self {
            SessionEvent::NotRendered { reason, frames } => (
                "not-rendered",
                match reason {
                    NotRendered::Runtime => "runtime",
                    NotRendered::Tracking => "tracking",
                    NotRendered::Failed => "failed",
                },
                frames,
            ),
            SessionEvent::Late { periods } => ("late", "", periods),
            SessionEvent::Ended => ("session-ended", "", 0),
            SessionEvent::Resumed => ("session-resumed", "", 0),
            SessionEvent::Unfocused => ("unfocused", "", 0),
            SessionEvent::Focused => ("focused", "", 0),
            SessionEvent::Lost(Loss::Session) => ("lost", "session", 0),
            SessionEvent::Lost(Loss::Instance) => ("lost", "instance", 0),
            SessionEvent::Reconnected { waited_ms } => ("reconnected", "", waited_ms),
            SessionEvent::TrackingLost(TrackingLoss::Position) => ("tracking-lost", "position", 0),
            SessionEvent::TrackingLost(TrackingLoss::Orientation) => {
                ("tracking-lost", "orientation", 0)
            }
            SessionEvent::TrackingBack => ("tracking-back", "", 0),
            SessionEvent::Recentred => ("recentred", "", 0),
            SessionEvent::GazeLost => ("gaze-lost", "", 0),
            SessionEvent::GazeBack { after_ms } => ("gaze-back", "", after_ms),
        }
    }

    /// The event an event line's kind, reason and count describe, or what is expected of them.
    pub fn from_fields(kind: &str, reason: &str, count: u64) -> Result<SessionEvent, String> {
        let none = |e: SessionEvent| {
            if reason.is_empty() {
                Ok(e)
            } else {
                Err(format!("`{kind}` takes no reason, got `{reason}`"))
            }
        };
        match kind {
            "not-rendered" => Ok(SessionEvent::NotRendered {
                reason: match reason {
                    "runtime" => NotRendered::Runtime,
                    "tracking" => NotRendered::Tracking,
                    "failed" => NotRendered::Failed,
                    other => {
                        return Err(format!(
                            "`not-rendered` takes runtime, tracking or failed, got `{other}`"
                        ));
                    }
                },
                frames: count,
            }),
            "late" => none(SessionEvent::Late { periods: count }),
            "session-ended" => none(SessionEvent::Ended),
            "session-resumed" => none(SessionEvent::Resumed),
            "unfocused" => none(SessionEvent::Unfocused),
            "focused" => none(SessionEvent::Focused),
            "lost" => match reason {
                "session" => Ok(SessionEvent::Lost(Loss::Session)),
                "instance" => Ok(SessionEvent::Lost(Loss::Instance)),
                other => Err(format!("`lost` takes session or instance, got `{other}`")),
            },
            "reconnected" => none(SessionEvent::Reconnected { waited_ms: count }),
            "tracking-lost" => match reason {
                "position" => Ok(SessionEvent::TrackingLost(TrackingLoss::Position)),
                "orientation" => Ok(SessionEvent::TrackingLost(TrackingLoss::Orientation)),
                other => Err(format!(
                    "`tracking-lost` takes position or orientation, got `{other}`"
                )),
            },
            "tracking-back" => none(SessionEvent::TrackingBack),
            "recentred" => none(SessionEvent::Recentred),
            "gaze-lost" => none(SessionEvent::GazeLost),
            "gaze-back" => none(SessionEvent::GazeBack { after_ms: count }),
            other => Err(format!(
                "`{other}` is not one of {}",
                EVENT_KINDS.join(", ")
            )),
        }
    }
}

impl fmt::Display for SessionEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            SessionEvent::NotRendered { reason, frames } => write!(
                f,
                "{frames} frame{} not rendered ({})",
                if frames == 1 { "" } else { "s" },
                match reason {
                    NotRendered::Runtime => "the runtime said not to",
                    NotRendered::Tracking => "head orientation not tracked",
                    NotRendered::Failed => "a runtime call failed",
                }
            ),
            SessionEvent::Late { periods } => write!(
                f,
                "{periods} display period{} passed without a frame (late)",
                if periods == 1 { "" } else { "s" }
            ),
            SessionEvent::Ended => f.write_str("the runtime stopped the session (headset off?)"),
            SessionEvent::Resumed => f.write_str("the session runs again"),
            SessionEvent::Unfocused => f.write_str("the session lost the input focus"),
            SessionEvent::Focused => f.write_str("the session has the input focus again"),
            SessionEvent::Lost(Loss::Session) => f.write_str("the session was lost"),
            SessionEvent::Lost(Loss::Instance) => f.write_str("the OpenXR runtime was lost"),
            SessionEvent::Reconnected { waited_ms } => write!(
                f,
                "a new session after waiting {:.1} s for the runtime",
                waited_ms as f64 / 1000.0
            ),
            SessionEvent::TrackingLost(TrackingLoss::Position) => {
                f.write_str("head position not tracked: held at the last tracked one")
            }
            SessionEvent::TrackingLost(TrackingLoss::Orientation) => {
                f.write_str("head orientation not tracked: frames not drawn")
            }
            SessionEvent::TrackingBack => f.write_str("head tracking is back"),
            SessionEvent::Recentred => f.write_str("the reference space changed (recentred)"),
            SessionEvent::GazeLost => {
                f.write_str("the eye tracker gives no usable sample: the gaze decision is held")
            }
            SessionEvent::GazeBack { after_ms } => write!(
                f,
                "the eye tracker is back after {:.1} s",
                after_ms as f64 / 1000.0
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_goes_through_its_fields_and_back() {
        let all = [
            SessionEvent::NotRendered {
                reason: NotRendered::Runtime,
                frames: 3,
            },
            SessionEvent::NotRendered {
                reason: NotRendered::Tracking,
                frames: 1,
            },
            SessionEvent::NotRendered {
                reason: NotRendered::Failed,
                frames: 1,
            },
            SessionEvent::Late { periods: 4 },
            SessionEvent::Ended,
            SessionEvent::Resumed,
            SessionEvent::Unfocused,
            SessionEvent::Focused,
            SessionEvent::Lost(Loss::Session),
            SessionEvent::Lost(Loss::Instance),
            SessionEvent::Reconnected { waited_ms: 2500 },
            SessionEvent::TrackingLost(TrackingLoss::Position),
            SessionEvent::TrackingLost(TrackingLoss::Orientation),
            SessionEvent::TrackingBack,
            SessionEvent::Recentred,
            SessionEvent::GazeLost,
            SessionEvent::GazeBack { after_ms: 1200 },
        ];
        for e in all {
            let (kind, reason, count) = e.fields();
            assert!(EVENT_KINDS.contains(&kind), "{kind}");
            assert_eq!(SessionEvent::from_fields(kind, reason, count), Ok(e));
            assert!(!e.to_string().is_empty());
        }
        for kind in EVENT_KINDS {
            assert!(
                all.iter().any(|e| e.fields().0 == kind),
                "{kind} never made"
            );
        }
    }

    #[test]
    fn a_bad_kind_or_reason_says_what_is_expected() {
        let e = SessionEvent::from_fields("crashed", "", 0).unwrap_err();
        assert!(e.contains("not-rendered, late"), "{e}");
        let e = SessionEvent::from_fields("lost", "headset", 0).unwrap_err();
        assert!(e.contains("session or instance"), "{e}");
        let e = SessionEvent::from_fields("recentred", "twice", 0).unwrap_err();
        assert!(e.contains("takes no reason"), "{e}");
    }
}
