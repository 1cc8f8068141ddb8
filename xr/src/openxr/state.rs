//! The OpenXR session state machine as a pure function: what to do on each state change.
//!
//! ```text
//! IDLE -> READY (begin) -> SYNCHRONIZED -> VISIBLE -> FOCUSED
//!                                 ... -> STOPPING (end) -> IDLE -> EXITING (quit)
//!                       any -> LOSS_PENDING (end if running, quit)
//! ```
//! The app leaves by asking the runtime (xrRequestExitSession), which walks the session down
//! through STOPPING to EXITING, so every way out passes the same clean path.

use std::fmt;

/// Session states, as vitreous tracks them (OpenXR's `XrSessionState`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum State {
    /// Created, not yet running.
    Idle,
    /// The runtime wants the session begun.
    Ready,
    /// Frames are in step with the display but not shown.
    Synchronized,
    /// Frames are shown.
    Visible,
    /// Frames are shown and the app gets input.
    Focused,
    /// The runtime wants the session ended.
    Stopping,
    /// The session is about to be lost (device unplugged, runtime going away).
    LossPending,
    /// The session is over; destroy it.
    Exiting,
    /// A state this version does not know.
    Unknown,
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            State::Idle => "IDLE",
            State::Ready => "READY",
            State::Synchronized => "SYNCHRONIZED",
            State::Visible => "VISIBLE",
            State::Focused => "FOCUSED",
            State::Stopping => "STOPPING",
            State::LossPending => "LOSS_PENDING",
            State::Exiting => "EXITING",
            State::Unknown => "UNKNOWN",
        })
    }
}

/// What the backend does after a state change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Nothing; keep going (running frames if the session runs).
    Continue,
    /// Call xrBeginSession and start the frame loop.
    Begin,
    /// Call xrEndSession; stay to see IDLE/EXITING.
    End,
    /// Call xrEndSession if running, then leave: the session is being lost.
    EndAndQuit,
    /// Leave the loop and destroy the session.
    Quit,
}

/// The action for a change to `state` when the session is `running` (begun, not ended).
pub fn on_state(state: State, running: bool) -> Action {
    match state {
        State::Ready if !running => Action::Begin,
        State::Stopping if running => Action::End,
        State::LossPending if running => Action::EndAndQuit,
        State::LossPending => Action::Quit,
        State::Exiting => Action::Quit,
        _ => Action::Continue,
    }
}

/// Why a live session ended; every reason ends cleanly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EndReason {
    /// The asked-for number of frames was submitted.
    FrameLimit,
    /// Ctrl-C (SIGINT).
    Interrupted,
    /// The application said it is done ([`crate::openxr::SessionOptions::end`]).
    AppDone,
    /// The runtime asked the session to exit (EXITING after STOPPING), e.g. the user quit.
    RuntimeExit,
    /// The session is being lost (LOSS_PENDING).
    SessionLost,
    /// The runtime is going away (XR_EVENT_DATA_INSTANCE_LOSS_PENDING).
    InstanceLost,
}

impl fmt::Display for EndReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            EndReason::FrameLimit => "frame limit reached",
            EndReason::Interrupted => "interrupted (Ctrl-C)",
            EndReason::AppDone => "the application is done",
            EndReason::RuntimeExit => "the runtime ended the session",
            EndReason::SessionLost => "the session was lost (LOSS_PENDING)",
            EndReason::InstanceLost => "the OpenXR runtime is going away (instance loss pending)",
        })
    }
}

/// Whether frames may be waited for in `state` once the session runs.
pub fn runs_frames(state: State) -> bool {
    matches!(
        state,
        State::Ready | State::Synchronized | State::Visible | State::Focused
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ready_begins_only_once() {
        assert_eq!(on_state(State::Ready, false), Action::Begin);
        assert_eq!(on_state(State::Ready, true), Action::Continue);
    }

    #[test]
    fn stopping_ends_a_running_session() {
        assert_eq!(on_state(State::Stopping, true), Action::End);
        assert_eq!(on_state(State::Stopping, false), Action::Continue);
    }

    #[test]
    fn loss_pending_ends_and_quits() {
        assert_eq!(on_state(State::LossPending, true), Action::EndAndQuit);
        assert_eq!(on_state(State::LossPending, false), Action::Quit);
    }

    #[test]
    fn exiting_quits_whatever_else() {
        assert_eq!(on_state(State::Exiting, false), Action::Quit);
        assert_eq!(on_state(State::Exiting, true), Action::Quit);
    }

    #[test]
    fn visible_states_continue_and_run_frames() {
        for s in [State::Synchronized, State::Visible, State::Focused] {
            assert_eq!(on_state(s, true), Action::Continue);
            assert!(runs_frames(s));
        }
        assert!(!runs_frames(State::Stopping));
        assert!(!runs_frames(State::Idle));
    }

    #[test]
    fn a_full_session_walks_begin_then_end_then_quit() {
        let mut running = false;
        let mut actions = Vec::new();
        for s in [
            State::Idle,
            State::Ready,
            State::Synchronized,
            State::Visible,
            State::Focused,
            State::Visible,
            State::Synchronized,
            State::Stopping,
            State::Idle,
            State::Exiting,
        ] {
            let a = on_state(s, running);
            match a {
                Action::Begin => running = true,
                Action::End | Action::EndAndQuit => running = false,
                _ => {}
            }
            if a != Action::Continue {
                actions.push(a);
            }
        }
        assert_eq!(actions, [Action::Begin, Action::End, Action::Quit]);
    }
}
