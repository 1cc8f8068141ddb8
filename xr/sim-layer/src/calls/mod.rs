//! The layer's OpenXR entry points, and what they share: the context of a session copied out
//! of the registry, and locating spaces relative to the head.
//!
//! Every entry point runs its body in [`guard`](crate::guard::guard), takes what it needs
//! from the registry under the lock, and calls down the chain without it.

pub mod actions;
pub mod controller;
pub mod fb;
pub mod instance;
pub mod lifecycle;
pub mod light;
pub mod ml;
pub mod planes;
pub mod session;
pub mod spaces;
pub mod swapchain;
pub mod tracking;

use std::ffi::c_void;
use std::sync::Arc;

use openxr::sys::{self, Handle};
use vitreous_trace::{GazeBehaviour, GazeSample, Pose, TrackerConfidence, TrackerReport};

use crate::behaviour::Behaviour;
use crate::config::{Config, GazeExtension};
use crate::eye_geometry::{from_posef, inverse};
use crate::faults::schedule::Dropout;
use crate::next::NextTable;
use crate::registry::Registry;
use crate::timeline::{GazeTimeline, TimeBase};

/// How many structures of a `next` chain the layer looks at before giving up (a chain that
/// long is a loop).
const MAX_CHAIN: usize = 64;

/// The structures of a `next` chain, in order.
///
/// # Safety
/// `first` must be null or the start of a valid chain of OpenXR structures.
pub unsafe fn chain(first: *mut c_void) -> Vec<*mut sys::BaseOutStructure> {
    let mut out = Vec::new();
    let mut p = first as *mut sys::BaseOutStructure;
    while !p.is_null() && out.len() < MAX_CHAIN {
        out.push(p);
        // SAFETY: `p` is a structure of the valid chain (caller's guarantee).
        p = unsafe { (*p).next };
    }
    out
}

/// Every location flag: what a tracked pose reports.
pub fn all_location_flags() -> sys::SpaceLocationFlags {
    sys::SpaceLocationFlags::ORIENTATION_VALID
        | sys::SpaceLocationFlags::POSITION_VALID
        | sys::SpaceLocationFlags::ORIENTATION_TRACKED
        | sys::SpaceLocationFlags::POSITION_TRACKED
}

/// The next layer's functions of an instance the layer knows.
pub fn instance_next(instance: sys::Instance) -> Option<Arc<NextTable>> {
    crate::registry::registry()
        .instances
        .get(&instance.into_raw())
        .map(|i| i.next.clone())
}

/// What a call about a session needs, copied out of the registry.
#[derive(Clone)]
pub struct SessionContext {
    /// The session.
    pub session: sys::Session,
    /// Its instance.
    pub instance: sys::Instance,
    /// The next layer's functions.
    pub next: Arc<NextTable>,
    /// The configuration.
    pub config: Arc<Config>,
    /// The layer's extensions the app enabled.
    pub owned: Vec<GazeExtension>,
    /// The layer's VIEW space: the head.
    pub view_space: sys::Space,
    /// The trace's eye data.
    pub timeline: Option<Arc<GazeTimeline>>,
    /// The session's clock mapping (after the first `xrWaitFrame`).
    pub time_base: Option<TimeBase>,
    /// The newest predicted display time.
    pub latest_display_ns: Option<i64>,
}

impl SessionContext {
    /// The context of `session`, if the layer knows it.
    pub fn of(reg: &Registry, session: u64) -> Option<SessionContext> {
        let (s, i) = reg.session(session)?;
        let timeline = i.timeline.clone();
        let time_base = match (&timeline, s.first_display_ns) {
            (Some(t), Some(first)) => Some(TimeBase {
                first_display_ns: first,
                trace_start_ns: t.start_ns(),
            }),
            _ => None,
        };
        Some(SessionContext {
            session: sys::Session::from_raw(session),
            instance: sys::Instance::from_raw(s.instance),
            next: i.next.clone(),
            config: i.config.clone(),
            owned: i.owned.clone(),
            view_space: s.view_space,
            timeline,
            time_base,
            latest_display_ns: s.latest_display_ns,
        })
    }

    /// The eye data at runtime time `time_ns`, its `sample_time_ns` on the runtime clock (or
    /// that far ahead of it while a `gaze-clock` fault lasts). Before the session's first frame
    /// there is no clock mapping yet: the trace's first sample, stamped `time_ns`.
    pub fn gaze_at(&self, time_ns: i64) -> Option<GazeSample> {
        let (dropout, lead_ns) =
            crate::faults::with(|f| (f.dropout_at(time_ns), f.gaze_lead_at(time_ns)))
                .unwrap_or((None, 0));
        let mut sample = match dropout {
            None => self.trace_gaze_at(time_ns),
            Some((kind, from_ns)) => self.dropped_out(time_ns, kind, from_ns),
        }?;
        sample.sample_time_ns += lead_ns;
        Some(sample)
    }

