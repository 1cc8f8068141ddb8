//! Gaze sources of a live session: XR_FB_eye_tracking_social (per-eye poses),
//! XR_EXT_eye_gaze_interaction (a combined ray with its sample time), a recorded trace replayed
//! by time since the session's first frame, or none (manual). All give rays in the head (VIEW)
//! frame, as [`GazeSample`] wants.

use std::path::Path;

use glam::{Quat, Vec3};
use openxr as xr;

use super::choose::GazeSource;
use super::{OpenXrError, Result, XrContext};
use crate::frame::{GazeRay, GazeSample};
use crate::trace::{TraceSample, read_trace};

/// A gaze source, ready to sample.
pub(super) enum Gaze {
    /// Per-eye poses from an FB eye tracker.
    FbSocial(FbTracker),
    /// The combined ray of the eye-gaze interaction profile.
    ExtGaze(ExtGaze),
    /// A trace's gaze by elapsed time.
    Trace(TraceGaze),
    /// No gaze.
    Manual,
}

impl Gaze {
    /// Which source this is.
    pub(super) fn source(&self) -> GazeSource {
        match self {
            Gaze::FbSocial(_) => GazeSource::FbSocial,
            Gaze::ExtGaze(_) => GazeSource::ExtGaze,
            Gaze::Trace(_) => GazeSource::Trace,
            Gaze::Manual => GazeSource::Manual,
        }
    }

    /// The newest gaze sample for a frame displayed at `display`, rays in `view_space` (the
    /// head frame). `first_display` is the display time of the session's first frame.
    pub(super) fn sample(
        &mut self,
        session: &xr::Session<xr::Vulkan>,
        view_space: &xr::Space,
        display: xr::Time,
        first_display: xr::Time,
    ) -> Option<GazeSample> {
        match self {
            Gaze::FbSocial(t) => t.sample(view_space, display),
            Gaze::ExtGaze(g) => g.sample(session, view_space, display),
            Gaze::Trace(t) => t.sample(display.as_nanos(), first_display.as_nanos()),
            Gaze::Manual => None,
        }
    }
}

/// A ray along a pose's forward axis (-z).
fn ray_of(pose: &xr::Posef) -> GazeRay {
    let q = Quat::from_xyzw(
        pose.orientation.x,
        pose.orientation.y,
        pose.orientation.z,
        pose.orientation.w,
    );
    GazeRay {
        origin: Vec3::new(pose.position.x, pose.position.y, pose.position.z),
        direction: (q * Vec3::NEG_Z).normalize_or(Vec3::NEG_Z),
        valid: true,
    }
}

/// An XR_FB_eye_tracking_social tracker.
pub(super) struct FbTracker {
    /// The instance, for its function pointers.
    instance: xr::Instance,
    /// The tracker handle; destroyed on drop.
    tracker: xr::sys::EyeTrackerFB,
}

impl FbTracker {
    /// Creates the tracker.
    pub(super) fn new(session: &xr::Session<xr::Vulkan>) -> Result<FbTracker> {
        let instance = session.instance().clone();
        let fp = instance.exts().fb_eye_tracking_social.ok_or_else(|| {
            OpenXrError::Unsupported("XR_FB_eye_tracking_social is not enabled".into())
        })?;
        let info = xr::sys::EyeTrackerCreateInfoFB {
            ty: xr::sys::EyeTrackerCreateInfoFB::TYPE,
            next: std::ptr::null(),
        };
        let mut tracker = <xr::sys::EyeTrackerFB as xr::sys::Handle>::NULL;
        // SAFETY: `fp` was loaded from this session's instance with the extension enabled;
        // `info` and `tracker` are valid for the call.
        let r = unsafe { (fp.create_eye_tracker)(session.as_raw(), &info, &mut tracker) };
        if r != xr::sys::Result::SUCCESS {
            return Err(r).xr("xrCreateEyeTrackerFB");
        }
        Ok(FbTracker { instance, tracker })
    }

