//! The layer's state: one entry per instance, session, space and eye tracker the layer
//! knows, keyed by the raw handle, behind one mutex. Calls copy what they need out of it and
//! release the lock before calling down the chain (xrWaitFrame blocks).

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::{Arc, LazyLock, Mutex, MutexGuard};

use openxr::sys;
use vitreous_trace::Pose;

use crate::bindings::GazePaths;
use crate::config::{Config, GazeExtension};
use crate::controller::Buttons;
use crate::images::{SharedImages, TexelLayout};
use crate::next::NextTable;
use crate::submitted::SubmittedLog;
use crate::timeline::GazeTimeline;

/// What the layer keeps per instance.
pub struct InstanceState {
    /// The next layer's functions.
    pub next: Arc<NextTable>,
    /// The configuration read when the instance was created.
    pub config: Arc<Config>,
    /// The layer's extensions the app enabled.
    pub owned: Vec<GazeExtension>,
    /// The trace's eye data (present whenever an eye extension is offered).
    pub timeline: Option<Arc<GazeTimeline>>,
    /// The eye-gaze profile's paths (when XR_EXT_eye_gaze_interaction is enabled).
    pub gaze_paths: Option<GazePaths>,
    /// Actions bound to the eye-gaze pose.
    pub gaze_actions: HashSet<u64>,
    /// The submitted-frames CSV.
    pub submitted: Option<Arc<Mutex<SubmittedLog>>>,
    /// The simulated controller buttons (`VITREOUS_SIM_BUTTONS`).
    pub buttons: Option<Arc<Buttons>>,
    /// Actions bound to scripted inputs: the inputs of each (indices into the script's).
    pub button_actions: HashMap<u64, Vec<usize>>,
    /// Whether action sets were attached to any of its sessions (suggestions are then refused).
    pub attached: bool,
    /// The app enabled XR_EXT_plane_detection, which the layer answers.
    pub planes: bool,
    /// The app enabled XR_ML_light_estimation, which the layer answers.
    pub light: bool,
}

impl InstanceState {
    /// Whether the app enabled `ext` and the layer provides it.
    pub fn owns(&self, ext: GazeExtension) -> bool {
        self.owned.contains(&ext)
    }
}

/// What the layer keeps per session.
#[derive(Clone, Debug)]
pub struct SessionState {
    /// The instance's raw handle.
    pub instance: u64,
    /// The system the session runs on.
    pub system: sys::SystemId,
    /// A VIEW reference space the layer created in the runtime: the head.
    pub view_space: sys::Space,
    /// The predicted display time of the first `xrWaitFrame`: trace time zero.
    pub first_display_ns: Option<i64>,
    /// The predicted display time of the newest `xrWaitFrame`.
    pub latest_display_ns: Option<i64>,
    /// How many frames the app has ended.
    pub frames_ended: u64,
    /// The process's sessions made before this one.
    pub serial: u64,
    /// The newest predicted display time at the last two `xrSyncActions` (older, newer).
    pub syncs_ns: (Option<i64>, Option<i64>),
    /// The runtime's blend modes for the session's view configuration (known after
    /// `xrBeginSession`).
    pub runtime_blend: Option<Vec<sys::EnvironmentBlendMode>>,
    /// Whether the app attached its action sets to the session.
    pub attached: bool,
    /// What the app submits, read back (`VITREOUS_SIM_IMAGES`).
    pub images: Option<SharedImages>,
}

/// What the layer keeps per swapchain of a session whose images it reads back.
#[derive(Clone, Debug)]
pub struct SwapchainState {
    /// The session's raw handle.
    pub session: u64,
    /// How its texels are laid out (`None`: a format the layer does not read).
    pub layout: Option<TexelLayout>,
    /// Width and height, pixels.
    pub size: (u32, u32),
    /// Array layers.
    pub layers: u32,
    /// Its `VkImage`s, in index order.
    pub images: Vec<u64>,
    /// Indices acquired and not yet released, oldest first.
    pub acquired: VecDeque<u32>,
    /// The texels of each layer of the image released last.
    pub released: Option<Arc<Vec<Vec<u8>>>>,
}