    /// The eye data while the tracker drops out (`kind`, since `from_ns`): the sample at the
    /// start of the dropout, its time stamp kept (no new sample); a sample with nothing valid;
    /// or the sample with LOW confidence.
    fn dropped_out(&self, time_ns: i64, kind: Dropout, from_ns: i64) -> Option<GazeSample> {
        Some(match kind {
            Dropout::None => self.trace_gaze_at(from_ns)?,
            Dropout::Invalid => {
                self.timeline.as_ref()?;
                GazeSample::none(time_ns)
            }
            Dropout::Low => {
                let mut s = self.trace_gaze_at(time_ns)?;
                s.report = Some(TrackerReport {
                    confidence: TrackerConfidence::Low,
                    behaviour: s.report.map_or(GazeBehaviour::Unknown, |r| r.behaviour),
                });
                s
            }
        })
    }

    /// The trace's eye data at runtime time `time_ns` (see [`SessionContext::gaze_at`]).
    fn trace_gaze_at(&self, time_ns: i64) -> Option<GazeSample> {
        let timeline = self.timeline.as_ref()?;
        Some(match self.time_base {
            Some(base) => {
                let mut s = timeline.at(base.to_trace(time_ns));
                s.sample_time_ns = base.to_runtime(s.sample_time_ns);
                s
            }
            None => {
                let mut s = timeline.at(i64::MIN);
                s.sample_time_ns = time_ns;
                s
            }
        })
    }

    /// The eye data at the newest frame's display time (for the calls that name no time).
    pub fn gaze_now(&self) -> Option<GazeSample> {
        self.gaze_at(self.latest_display_ns.unwrap_or(0))
    }

    /// The gaze behaviour at runtime time `time_ns`, its onset on the runtime clock. Before the
    /// session's first frame: the trace's first sample's, begun at `time_ns`.
    pub fn behaviour_at(&self, time_ns: i64) -> Option<Behaviour> {
        let timeline = self.timeline.as_ref()?;
        // An eye tracker without samples does not classify the eyes' movement either.
        if let Some(Some((Dropout::None | Dropout::Invalid, _))) =
            crate::faults::with(|f| f.dropout_at(time_ns))
        {
            return None;
        }
        Some(match self.time_base {
            Some(base) => {
                let mut b = timeline.behaviour_at(base.to_trace(time_ns));
                b.onset_ns = base.to_runtime(b.onset_ns);
                b
            }
            None => Behaviour {
                onset_ns: time_ns,
                duration_ns: 0,
                ..timeline.behaviour_at(i64::MIN)
            },
        })
    }

    /// Where `space` is in the head (VIEW) frame at `time`, located by the next layer, with
    /// the location flags. `None` when the next layer fails.
    pub fn runtime_space_in_view(
        &self,
        space: sys::Space,
        time: sys::Time,
    ) -> Option<(Pose, sys::SpaceLocationFlags)> {
        let mut loc = sys::SpaceLocation {
            ty: sys::SpaceLocation::TYPE,
            next: std::ptr::null_mut(),
            location_flags: sys::SpaceLocationFlags::EMPTY,
            pose: sys::Posef::IDENTITY,
        };
        // SAFETY: both spaces belong to this session's chain (the view space is the layer's,
        // `space` the caller's); `loc` is a valid output structure.
        let r = unsafe { (self.next.locate_space)(space, self.view_space, time, &mut loc) };
        if r.into_raw() < 0 {
            return None;
        }
        Some((from_posef(&loc.pose), loc.location_flags))
    }

    /// Where space `a` is in space `b` at `time`, through the runtime; `None` when it cannot
    /// locate it.
    pub fn space_in(&self, a: sys::Space, b: sys::Space, time: sys::Time) -> Option<Pose> {
        let mut loc = sys::SpaceLocation {
            ty: sys::SpaceLocation::TYPE,
            next: std::ptr::null_mut(),
            location_flags: sys::SpaceLocationFlags::EMPTY,
            pose: sys::Posef::IDENTITY,
        };
        // SAFETY: the next layer's function with the app's live spaces and a valid output.
        let r = unsafe { (self.next.locate_space)(a, b, time, &mut loc) };
        let needed =
            sys::SpaceLocationFlags::ORIENTATION_VALID | sys::SpaceLocationFlags::POSITION_VALID;
        (r.into_raw() >= 0 && loc.location_flags.contains(needed)).then(|| from_posef(&loc.pose))
    }

    /// The transform from the head frame into `base` at `time` (`view_in_base`), when the
    /// runtime locates `base` with a valid position and orientation.
    pub fn head_to_base(
        &self,
        base: sys::Space,
        time: sys::Time,
    ) -> Option<(Pose, sys::SpaceLocationFlags)> {
        let (base_in_view, flags) = self.runtime_space_in_view(base, time)?;
        let needed =
            sys::SpaceLocationFlags::ORIENTATION_VALID | sys::SpaceLocationFlags::POSITION_VALID;
        flags
            .contains(needed)
            .then(|| (inverse(&base_in_view), flags))
    }
}

/// The pose of a valid head-frame ray in `base`, given `view_in_base`.
pub fn in_base(view_in_base: &Pose, head_frame_pose: &Pose) -> sys::Posef {
    crate::eye_geometry::to_posef(&crate::eye_geometry::compose(view_in_base, head_frame_pose))
}
