//! What the fault schedule has done so far and what it makes each call answer: the layer's
//! side of a misbehaving headset as a state machine without OpenXR calls (the entry points in
//! `crate::calls::lifecycle` and friends ask it, then call down or not).
//!
//! A fault that walks the session through states (the headset taken off, a menu) makes the
//! layer answer the session's lifecycle itself while the runtime's own session keeps running
//! FOCUSED underneath: the app is shown VISIBLE, SYNCHRONIZED, STOPPING, its `xrEndSession`
//! is answered here (the runtime's session is not ended), IDLE, then READY after the headset's
//! time off, and its `xrBeginSession` is answered here too, followed by SYNCHRONIZED, VISIBLE
//! and FOCUSED on the next frames. Calls out of order for the state the app was shown get the
//! result the specification gives (`XR_ERROR_SESSION_NOT_RUNNING`, `_NOT_READY`,
//! `_NOT_STOPPING`), so an app that mishandles the walk fails the way it would on a headset.
//!
//! Just over 600 lines, one idea: the state every fault keeps and when each starts; the
//! session's walk (`walk.rs`), the bad display times (`display_time.rs`), the eye tracker's
//! faults (`gaze.rs`) and the tests are apart.

use std::collections::{HashMap, HashSet, VecDeque};
use std::time::{Duration, Instant};

use openxr::sys;

use super::schedule::{BadTime, Dropout, Fault, Scheduled, Trigger};
use crate::config::SimViews;
use gaze::GazeFaults;

/// Something the layer hands the app through `xrPollEvent`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// `XrEventDataSessionStateChanged`.
    State {
        /// The session.
        session: u64,
        /// Its new state.
        state: sys::SessionState,
        /// When, runtime time.
        time_ns: i64,
    },
    /// `XrEventDataInstanceLossPending`.
    InstanceLoss {
        /// When the instance is lost, runtime time.
        loss_time_ns: i64,
    },
    /// `XrEventDataReferenceSpaceChangePending`.
    SpaceChange {
        /// The session.
        session: u64,
        /// The reference space type that changes.
        space: sys::ReferenceSpaceType,
        /// When, runtime time.
        time_ns: i64,
    },
}

/// What a located head pose lacks this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackingLoss {
    /// The position is not valid.
    Position,
    /// Neither position nor orientation is valid.
    Orientation,
    /// Both marked valid, but holding nothing usable: the position not a number, the
    /// orientation an all-zero quaternion (as runtimes have handed out at start-up).
    Unusable,
    /// The poses as they are, but every view's field of view four zero angles (as a runtime
    /// asked for its views too early answers).
    ZeroFov,
}

/// What the layer does with the app's `xrWaitFrame`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaitPlan {
    /// Refuse it with this result.
    Refuse(sys::Result),
    /// Wait, begin and end this many frames with no layers first (the app is that many display
    /// periods late), then pass the app's call on.
    Go {
        /// Frames to skip.
        late: u64,
    },
}

/// A line for the fault log: its event and detail.
pub type LogLine = (&'static str, String);

/// Something pending for a session, deliverable once the app has waited for more frames than
/// its `due` frame.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pending {
    /// A state change.
    State(sys::SessionState),
    /// A reference space change.
    Space(sys::ReferenceSpaceType),
    /// LOSS_PENDING, then the headset is gone for this many seconds.
    Loss(f64),
}

