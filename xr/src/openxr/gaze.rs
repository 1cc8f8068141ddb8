//! Gaze sources of a live session: XR_ML_eye_tracker (per-eye poses, fixation point, pupil
//! diameters, the tracker's report; its raw calls in [`super::ml_tracker`]),
//! XR_FB_eye_tracking_social (per-eye poses), XR_EXT_eye_gaze_interaction (a combined ray with
//! its sample time), a recorded trace replayed by time since the session's first frame, or none
//! (manual). All give rays in the head (VIEW) frame, as [`GazeSample`] wants.
//!
//! The combined EXT ray has no depth, so it cannot drive the gaze image: with it, the frame's
//! per-eye gaze comes from the trace (when one is given; else there is none and the gaze image
//! is chosen by hand), and the EXT ray is carried as the sample's combined ray, so a recording
//! holds exactly what decided each frame.

use std::path::Path;

use openxr as xr;
use vitreous_trace::format::{TraceSample, read_trace};
use vitreous_trace::{GazeRay, GazeSample};

use super::choose::GazeSource;
use super::convert::ray_of;
use super::ml_tracker::MlTracker;
use super::{OpenXrError, Result, XrContext};

/// A gaze source, ready to sample.
pub(super) enum Gaze {
    /// Per-eye, fixation and pupil data from a Magic Leap eye tracker.
    MlEyeTracker(MlTracker),
    /// Per-eye poses from an FB eye tracker.
    FbSocial(FbTracker),
    /// The combined ray of the eye-gaze interaction profile, and the trace whose per-eye gaze
    /// decides the gaze image (none: decided by hand).
    Combined(ExtGaze, Option<TraceGaze>),
    /// A trace's gaze by elapsed time.
    Trace(TraceGaze),
    /// No gaze.
    Manual,
}

/// What one frame's gaze sampling gave.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Sampled {
    /// The frame's gaze (what the look planner and a recording get).
    pub(super) frame: Option<GazeSample>,
    /// The sample time of the source's own sample, when it gave one (for EXT: the runtime's
    /// combined ray, even when the frame's gaze comes from the trace).
    pub(super) source_time_ns: Option<i64>,
}

impl Gaze {
    /// Which source this is.
    pub(super) fn source(&self) -> GazeSource {
        match self {
            Gaze::MlEyeTracker(_) => GazeSource::MlEyeTracker,
            Gaze::FbSocial(_) => GazeSource::FbSocial,
            Gaze::Combined(..) => GazeSource::ExtGaze,
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
    ) -> Sampled {
        let own = |g: Option<GazeSample>| Sampled {
            frame: g,
            source_time_ns: g.map(|g| g.sample_time_ns),
        };
        match self {
            Gaze::MlEyeTracker(t) => own(t.sample(view_space, display)),
            Gaze::FbSocial(t) => own(t.sample(view_space, display)),
            Gaze::Combined(g, trace) => {
                let ext = g.sample(session, view_space, display);
                let decided = trace
                    .as_mut()
                    .and_then(|t| t.sample(display.as_nanos(), first_display.as_nanos()));
                Sampled {
                    frame: with_combined(decided, ext),
                    source_time_ns: ext.map(|e| e.sample_time_ns),
                }
            }
            Gaze::Trace(t) => own(t.sample(display.as_nanos(), first_display.as_nanos())),
            Gaze::Manual => Sampled::default(),
        }
    }
}

/// The frame's gaze with the EXT source: the trace's sample (its per-eye rays decide) carrying
/// the runtime's combined ray; without a trace, the runtime's sample alone (no per-eye rays,
/// so no decision).
fn with_combined(decided: Option<GazeSample>, ext: Option<GazeSample>) -> Option<GazeSample> {
    match (decided, ext) {
        (Some(mut d), Some(e)) => {
            d.combined = e.combined;
            Some(d)
        }
        (Some(d), None) => Some(d),
        (None, e) => e,
    }
}

/// How many gaze samples the source gave and how many frames saw a new one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GazeTally {
    /// Frames the source was asked for a sample.
    pub frames: u64,
    /// Frames it gave one (new or not).
    pub received: u64,
    /// Frames whose sample was newer than every earlier frame's: a fresh sample.
    pub fresh: u64,
    /// Frames whose sample was stamped before one already used, given that one again
    /// ([`super::GazeOrder`]).
    pub out_of_order: u64,
    /// Frames whose new sample was stamped after the frame's display time: given the frame
    /// stamped at its display time ([`super::GazeOrder`]).
    pub after_display: u64,
    /// The most a sample was stamped after its frame's display time, nanoseconds.
    pub max_ahead_ns: i64,
    /// The newest sample time seen, nanoseconds.
    newest_ns: Option<i64>,
}

