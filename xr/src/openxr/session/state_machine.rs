//! The session state machine: OpenXR events, xrBeginSession/xrEndSession as the runtime
//! walks the states, ending on request, and the live actions synced while FOCUSED.

use std::time::Instant;

use glam::Vec3;
use openxr as xr;
use vitreous_trace::session_event::{Loss, SessionEvent};

use super::super::state::{self, Action, EndReason, State};
use super::super::{Result, XrContext};
use super::Session;
use super::interruptions::{Severity, severity};

impl Session {
    /// xrSyncActions with every attached set, then the controller commands; only while
    /// FOCUSED (input goes to the focused session only).
    pub(super) fn sync_actions(&mut self, head_m: Vec3) -> Result<()> {
        if self.state != State::Focused || self.action_sets.is_empty() {
            return Ok(());
        }
        let active: Vec<xr::ActiveActionSet<'_>> = self
            .action_sets
            .iter()
            .map(xr::ActiveActionSet::new)
            .collect();
        self.session.sync_actions(&active).xr("xrSyncActions")?;
        self.report.action_syncs += 1;
        let commands = match &self.controls {
            Some(c) => c.commands(&self.session)?,
            None => Vec::new(),
        };
        for command in commands {
            self.command(command, head_m);
        }
        Ok(())
    }

    fn set_state(&mut self, s: State) {
        self.state = s;
        if self.report.states.last() != Some(&s) {
            self.report.states.push(s);
        }
        tracing::info!("session state {s}");
    }

    fn end_with(&mut self, reason: EndReason) {
        if self.report.end_reason.is_none() {
            self.report.end_reason = Some(reason);
        }
    }

    /// Handles pending events; applies the state machine. A session or runtime lost in one of
    /// its calls (`xrPollEvent`, `xrBeginSession`, `xrEndSession`: a real runtime may say so
    /// there before any event does) ends the session as its loss event would.
    pub(super) fn poll_events(&mut self) -> Result<()> {
        let r = self.take_events();
        self.lost_or(r)
    }

    /// `r`, or `Ok` with the session lost where its error says the session or runtime is.
    fn lost_or(&mut self, r: Result<()>) -> Result<()> {
        match r {
            Err(e) => match severity(&e) {
                Severity::Lost(loss) => {
                    tracing::warn!("{e}");
                    self.lose(loss);
                    Ok(())
                }
                Severity::Frame | Severity::Fatal => Err(e),
            },
            ok => ok,
        }
    }

    fn take_events(&mut self) -> Result<()> {
        loop {
            let event = self
                .instance
                .poll_event(&mut self.events)
                .xr("xrPollEvent")?;
            let Some(event) = event else { break };
            match event {
                xr::Event::SessionStateChanged(e) => {
                    let s = state_of(e.state());
                    // Copy out before `self` is borrowed mutably again.
                    let before = self.state;
                    self.set_state(s);
                    self.note_focus(before, s);
                    match state::on_state(s, self.running) {
                        Action::Begin => {
                            self.session
                                .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
                                .xr("xrBeginSession")?;
                            self.running = true;
                            if self.paused.take().is_some() {
                                self.report.interruptions.resumes += 1;
                                self.pending.push(SessionEvent::Resumed);
                            }
                        }
                        Action::End => {
                            self.session.end().xr("xrEndSession")?;
                            self.running = false;
                            // Not asked for: the runtime stopped the session (the headset
                            // taken off, the device asleep), which may run again.
                            if !self.exit_requested {
                                let now = Instant::now();
                                self.paused = Some((now, now));
                                self.last_waited_ns = None;
                                self.report.interruptions.pauses += 1;
                                self.pending.push(SessionEvent::Ended);
                            }
                        }
                        Action::EndAndQuit | Action::Quit if s == State::LossPending => {
                            self.lose(Loss::Session);
                        }
                        Action::EndAndQuit | Action::Quit => {
                            self.end_with(EndReason::RuntimeExit);
                            self.quit = true;
                        }
                        Action::Continue => {}
                    }
                }
                xr::Event::InstanceLossPending(_) => {
                    self.lose(Loss::Instance);
                }
                xr::Event::ReferenceSpaceChangePending(e)
                    if e.reference_space_type() == self.space_type =>
                {
                    self.report.space_changes += 1;
                    self.pending.push(SessionEvent::Recentred);
                    self.world_from_space = None;
                    tracing::info!(
                        "the {:?} reference space changes (at {} ns): the scene is placed \
                         again at the next head pose",
                        e.reference_space_type(),
                        e.change_time().as_nanos()
                    );
                }
                xr::Event::EventsLost(e) => {
                    tracing::warn!("the runtime dropped {} events", e.lost_event_count());
                }
                _ => {}
            }
            if self.quit {
                break;
            }
        }
        Ok(())
    }

    /// The session or the runtime is lost: the session ends now, without the calls a lost
    /// session refuses (the app may start a new one).
    pub(super) fn lose(&mut self, loss: Loss) {
        if self.report.interruptions.lost.is_none() {
            self.report.interruptions.lost = Some(loss);
            self.pending.push(SessionEvent::Lost(loss));
        }
        self.running = false;
        self.end_with(match loss {
            Loss::Session => EndReason::SessionLost,
            Loss::Instance => EndReason::InstanceLost,
        });
        self.quit = true;
    }

    /// Notes the running session losing the input focus (FOCUSED to VISIBLE or SYNCHRONIZED,
    /// not on the way out) and getting it back.
    fn note_focus(&mut self, before: State, now: State) {
        let unfocused = matches!(now, State::Visible | State::Synchronized);
        if before == State::Focused && unfocused && self.running && !self.exit_requested {
            self.unfocused = true;
            self.report.interruptions.unfocused += 1;
            self.pending.push(SessionEvent::Unfocused);
        } else if now == State::Focused && self.unfocused {
            self.unfocused = false;
            self.pending.push(SessionEvent::Focused);
        }
    }

    /// Asks the runtime to end the session (or quits at once if it never ran).
    pub(super) fn stop(&mut self, reason: EndReason) -> Result<()> {
        self.end_with(reason);
        if self.exit_requested {
            return Ok(());
        }
        self.exit_requested = true;
        if self.running {
            tracing::info!("ending the session: {reason}");
            let r = self.session.request_exit().xr("xrRequestExitSession");
            self.lost_or(r)?;
        } else {
            self.quit = true;
        }
        Ok(())
    }
}

/// vitreous' state for an OpenXR one.
fn state_of(s: xr::SessionState) -> State {
    match s {
        xr::SessionState::IDLE => State::Idle,
        xr::SessionState::READY => State::Ready,
        xr::SessionState::SYNCHRONIZED => State::Synchronized,
        xr::SessionState::VISIBLE => State::Visible,
        xr::SessionState::FOCUSED => State::Focused,
        xr::SessionState::STOPPING => State::Stopping,
        xr::SessionState::LOSS_PENDING => State::LossPending,
        xr::SessionState::EXITING => State::Exiting,
        _ => State::Unknown,
    }
}