/// What the layer keeps per session.
#[derive(Debug)]
struct Virtual {
    /// The session's instance.
    instance: u64,
    /// The state the runtime last announced (passing through `xrPollEvent`).
    runtime: sys::SessionState,
    /// The state the layer shows the app while it walks the session itself (`None`: the
    /// runtime's).
    shown: Option<sys::SessionState>,
    /// Whether the app has the session running (its own `xrBeginSession` without a matching
    /// `xrEndSession`).
    running: bool,
    /// Events to hand out, each once the app has waited for more frames than its due frame.
    pending: VecDeque<(u64, Pending)>,
    /// When a session the app ended (the headset off) becomes READY again.
    ready_at: Option<Instant>,
    /// How long the headset stays off once the app ends the session, seconds.
    off_s: f64,
    /// Refused with `XR_ERROR_SESSION_LOST` from the delivery of LOSS_PENDING on.
    lost: bool,
    /// The reference space types of the session's LOCAL and STAGE spaces.
    spaces: Vec<sys::ReferenceSpaceType>,
    /// The frame the app was last told not to render.
    no_render_frame: Option<u64>,
}

impl Virtual {
    /// The state the app sees.
    fn state(&self) -> sys::SessionState {
        self.shown.unwrap_or(self.runtime)
    }

    /// Whether the layer walks the session (or is about to).
    fn walking(&self) -> bool {
        self.shown.is_some() || !self.pending.is_empty() || self.ready_at.is_some()
    }
}

/// Why `xrGetSystem` or `xrCreateInstance` is refused for a while.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outage {
    /// After a session loss: `xrGetSystem` fails with `XR_ERROR_FORM_FACTOR_UNAVAILABLE`.
    Headset,
    /// After an instance loss: `xrCreateInstance` fails with `XR_ERROR_RUNTIME_UNAVAILABLE`, then
    /// with `XR_ERROR_INITIALIZATION_FAILED` (a runtime starting again, not ready yet).
    Runtime,
}

/// The fault schedule's state for the process.
#[derive(Debug)]
pub struct Faults {
    /// Faults not started yet, in start order.
    schedule: VecDeque<Scheduled>,
    /// The app's `xrWaitFrame` calls so far in the process.
    frames: u64,
    /// The first frame's predicted display time.
    first_display_ns: Option<i64>,
    /// The newest frame's.
    latest_display_ns: Option<i64>,
    /// Per session.
    sessions: HashMap<u64, Virtual>,
    /// Swapchains' sessions.
    swapchains: HashMap<u64, u64>,
    /// Instance losses not yet announced: instance -> the outage's seconds.
    instance_events: HashMap<u64, f64>,
    /// Instances lost.
    lost_instances: HashSet<u64>,
    /// Until when what is refused.
    outage: Option<(Outage, Instant)>,
    /// Calls refused in the current outage.
    outage_refusals: u32,
    /// Frames still to be told not to render.
    no_render_left: u64,
    /// Frames to skip before the app's next one.
    late_pending: u64,
    /// Swapchain image waits still to time out.
    timeouts_left: u64,
    /// Calls to fail once each.
    failing: Vec<&'static str>,
    /// Frames still to lose the head's position, then its orientation.
    tracking_left: (u64, u64),
    /// Frames still to hand out unusable head poses marked valid.
    unusable_left: u64,
    /// Frames left whose views have a zero field of view.
    zero_fov_left: u64,
    /// Frames still to predict at a bad display time, and how.
    bad_time_left: (u64, BadTime),
    /// The display time the app was shown for its newest frame.
    shown_ns: Option<i64>,
    /// The newest frame's bad display time as shown, its true one and how it is bad, until the
    /// app ends the frame.
    falsified: Option<(i64, i64, BadTime)>,
    /// What this frame's head poses lack.
    tracking_now: Option<TrackingLoss>,
    /// The eye tracker's dropouts and clocks ahead.
    gaze: GazeFaults,
    /// The eyes the newest `eyes` fault gave the headset, if one has started.
    eyes: Option<SimViews>,
    /// Lines for the fault log, taken by the caller.
    log: Vec<LogLine>,
}