impl GazeTally {
    /// Adds a later session's tally.
    pub(super) fn add(&mut self, later: &GazeTally) {
        self.frames += later.frames;
        self.received += later.received;
        self.fresh += later.fresh;
        self.out_of_order += later.out_of_order;
        self.after_display += later.after_display;
        self.max_ahead_ns = self.max_ahead_ns.max(later.max_ahead_ns);
        self.newest_ns = later.newest_ns.max(self.newest_ns);
    }

    /// Counts one frame's sampling.
    pub(super) fn count(&mut self, sampled: &Sampled) {
        self.frames += 1;
        let Some(t) = sampled.source_time_ns else {
            return;
        };
        self.received += 1;
        if self.newest_ns.is_none_or(|n| t > n) {
            self.fresh += 1;
            self.newest_ns = Some(t);
        }
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
        Some(GazeSample::binocular(
            gazes.time.as_nanos(),
            eye(&gazes.gaze[0]),
            eye(&gazes.gaze[1]),
        ))
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
            combined: Some(combined),
            ..GazeSample::none(sample_time.time.as_nanos())
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

    /// The gaze of the newest line at or before the trace's start plus the time since the first
    /// frame (the last one once the trace is over; what the recorder knew then, as the null
    /// backend replays it), with its sample time moved onto the runtime's clock.
    pub(super) fn sample(&mut self, display_ns: i64, first_display_ns: i64) -> Option<GazeSample> {
        let t0 = self.samples[0].time_ns;
        let t = t0 + (display_ns - first_display_ns).max(0);
        while self.cursor + 1 < self.samples.len() && self.samples[self.cursor + 1].time_ns <= t {
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
    use glam::Vec3;
    use vitreous_trace::Pose;

    fn sample(time_ns: i64, gaze_ns: i64, x: f32) -> TraceSample {
        let ray = GazeRay {
            origin: Vec3::new(x, 0.0, 0.0),
            direction: Vec3::NEG_Z,
            valid: true,
        };
        TraceSample {
            time_ns,
            head: Pose::IDENTITY,
            gaze: GazeSample::binocular(gaze_ns, ray, ray),
        }
    }

    #[test]
    fn fresh_samples_are_those_newer_than_any_before() {
        let mut t = GazeTally::default();
        let at = |ns: Option<i64>| Sampled {
            frame: None,
            source_time_ns: ns,
        };
        for ns in [Some(10), Some(10), None, Some(20), Some(15), Some(30)] {
            t.count(&at(ns));
        }
        assert_eq!((t.frames, t.received, t.fresh), (6, 5, 3));
    }

    #[test]
    fn the_combined_ray_rides_on_the_traces_per_eye_gaze() {
        let trace = sample(0, 100, 1.0).gaze;
        let combined = GazeRay {
            origin: Vec3::ZERO,
            direction: Vec3::X,
            valid: true,
        };
        let ext = GazeSample {
            combined: Some(combined),
            ..GazeSample::none(7)
        };
        let merged = with_combined(Some(trace), Some(ext)).unwrap();
        assert_eq!((merged.left, merged.right), (trace.left, trace.right));
        assert_eq!(merged.sample_time_ns, 100);
        assert_eq!(merged.combined, Some(combined));
        // Without a trace the runtime's ray alone: no per-eye gaze, nothing decided.
        let alone = with_combined(None, Some(ext)).unwrap();
        assert!(!alone.left.valid && !alone.right.valid);
        assert_eq!(with_combined(Some(trace), None), Some(trace));
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
        // At trace time 2 600 the newest line is at 2 000: the sample stamped 2 500 was written
        // at 3 000 (the recorder had it then), so it is not yet the gaze.
        let s = g.sample(first + 1_600, first).unwrap();
        assert_eq!((s.left.origin.x, s.sample_time_ns), (1.0, first + 1_000));
        let s = g.sample(first + 2_000, first).unwrap();
        assert_eq!((s.left.origin.x, s.sample_time_ns), (2.0, first + 1_500));
        // Past the end the last sample holds.
        let s = g.sample(first + 10_000, first).unwrap();
        assert_eq!(s.left.origin.x, 2.0);
    }
}