/// What the layer keeps per space it saw created.
#[derive(Clone, Copy, Debug)]
pub struct SpaceState {
    /// The session's raw handle.
    pub session: u64,
    /// For an action space: the action and the space's pose in the action space. Whether
    /// the action is an eye-gaze action is decided when the space is located (its binding
    /// may be suggested after the space is created).
    pub action: Option<(u64, Pose)>,
    /// For a reference space: its type.
    pub reference: Option<sys::ReferenceSpaceType>,
}

/// An eye tracker the layer made.
#[derive(Clone, Copy, Debug)]
pub struct TrackerState {
    /// The session's raw handle.
    pub session: u64,
    /// Which extension made it.
    pub kind: GazeExtension,
}

/// A plane detector the layer made.
#[derive(Clone, Debug)]
pub struct DetectorState {
    /// The session's raw handle.
    pub session: u64,
    /// The last detection begun: its base space, the head's level pose in it then, and how
    /// many of the configured planes it found.
    pub detection: Option<(sys::Space, Pose, usize)>,
}

/// A light estimation the layer made.
#[derive(Clone, Copy, Debug)]
pub struct EstimationState {
    /// The session's raw handle.
    pub session: u64,
    /// The space the estimates' directions are in.
    pub base_space: sys::Space,
    /// The head's level pose in that space when the estimation was made: the frame the
    /// configured light is in.
    pub anchor: Pose,
    /// When it was made (its create info's time), nanoseconds.
    pub made_ns: i64,
    /// The cube map's face side, texels.
    pub face_side: u32,
}

/// One estimate the layer handed out: what it says, fixed when it was made.
#[derive(Clone, Copy, Debug)]
pub struct EstimateState {
    /// The estimation's raw handle.
    pub estimation: u64,
    /// The way the main light travels, in the estimation's base space.
    pub direction: glam::Vec3,
    /// When it was estimated, nanoseconds.
    pub time_ns: i64,
}

/// All of the layer's state.
pub struct Registry {
    /// Instances by handle.
    pub instances: HashMap<u64, InstanceState>,
    /// Sessions by handle.
    pub sessions: HashMap<u64, SessionState>,
    /// Spaces by handle.
    pub spaces: HashMap<u64, SpaceState>,
    /// Eye trackers by the handle the layer gave them.
    pub trackers: HashMap<u64, TrackerState>,
    /// Plane detectors by the handle the layer gave them.
    pub detectors: HashMap<u64, DetectorState>,
    /// Light estimations by the handle the layer gave them.
    pub estimations: HashMap<u64, EstimationState>,
    /// Light estimates by the handle the layer gave them.
    pub estimates: HashMap<u64, EstimateState>,
    /// Swapchains of sessions whose images the layer reads back, by handle.
    pub swapchains: HashMap<u64, SwapchainState>,
    /// The next handle the layer gives out.
    next_handle: u64,
    /// Sessions made so far in the process.
    pub sessions_made: u64,
}

/// The first handle the layer gives out: unlike the small counters and pointers runtimes use,
/// so a mix-up shows in logs.
const FIRST_HANDLE: u64 = 0x5649_5452_0000_0001;

impl Registry {
    /// An empty registry.
    fn new() -> Registry {
        Registry {
            instances: HashMap::new(),
            sessions: HashMap::new(),
            spaces: HashMap::new(),
            trackers: HashMap::new(),
            detectors: HashMap::new(),
            estimations: HashMap::new(),
            estimates: HashMap::new(),
            swapchains: HashMap::new(),
            next_handle: FIRST_HANDLE,
            sessions_made: 0,
        }
    }

    /// A new handle: unique in the process, never zero.
    pub fn new_handle(&mut self) -> u64 {
        let h = self.next_handle;
        self.next_handle = self.next_handle.wrapping_add(1).max(1);
        h
    }

