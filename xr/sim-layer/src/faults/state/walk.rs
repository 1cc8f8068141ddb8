//! The session's lifecycle as the layer walks it: the states it hands out through
//! `xrPollEvent`, the app's `xrBeginSession`, `xrEndSession` and `xrRequestExitSession` answered
//! (or passed on) for the state the app was shown, and the runtime's own word taking over.

use std::time::Instant;

use openxr::sys;

use super::{Event, Faults, Outage, Pending, secs, state_name};

impl Faults {
    /// The next event for the app's `xrPollEvent` on `instance`, applied to the layer's state
    /// (`None`: ask the runtime).
    pub fn next_event(&mut self, instance: u64, now: Instant) -> Option<Event> {
        let time_ns = self.latest_display_ns.unwrap_or(0);
        if let Some(s) = self.instance_events.remove(&instance) {
            self.lost_instances.insert(instance);
            self.begin_outage(Outage::Runtime, now + secs(s));
            self.log.push(("instance-loss", format!("{s}")));
            return Some(Event::InstanceLoss {
                loss_time_ns: time_ns,
            });
        }
        let frames = self.frames;
        let mut sessions: Vec<u64> = self
            .sessions
            .iter()
            .filter(|(_, v)| v.instance == instance)
            .map(|(s, _)| *s)
            .collect();
        sessions.sort_unstable();
        for session in sessions {
            let Some(v) = self.sessions.get_mut(&session) else {
                continue;
            };
            let pending = match v.pending.front() {
                Some((due, p)) if *due < frames => {
                    let p = *p;
                    v.pending.pop_front();
                    p
                }
                _ => {
                    // Back on the wearer's head: READY once the time off has passed.
                    if v.shown == Some(sys::SessionState::IDLE)
                        && v.ready_at.is_some_and(|at| now >= at)
                    {
                        v.ready_at = None;
                        Pending::State(sys::SessionState::READY)
                    } else {
                        continue;
                    }
                }
            };
            let event = match pending {
                Pending::State(state) => {
                    // FOCUSED ends a walk: the runtime's session is FOCUSED underneath.
                    v.shown = (state != sys::SessionState::FOCUSED
                        || v.runtime != sys::SessionState::FOCUSED)
                        .then_some(state);
                    self.log.push(("state", state_name(state).to_owned()));
                    Event::State {
                        session,
                        state,
                        time_ns,
                    }
                }
                Pending::Space(space) => {
                    self.log.push(("space-change", format!("{space:?}")));
                    Event::SpaceChange {
                        session,
                        space,
                        time_ns,
                    }
                }
                Pending::Loss(s) => {
                    v.lost = true;
                    v.shown = Some(sys::SessionState::LOSS_PENDING);
                    self.begin_outage(Outage::Headset, now + secs(s));
                    self.log.push(("state", "LOSS_PENDING".to_owned()));
                    Event::State {
                        session,
                        state: sys::SessionState::LOSS_PENDING,
                        time_ns,
                    }
                }
            };
            return Some(event);
        }
        None
    }

    /// The runtime announced `state` for `session` (passing through `xrPollEvent`): the layer
    /// stops walking the session (the runtime's word wins).
    pub fn runtime_state(&mut self, session: u64, state: sys::SessionState) {
        if let Some(v) = self.sessions.get_mut(&session) {
            v.runtime = state;
            if v.shown.take().is_some() {
                v.pending.clear();
                v.ready_at = None;
                v.running = state != sys::SessionState::IDLE
                    && state != sys::SessionState::READY
                    && state != sys::SessionState::EXITING;
                self.log
                    .push(("state", format!("{} (the runtime's)", state_name(state))));
            }
        }
    }

    /// The app's `xrBeginSession`: `Some(result)` when the layer answers it (the runtime's
    /// session runs on), `None` to pass it on.
    pub fn begin_session(&mut self, session: u64) -> Option<sys::Result> {
        if let Some(r) = self.lost("xrBeginSession", session) {
            return Some(r);
        }
        let frames = self.frames;
        let v = self.sessions.get_mut(&session)?;
        if !v.walking() {
            v.running = true;
            return None;
        }
        let r = if v.running {
            sys::Result::ERROR_SESSION_RUNNING
        } else if v.state() != sys::SessionState::READY {
            sys::Result::ERROR_SESSION_NOT_READY
        } else {
            v.running = true;
            v.pending.extend([
                (frames, Pending::State(sys::SessionState::SYNCHRONIZED)),
                (frames + 1, Pending::State(sys::SessionState::VISIBLE)),
                (frames + 2, Pending::State(sys::SessionState::FOCUSED)),
            ]);
            self.log.push(("begin-session", "virtual".to_owned()));
            return Some(sys::Result::SUCCESS);
        };
        self.log.push(("refused", format!("xrBeginSession {r:?}")));
        Some(r)
    }

    /// The app's `xrEndSession`: `Some(result)` when the layer answers it, `None` to pass it
    /// on.
    pub fn end_session(&mut self, session: u64, now: Instant) -> Option<sys::Result> {
        if let Some(r) = self.lost("xrEndSession", session) {
            return Some(r);
        }
        let frames = self.frames;
        let v = self.sessions.get_mut(&session)?;
        if !v.walking() {
            v.running = false;
            return None;
        }
        let r = if !v.running {
            sys::Result::ERROR_SESSION_NOT_RUNNING
        } else if v.state() != sys::SessionState::STOPPING {
            sys::Result::ERROR_SESSION_NOT_STOPPING
        } else {
            v.running = false;
            v.pending.push_back((
                frames.saturating_sub(1),
                Pending::State(sys::SessionState::IDLE),
            ));
            v.ready_at = Some(now + secs(v.off_s));
            self.log.push(("end-session", "virtual".to_owned()));
            return Some(sys::Result::SUCCESS);
        };
        self.log.push(("refused", format!("xrEndSession {r:?}")));
        Some(r)
    }

    /// The app's `xrRequestExitSession`: refused when the app was shown a session that is not
    /// running (or a lost one), else passed on.
    pub fn request_exit(&mut self, session: u64) -> Option<sys::Result> {
        if let Some(r) = self.lost("xrRequestExitSession", session) {
            return Some(r);
        }
        let v = self.sessions.get(&session)?;
        (v.walking() && !v.running).then(|| {
            self.log.push((
                "refused",
                "xrRequestExitSession XR_ERROR_SESSION_NOT_RUNNING".to_owned(),
            ));
            sys::Result::ERROR_SESSION_NOT_RUNNING
        })
    }
}