    fn sample(&mut self, view_space: &xr::Space, display: xr::Time) -> Option<GazeSample> {
        let fp = self.instance.exts().fb_eye_tracking_social?;
        let info = xr::sys::EyeGazesInfoFB {
            ty: xr::sys::EyeGazesInfoFB::TYPE,
            next: std::ptr::null(),
            base_space: view_space.as_raw(),
            time: display,
        };
        // SAFETY: EyeGazesFB is plain data; zeroed then typed is its valid output state.
        let mut gazes: xr::sys::EyeGazesFB = unsafe { std::mem::zeroed() };
        gazes.ty = xr::sys::EyeGazesFB::TYPE;
        // SAFETY: `self.tracker` is live until drop; `info` and `gazes` are valid, typed
        // structs that outlive the call.
        let r = unsafe { (fp.get_eye_gazes)(self.tracker, &info, &mut gazes) };
        if r != xr::sys::Result::SUCCESS {
            return None;
        }
        let eye = |g: &xr::sys::EyeGazeFB| {
            if g.is_valid == xr::sys::TRUE {
                ray_of(&g.gaze_pose)
            } else {
                GazeRay::INVALID
            }
        };
        Some(GazeSample {
            sample_time_ns: gazes.time.as_nanos(),
            left: eye(&gazes.gaze[0]),
            right: eye(&gazes.gaze[1]),
            combined: None,
            fixation: None,
            pupil_diameter_m: [None, None],
        })
    }
}

impl Drop for FbTracker {
    fn drop(&mut self) {
        if let Some(fp) = self.instance.exts().fb_eye_tracking_social {
            // SAFETY: the tracker was created by this instance's function table and is not
            // used after this drop.
            unsafe { (fp.destroy_eye_tracker)(self.tracker) };
        }
    }
}

/// The XR_EXT_eye_gaze_interaction pose action and its space.
pub(super) struct ExtGaze {
    /// The action set holding the gaze action (attached by the session).
    pub(super) set: xr::ActionSet,
    /// The gaze pose action.
    #[allow(dead_code)]
    action: xr::Action<xr::Posef>,
    /// Space of the gaze pose.
    space: xr::Space,
}

impl ExtGaze {
    /// Creates the action, suggests its binding and makes its space. The caller attaches
    /// [`ExtGaze::set`] with the session's other action sets.
    pub(super) fn new(session: &xr::Session<xr::Vulkan>) -> Result<ExtGaze> {
        let instance = session.instance();
        let set = instance
            .create_action_set("vitreous_gaze", "vitreous eye gaze", 0)
            .xr("xrCreateActionSet")?;
        let action = set
            .create_action::<xr::Posef>("eye_gaze", "Eye gaze", &[])
            .xr("xrCreateAction")?;
        let profile = instance
            .string_to_path("/interaction_profiles/ext/eye_gaze_interaction")
            .xr("xrStringToPath")?;
        let binding = instance
            .string_to_path("/user/eyes_ext/input/gaze_ext/pose")
            .xr("xrStringToPath")?;
        instance
            .suggest_interaction_profile_bindings(profile, &[xr::Binding::new(&action, binding)])
            .xr("xrSuggestInteractionProfileBindings")?;
        let space = action
            .create_space(session, xr::Path::NULL, xr::Posef::IDENTITY)
            .xr("xrCreateActionSpace")?;
        Ok(ExtGaze { set, action, space })
    }