    /// A new plane detector on `session`: its handle, or `None` when the layer knows no
    /// such session.
    pub fn new_detector(&mut self, session: u64) -> Option<u64> {
        if !self.sessions.contains_key(&session) {
            return None;
        }
        let h = self.new_handle();
        self.detectors.insert(
            h,
            DetectorState {
                session,
                detection: None,
            },
        );
        Some(h)
    }

    /// A new eye tracker of extension `kind` on `session`: its handle, or `None` when the
    /// layer knows no such session.
    pub fn new_tracker(&mut self, session: u64, kind: GazeExtension) -> Option<u64> {
        if !self.sessions.contains_key(&session) {
            return None;
        }
        let h = self.new_handle();
        self.trackers.insert(h, TrackerState { session, kind });
        Some(h)
    }

    /// A session's state and its instance's.
    pub fn session(&self, session: u64) -> Option<(&SessionState, &InstanceState)> {
        let s = self.sessions.get(&session)?;
        let i = self.instances.get(&s.instance)?;
        Some((s, i))
    }

    /// The next-layer table to call for a space: its session's instance, or, for a space the
    /// layer did not see created, the only instance (`None` when there are several).
    pub fn next_for_space(&self, space: u64) -> Option<Arc<NextTable>> {
        if let Some(s) = self.spaces.get(&space)
            && let Some((_, i)) = self.session(s.session)
        {
            return Some(i.next.clone());
        }
        self.only_instance().map(|i| i.next.clone())
    }

    /// For the action space of an eye-gaze action (XR_EXT_eye_gaze_interaction enabled):
    /// its session and its pose in the action space.
    pub fn gaze_space(&self, space: u64) -> Option<(u64, Pose)> {
        let s = self.spaces.get(&space)?;
        let (action, offset) = s.action?;
        let (_, i) = self.session(s.session)?;
        (i.owns(GazeExtension::Ext) && i.gaze_actions.contains(&action))
            .then_some((s.session, offset))
    }

    /// The instance, when exactly one exists.
    pub fn only_instance(&self) -> Option<&InstanceState> {
        let mut it = self.instances.values();
        match (it.next(), it.next()) {
            (Some(i), None) => Some(i),
            _ => None,
        }
    }

    /// Forgets a session and everything made from it.
    pub fn remove_session(&mut self, session: u64) -> Option<SessionState> {
        self.spaces.retain(|_, s| s.session != session);
        self.trackers.retain(|_, t| t.session != session);
        self.detectors.retain(|_, d| d.session != session);
        self.swapchains.retain(|_, c| c.session != session);
        let estimations = &mut self.estimations;
        estimations.retain(|_, e| e.session != session);
        self.estimates
            .retain(|_, e| estimations.contains_key(&e.estimation));
        self.sessions.remove(&session)
    }

    /// Forgets an instance and everything made from it.
    pub fn remove_instance(&mut self, instance: u64) {
        let sessions: Vec<u64> = self
            .sessions
            .iter()
            .filter(|(_, s)| s.instance == instance)
            .map(|(h, _)| *h)
            .collect();
        for s in sessions {
            self.remove_session(s);
        }
        self.instances.remove(&instance);
    }
}

/// The process's registry.
static REGISTRY: LazyLock<Mutex<Registry>> = LazyLock::new(|| Mutex::new(Registry::new()));

/// Locks the registry. A panic while it was held (caught at the entry point) does not make
/// it unusable: every update leaves it consistent before anything can panic.
pub fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_are_unique_and_non_zero() {
        let mut r = Registry::new();
        let a = r.new_handle();
        let b = r.new_handle();
        assert!(a != 0 && b != 0 && a != b);
        r.next_handle = u64::MAX;
        assert_eq!(r.new_handle(), u64::MAX);
        assert_ne!(r.new_handle(), 0);
    }
}
