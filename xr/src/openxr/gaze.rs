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
    /// ([`GazeOrder`]).
    pub out_of_order: u64,
    /// Frames whose new sample was stamped after the frame's display time: given the frame
    /// stamped at its display time ([`GazeOrder`]).
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

/// The frames' gaze in time order, never stamped after its frame.
///
/// A runtime may hand out a sample stamped before one the app already used: a tracker that
/// stamped a blink with the display time and then stalls on an older sample, a clock that went
/// back. Such a sample is not new; the frame gets the newest sample used so far again instead,
/// as a tracker with no new sample answers, so the gaze filters and the recording (whose gaze
/// times must not decrease) only see time go forward.
///
/// A runtime may also stamp a new sample after the display time the frame asked it for: an eye
/// tracker whose clock runs ahead of the runtime's. It is the newest the tracker has, so the
/// frame uses it, stamped at the frame's display time (a frame's gaze is what was known when it
/// was shown; a recording's line pairs a pose with the gaze at or before it); the same sample
/// handed out again keeps that stamp, and later samples are ordered by the runtime's stamps.
///
/// It carries over to the next session after a loss ([`super::Continued`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GazeOrder {
    /// The newest sample handed to a frame, as handed.
    newest: Option<GazeSample>,
    /// The runtime's stamp of that sample (later than `newest`'s when it was stamped ahead).
    newest_runtime_ns: Option<i64>,
}

/// The gaze a frame gets ([`GazeOrder::order`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ordered {
    /// The sample, stamped no later than the frame's display time.
    pub gaze: Option<GazeSample>,
    /// Stamped before one already used: the newest was given again instead.
    pub out_of_order: bool,
    /// A new sample stamped this long after the frame's display time, nanoseconds (restamped).
    pub ahead_ns: Option<i64>,
}

impl GazeOrder {
    /// The newest sample handed to a frame so far.
    pub fn newest(&self) -> Option<GazeSample> {
        self.newest
    }

    /// The gaze a frame displayed at `display_ns` gets for the runtime's `gaze`.
    pub fn order(&mut self, gaze: Option<GazeSample>, display_ns: i64) -> Ordered {
        let ordered = |gaze, out_of_order, ahead_ns| Ordered {
            gaze,
            out_of_order,
            ahead_ns,
        };
        let Some(mut g) = gaze else {
            return ordered(None, false, None);
        };
        let stamped = g.sample_time_ns;
        match (self.newest, self.newest_runtime_ns) {
            (Some(n), Some(runtime_ns)) if stamped < runtime_ns => {
                return ordered(Some(n), true, None);
            }
            (Some(n), Some(runtime_ns)) if stamped == runtime_ns => {
                g.sample_time_ns = n.sample_time_ns;
                self.newest = Some(g);
                return ordered(Some(g), false, None);
            }
            _ => {}
        }
        let ahead_ns = (stamped > display_ns).then(|| stamped - display_ns);
        if ahead_ns.is_some() {
            let floor = self.newest.map_or(i64::MIN, |n| n.sample_time_ns);
            g.sample_time_ns = display_ns.max(floor);
        }
        self.newest = Some(g);
        self.newest_runtime_ns = Some(stamped);
        ordered(Some(g), false, ahead_ns)
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

    /// Orders `gaze` for a frame at `display_ns`: (the frame's gaze, out of order, ahead).
    fn order_at(
        order: &mut GazeOrder,
        gaze: Option<GazeSample>,
        display_ns: i64,
    ) -> (Option<GazeSample>, bool, Option<i64>) {
        let o = order.order(gaze, display_ns);
        (o.gaze, o.out_of_order, o.ahead_ns)
    }

    #[test]
    fn a_sample_older_than_one_used_gives_the_newest_again() {
        let at = |ns: i64, x: f32| sample(ns, ns, x).gaze;
        let mut order = GazeOrder::default();
        assert_eq!(
            order_at(&mut order, Some(at(40, 0.1)), 45),
            (Some(at(40, 0.1)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(50, 0.2)), 60),
            (Some(at(50, 0.2)), false, None)
        );
        // A blink stamped with the display time (100), then a stalled tracker's older sample.
        assert_eq!(
            order_at(&mut order, Some(at(100, 0.0)), 100),
            (Some(at(100, 0.0)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(53, 0.3)), 110),
            (Some(at(100, 0.0)), true, None)
        );
        // The same time again is not out of order; no sample stays none.
        assert_eq!(
            order_at(&mut order, Some(at(100, 0.4)), 120),
            (Some(at(100, 0.4)), false, None)
        );
        assert_eq!(order_at(&mut order, None, 130), (None, false, None));
        assert_eq!(order.newest(), Some(at(100, 0.4)));
        // Carried over a loss: the next session's first sample is held against it.
        let mut next = order;
        assert_eq!(
            order_at(&mut next, Some(at(90, 0.5)), 140),
            (Some(at(100, 0.4)), true, None)
        );
    }

    #[test]
    fn a_sample_stamped_after_its_frame_is_used_at_the_frame_time() {
        let at = |ns: i64, x: f32| sample(ns, ns, x).gaze;
        let mut order = GazeOrder::default();
        assert_eq!(
            order_at(&mut order, Some(at(90, 0.1)), 100),
            (Some(at(90, 0.1)), false, None)
        );
        // A tracker's clock 30 ahead: the new sample is the frame's, stamped at its time.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 110),
            (Some(at(110, 0.2)), false, Some(30))
        );
        // The same sample again keeps that stamp, ahead of the next frame or not.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 120),
            (Some(at(110, 0.2)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 150),
            (Some(at(110, 0.2)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(160, 0.3)), 130),
            (Some(at(130, 0.3)), false, Some(30))
        );
        // The clock back in step: samples stamped before the runtime's newest stamp are old.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.4)), 140),
            (Some(at(130, 0.3)), true, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(170, 0.5)), 170),
            (Some(at(170, 0.5)), false, None)
        );
        // A restamp never goes back before a sample handed out earlier.
        let mut order = GazeOrder::default();
        order.order(Some(at(100, 0.1)), 100);
        assert_eq!(
            order_at(&mut order, Some(at(200, 0.2)), 100),
            (Some(at(100, 0.2)), false, Some(100))
        );
        // Every frame's gaze is stamped at or before its display time.
        let mut order = GazeOrder::default();
        let mut newest = i64::MIN;
        for (display, stamp) in [
            (10, 5),
            (20, 45),
            (30, 45),
            (40, 35),
            (50, 75),
            (60, 55),
            (70, 70),
        ] {
            let g = order.order(Some(at(stamp, 0.0)), display).gaze.unwrap();
            assert!(
                g.sample_time_ns <= display && g.sample_time_ns >= newest,
                "{display} {stamp}"
            );
            newest = g.sample_time_ns;
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