impl Faults {
    /// The state at the start of a process with this schedule (every fault's `schedule` line
    /// logged).
    pub fn new(schedule: Vec<Scheduled>) -> Faults {
        let log = schedule
            .iter()
            .map(|s| ("schedule", s.to_string()))
            .collect();
        Faults {
            schedule: schedule.into(),
            frames: 0,
            first_display_ns: None,
            latest_display_ns: None,
            sessions: HashMap::new(),
            swapchains: HashMap::new(),
            instance_events: HashMap::new(),
            lost_instances: HashSet::new(),
            outage: None,
            outage_refusals: 0,
            no_render_left: 0,
            late_pending: 0,
            timeouts_left: 0,
            failing: Vec::new(),
            tracking_left: (0, 0),
            unusable_left: 0,
            zero_fov_left: 0,
            bad_time_left: (0, BadTime::Negative),
            shown_ns: None,
            falsified: None,
            tracking_now: None,
            gaze: GazeFaults::default(),
            eyes: None,
            log,
        }
    }

    /// The newest frame (from 0) and its display time, for the log.
    pub fn clock(&self) -> (Option<u64>, Option<i64>) {
        (self.frames.checked_sub(1), self.latest_display_ns)
    }

    /// The log lines since the last call.
    pub fn take_log(&mut self) -> Vec<LogLine> {
        std::mem::take(&mut self.log)
    }

    /// A session was created on `instance`.
    pub fn session_created(&mut self, session: u64, instance: u64) {
        self.sessions.insert(
            session,
            Virtual {
                instance,
                runtime: sys::SessionState::IDLE,
                shown: None,
                running: false,
                pending: VecDeque::new(),
                ready_at: None,
                off_s: 0.0,
                lost: false,
                spaces: Vec::new(),
                no_render_frame: None,
            },
        );
    }

    /// A session was destroyed.
    pub fn session_destroyed(&mut self, session: u64) {
        self.sessions.remove(&session);
        self.swapchains.retain(|_, s| *s != session);
    }

    /// An instance was destroyed: the layer forgets it and its sessions (a runtime may hand the
    /// same handle to the next instance, which is not lost).
    pub fn instance_destroyed(&mut self, instance: u64) {
        self.lost_instances.remove(&instance);
        self.instance_events.remove(&instance);
        let gone: Vec<u64> = self
            .sessions
            .iter()
            .filter(|(_, v)| v.instance == instance)
            .map(|(s, _)| *s)
            .collect();
        for session in gone {
            self.session_destroyed(session);
        }
    }

    /// The session made a reference space of this type.
    pub fn space_created(&mut self, session: u64, space: sys::ReferenceSpaceType) {
        let world =
            space == sys::ReferenceSpaceType::LOCAL || space == sys::ReferenceSpaceType::STAGE;
        if let Some(v) = self.sessions.get_mut(&session)
            && world
            && !v.spaces.contains(&space)
        {
            v.spaces.push(space);
        }
    }

    /// The session made a swapchain.
    pub fn swapchain_created(&mut self, swapchain: u64, session: u64) {
        self.swapchains.insert(swapchain, session);
    }

    /// The session of a swapchain the layer saw made.
    pub fn swapchain_session(&self, swapchain: u64) -> Option<u64> {
        self.swapchains.get(&swapchain).copied()
    }

    /// The result a call on `session` gets because the session or its instance is lost, if it
    /// is (logged as `lost-call`).
    fn lost(&mut self, call: &str, session: u64) -> Option<sys::Result> {
        let v = self.sessions.get(&session)?;
        let result = if self.lost_instances.contains(&v.instance) {
            sys::Result::ERROR_INSTANCE_LOST
        } else if v.lost {
            sys::Result::ERROR_SESSION_LOST
        } else {
            return None;
        };
        self.log.push(("lost-call", format!("{call} {result:?}")));
        Some(result)
    }

    /// The result a call on `session` between `xrBeginFrame` and `xrEndFrame` (or
    /// `xrEndFrame` itself) gets instead of going on, if any: lost, or a scheduled
    /// `XR_ERROR_RUNTIME_FAILURE` (once).
    pub fn refuse(&mut self, call: &'static str, session: u64) -> Option<sys::Result> {
        if let Some(r) = self.lost(call, session) {
            return Some(r);
        }
        let i = self.failing.iter().position(|c| *c == call)?;
        self.failing.remove(i);
        self.log.push(("failure", call.to_owned()));
        Some(sys::Result::ERROR_RUNTIME_FAILURE)
    }