    fn sample(
        &mut self,
        session: &xr::Session<xr::Vulkan>,
        view_space: &xr::Space,
        display: xr::Time,
    ) -> Option<GazeSample> {
        let fp = session.instance().fp();
        let mut sample_time = xr::sys::EyeGazeSampleTimeEXT {
            ty: xr::sys::EyeGazeSampleTimeEXT::TYPE,
            next: std::ptr::null_mut(),
            time: display,
        };
        // SAFETY: SpaceLocation is plain data; the chained sample-time struct lives across
        // the call. The raw call is used because the safe one cannot chain it.
        let mut location: xr::sys::SpaceLocation = unsafe { std::mem::zeroed() };
        location.ty = xr::sys::SpaceLocation::TYPE;
        location.next = &mut sample_time as *mut _ as *mut _;
        // SAFETY: see above: the spaces are live, `location` and its chain outlive the call.
        let r = unsafe {
            (fp.locate_space)(
                self.space.as_raw(),
                view_space.as_raw(),
                display,
                &mut location,
            )
        };
        if r != xr::sys::Result::SUCCESS {
            return None;
        }
        let tracked = location.location_flags.contains(
            xr::SpaceLocationFlags::ORIENTATION_VALID | xr::SpaceLocationFlags::POSITION_VALID,
        );
        let combined = if tracked {
            ray_of(&location.pose)
        } else {
            GazeRay::INVALID
        };
        Some(GazeSample {
            sample_time_ns: sample_time.time.as_nanos(),
            left: GazeRay::INVALID,
            right: GazeRay::INVALID,
            combined: Some(combined),
            fixation: None,
            pupil_diameter_m: [None, None],
        })
    }
}

/// Gaze replayed from a recorded trace by time since the first frame.
pub(super) struct TraceGaze {
    /// The trace's samples.
    samples: Vec<TraceSample>,
    /// Index of the newest sample used so far.
    cursor: usize,
}

impl TraceGaze {
    /// Reads the trace.
    pub(super) fn open(path: &Path) -> Result<TraceGaze> {
        let samples = read_trace(path)?;
        if samples.is_empty() {
            return Err(OpenXrError::Unsupported(format!(
                "gaze trace {} has no samples",
                path.display()
            )));
        }
        Ok(TraceGaze { samples, cursor: 0 })
    }

    /// The newest gaze whose trace time is at or before the trace's start plus the time since
    /// the first frame (the last one once the trace is over), with its sample time moved onto
    /// the runtime's clock.
    pub(super) fn sample(&mut self, display_ns: i64, first_display_ns: i64) -> Option<GazeSample> {
        let t0 = self.samples[0].time_ns;
        let t = t0 + (display_ns - first_display_ns).max(0);
        while self.cursor + 1 < self.samples.len()
            && self.samples[self.cursor + 1].gaze.sample_time_ns <= t
        {
            self.cursor += 1;
        }
        let gaze = self.samples[self.cursor].gaze;
        if gaze.sample_time_ns > t {
            return None;
        }
        let mut gaze = gaze;
        gaze.sample_time_ns = gaze.sample_time_ns - t0 + first_display_ns;
        Some(gaze)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Pose;

    fn sample(time_ns: i64, gaze_ns: i64, x: f32) -> TraceSample {
        let ray = GazeRay {
            origin: Vec3::new(x, 0.0, 0.0),
            direction: Vec3::NEG_Z,
            valid: true,
        };
        TraceSample {
            time_ns,
            head: Pose::IDENTITY,
            gaze: GazeSample {
                sample_time_ns: gaze_ns,
                left: ray,
                right: ray,
                combined: None,
                fixation: None,
                pupil_diameter_m: [None, None],
            },
        }
    }

    #[test]
    fn trace_gaze_follows_elapsed_time_on_the_runtime_clock() {
        let mut g = TraceGaze {
            samples: vec![
                sample(1_000, 1_000, 0.0),
                sample(2_000, 2_000, 1.0),
                sample(3_000, 2_500, 2.0),
            ],
            cursor: 0,
        };
        let first = 50_000;
        let s = g.sample(first, first).unwrap();
        assert_eq!((s.left.origin.x, s.sample_time_ns), (0.0, first));
        let s = g.sample(first + 1_600, first).unwrap();
        assert_eq!((s.left.origin.x, s.sample_time_ns), (2.0, first + 1_500));
        // Past the end the last sample holds.
        let s = g.sample(first + 10_000, first).unwrap();
        assert_eq!(s.left.origin.x, 2.0);
    }
}