    /// The result of a frame call (`xrBeginFrame`, `xrEndFrame`) the session is in no state
    /// to take, if any.
    pub fn frame_call(&mut self, call: &'static str, session: u64) -> Option<sys::Result> {
        if let Some(r) = self.lost(call, session) {
            return Some(r);
        }
        let v = self.sessions.get(&session)?;
        if v.walking() && !v.running {
            self.log
                .push(("refused", format!("{call} XR_ERROR_SESSION_NOT_RUNNING")));
            return Some(sys::Result::ERROR_SESSION_NOT_RUNNING);
        }
        None
    }

    /// What to do with the app's `xrWaitFrame` on `session`.
    pub fn before_wait(&mut self, session: u64) -> WaitPlan {
        if let Some(r) = self.frame_call("xrWaitFrame", session) {
            return WaitPlan::Refuse(r);
        }
        WaitPlan::Go {
            late: std::mem::take(&mut self.late_pending),
        }
    }

    /// A frame the layer waited for and ended with no layers, before the app's.
    pub fn skipped(&mut self, display_ns: i64) {
        self.log.push(("late", display_ns.to_string()));
    }

    /// After the app's `xrWaitFrame` on `session` returned a frame displayed at `display_ns`:
    /// counts it, starts the faults that are due, and says whether the app should render it.
    pub fn after_wait(
        &mut self,
        session: u64,
        display_ns: i64,
        should_render: bool,
        now: Instant,
    ) -> bool {
        let frame = self.frames;
        self.frames += 1;
        self.first_display_ns.get_or_insert(display_ns);
        self.latest_display_ns = Some(display_ns);
        self.start_due(session, frame, display_ns, now);
        self.falsify_time(display_ns);
        self.tracking_now = match self.tracking_left {
            _ if self.zero_fov_left > 0 => {
                self.zero_fov_left -= 1;
                Some(TrackingLoss::ZeroFov)
            }
            _ if self.unusable_left > 0 => {
                self.unusable_left -= 1;
                Some(TrackingLoss::Unusable)
            }
            (p, _) if p > 0 => {
                self.tracking_left.0 -= 1;
                Some(TrackingLoss::Position)
            }
            (_, o) if o > 0 => {
                self.tracking_left.1 -= 1;
                Some(TrackingLoss::Orientation)
            }
            _ => None,
        };
        if let Some(loss) = self.tracking_now {
            self.log
                .push(("tracking", format!("{loss:?}").to_lowercase()));
        }
        let shown_invisible = self.sessions.get(&session).is_some_and(|v| {
            let s = v.state();
            s != sys::SessionState::VISIBLE && s != sys::SessionState::FOCUSED
        });
        let told = self.no_render_left > 0;
        if told {
            self.no_render_left -= 1;
        }
        let render = should_render && !told && !shown_invisible;
        if !render {
            if let Some(v) = self.sessions.get_mut(&session) {
                v.no_render_frame = Some(frame);
            }
            if should_render {
                self.log.push(("no-render", String::new()));
            }
        }
        render
    }

    /// Starts every fault that is due at `frame` (displayed at `display_ns`); one that walks
    /// the session waits until the session is FOCUSED with nothing else going on.
    fn start_due(&mut self, session: u64, frame: u64, display_ns: i64, now: Instant) {
        let elapsed_s = (display_ns - self.first_display_ns.unwrap_or(display_ns)) as f64 * 1e-9;
        while let Some(next) = self.schedule.front() {
            let due = match next.trigger {
                Trigger::Frame(n) => frame >= n,
                Trigger::At(s) => elapsed_s >= s,
            };
            if !due {
                break;
            }
            let busy = self
                .sessions
                .get(&session)
                .is_none_or(|v| v.walking() || v.lost || v.state() != sys::SessionState::FOCUSED);
            if next.fault.changes_state() && busy {
                break;
            }
            let Some(next) = self.schedule.pop_front() else {
                break;
            };
            self.log.push(("fault", next.fault.to_string()));
            self.start(session, frame, display_ns, next.fault, now);
        }
    }

    /// Starts one fault at `frame`.
    fn start(&mut self, session: u64, frame: u64, display_ns: i64, fault: Fault, _now: Instant) {
        use sys::SessionState as S;
        let Some(v) = self.sessions.get_mut(&session) else {
            return;
        };
        match fault {
            Fault::HeadsetOff(s) => {
                v.off_s = s;
                v.pending.extend([
                    (frame, Pending::State(S::VISIBLE)),
                    (frame + 1, Pending::State(S::SYNCHRONIZED)),
                    (frame + 2, Pending::State(S::STOPPING)),
                ]);
            }
            Fault::Menu(n) => v.pending.extend([
                (frame, Pending::State(S::VISIBLE)),
                (frame + n, Pending::State(S::FOCUSED)),
            ]),
            Fault::SessionLoss(s) => v.pending.push_back((frame, Pending::Loss(s))),
            Fault::InstanceLoss(s) => {
                self.instance_events.insert(v.instance, s);
            }
            Fault::Recentre => {
                let spaces = v.spaces.clone();
                v.pending
                    .extend(spaces.into_iter().map(|t| (frame, Pending::Space(t))));
            }
            Fault::NoRender(n) => self.no_render_left += n,
            Fault::Late(n) => self.late_pending += n,
            Fault::ImageTimeout(n) => self.timeouts_left += n,
            Fault::RuntimeFailure(call) => self.failing.push(call),
            Fault::TrackingLost(p, o) => self.tracking_left = (p, o),
            Fault::UnusablePose(n) => self.unusable_left = n,
            Fault::ZeroFov(n) => self.zero_fov_left = n,
            Fault::BadTime(n, kind) => self.bad_time_left = (n, kind),
            Fault::GazeDropout(s, kind) => {
                self.gaze.drop_out(display_ns, s, kind);
                self.log.push(("dropout", format!("{} {s}", kind.name())));
            }
            Fault::GazeClock(s, ms) => self.gaze.run_ahead(display_ns, s, ms),
            Fault::Eyes(ipd_mm, toe_out_deg) => self.eyes = SimViews::new(ipd_mm, toe_out_deg),
        }
    }

    /// The result `xrGetSystem` gets while the headset is gone, if it is.
    pub fn get_system(&mut self, now: Instant) -> Option<sys::Result> {
        self.refused_during(Outage::Headset, now, "xrGetSystem")
            .then_some(sys::Result::ERROR_FORM_FACTOR_UNAVAILABLE)
    }

    /// The result `xrCreateInstance` gets while the runtime is gone, if it is: unavailable the
    /// first time, then failing to initialise, as a runtime that is starting again answers
    /// until it is ready.
    pub fn create_instance(&mut self, now: Instant) -> Option<sys::Result> {
        let refused = self.refused_during(Outage::Runtime, now, "xrCreateInstance");
        refused.then_some(match self.outage_refusals {
            1 => sys::Result::ERROR_RUNTIME_UNAVAILABLE,
            _ => sys::Result::ERROR_INITIALIZATION_FAILED,
        })
    }

    /// Refuses what an outage of `kind` refuses until `until`.
    fn begin_outage(&mut self, kind: Outage, until: Instant) {
        self.outage = Some((kind, until));
        self.outage_refusals = 0;
    }

    /// Whether `call` is refused by an outage of `kind` at `now` (logged).
    fn refused_during(&mut self, kind: Outage, now: Instant, call: &str) -> bool {
        match self.outage {
            Some((k, until)) if k == kind && now < until => {
                self.log.push(("unavailable", call.to_owned()));
                self.outage_refusals += 1;
                true
            }
            Some((_, until)) if now >= until => {
                self.outage = None;
                false
            }
            _ => false,
        }
    }

    /// The result of the app's `xrWaitSwapchainImage` on `swapchain` instead of going on, if
    /// any: lost, a scheduled failure, or a timeout due (only for a finite timeout: an infinite
    /// one is logged as `infinite-wait` and passed on).
    pub fn wait_image(&mut self, swapchain: u64, infinite: bool) -> Option<sys::Result> {
        let session = self.swapchains.get(&swapchain).copied()?;
        if let Some(r) = self.refuse("xrWaitSwapchainImage", session) {
            return Some(r);
        }
        if self.timeouts_left == 0 {
            return None;
        }
        if infinite {
            self.log.push(("infinite-wait", String::new()));
            return None;
        }
        self.timeouts_left -= 1;
        self.log.push(("timeout", String::new()));
        Some(sys::Result::TIMEOUT_EXPIRED)
    }

    /// The result of the app's `xrSyncActions` on `session` instead of going on, if any: lost,
    /// a scheduled failure, or `XR_SESSION_NOT_FOCUSED` while the app was shown a session
    /// that is not FOCUSED (logged as `unfocused-sync`).
    pub fn sync_actions(&mut self, session: u64) -> Option<sys::Result> {
        if let Some(r) = self.refuse("xrSyncActions", session) {
            return Some(r);
        }
        let v = self.sessions.get(&session)?;
        (v.shown.is_some() && v.state() != sys::SessionState::FOCUSED).then(|| {
            self.log.push(("unfocused-sync", String::new()));
            sys::Result::SESSION_NOT_FOCUSED
        })
    }

    /// The app submitted `layers` composition layers for the newest frame of `session`: logged
    /// as `rendered-unasked` when it was told not to render it.
    pub fn submitted(&mut self, session: u64, layers: u32) {
        let frame = self.frames.checked_sub(1);
        if layers > 0
            && frame.is_some()
            && self
                .sessions
                .get(&session)
                .is_some_and(|v| v.no_render_frame == frame)
        {
            self.log.push(("rendered-unasked", layers.to_string()));
        }
    }

    /// What the head poses located this frame lack, if anything.
    pub fn tracking(&self) -> Option<TrackingLoss> {
        self.tracking_now
    }

    /// The eyes `xrLocateViews` answers since the newest `eyes` fault, if one has started.
    pub fn eyes(&self) -> Option<SimViews> {
        self.eyes
    }

    /// The eye tracker's dropout at runtime time `time_ns`, and when it started, if any.
    pub fn dropout_at(&self, time_ns: i64) -> Option<(Dropout, i64)> {
        self.gaze.dropout_at(time_ns)
    }

    /// How far ahead of the runtime's the eye tracker's clock is at runtime time `time_ns`,
    /// nanoseconds (behind: negative; 0 but during a `gaze-clock` fault).
    pub fn gaze_lead_at(&self, time_ns: i64) -> i64 {
        self.gaze.lead_at(time_ns)
    }
}

/// `s` seconds as a duration (never negative).
fn secs(s: f64) -> Duration {
    Duration::from_secs_f64(s.max(0.0))
}

/// The specification's name of a session state.
pub fn state_name(state: sys::SessionState) -> &'static str {
    use sys::SessionState as S;
    match state {
        S::IDLE => "IDLE",
        S::READY => "READY",
        S::SYNCHRONIZED => "SYNCHRONIZED",
        S::VISIBLE => "VISIBLE",
        S::FOCUSED => "FOCUSED",
        S::STOPPING => "STOPPING",
        S::LOSS_PENDING => "LOSS_PENDING",
        S::EXITING => "EXITING",
        _ => "UNKNOWN",
    }
}

mod display_time;
mod gaze;
#[cfg(test)]
mod tests;
mod walk;
