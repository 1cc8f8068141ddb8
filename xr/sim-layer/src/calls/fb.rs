//! `XR_FB_eye_tracking_social`: a pose per eye in the base space asked for, from the trace's
//! eye rays composed with the runtime's head pose.

use openxr::sys::{self, Handle};

use super::{SessionContext, in_base};
use crate::config::GazeExtension;
use crate::eye_geometry::ray_pose;
use crate::guard::guard;
use crate::registry::registry;

/// The session context of an FB tracker the layer made.
fn tracker_context(tracker: sys::EyeTrackerFB) -> Option<SessionContext> {
    let reg = registry();
    let t = reg.trackers.get(&tracker.into_raw())?;
    if t.kind != GazeExtension::Fb {
        return None;
    }
    SessionContext::of(&reg, t.session)
}

/// `xrCreateEyeTrackerFB`.
///
/// # Safety
/// As `xrCreateEyeTrackerFB`.
pub unsafe extern "system" fn create_eye_tracker(
    session: sys::Session,
    info: *const sys::EyeTrackerCreateInfoFB,
    tracker: *mut sys::EyeTrackerFB,
) -> sys::Result {
    guard("xrCreateEyeTrackerFB", || {
        // SAFETY: the app's structures, null or valid.
        let (Some(info), Some(out)) = (unsafe { info.as_ref() }, unsafe { tracker.as_mut() })
        else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.ty != sys::EyeTrackerCreateInfoFB::TYPE {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(h) = registry().new_tracker(session.into_raw(), GazeExtension::Fb) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        *out = sys::EyeTrackerFB::from_raw(h);
        sys::Result::SUCCESS
    })
}

/// `xrDestroyEyeTrackerFB`.
///
/// # Safety
/// As `xrDestroyEyeTrackerFB`.
pub unsafe extern "system" fn destroy_eye_tracker(tracker: sys::EyeTrackerFB) -> sys::Result {
    guard("xrDestroyEyeTrackerFB", || {
        let mut reg = registry();
        match reg.trackers.get(&tracker.into_raw()) {
            Some(t) if t.kind == GazeExtension::Fb => {
                reg.trackers.remove(&tracker.into_raw());
                sys::Result::SUCCESS
            }
            _ => sys::Result::ERROR_HANDLE_INVALID,
        }
    })
}

/// `xrGetEyeGazesFB`: per eye, the pose at the eye origin looking along the gaze (-z), in
/// `baseSpace` at `time`; valid when the trace's ray is valid and the runtime locates the
/// base space; confidence 1 when valid (0.1 when the sample is reported LOW), else 0.
///
/// # Safety
/// As `xrGetEyeGazesFB`.
pub unsafe extern "system" fn get_eye_gazes(
    tracker: sys::EyeTrackerFB,
    info: *const sys::EyeGazesInfoFB,
    gazes: *mut sys::EyeGazesFB,
) -> sys::Result {
    guard("xrGetEyeGazesFB", || {
        let Some(ctx) = tracker_context(tracker) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structures, null or valid.
        let (Some(info), Some(out)) = (unsafe { info.as_ref() }, unsafe { gazes.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.ty != sys::EyeGazesInfoFB::TYPE || out.ty != sys::EyeGazesFB::TYPE {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(sample) = ctx.gaze_at(info.time.as_nanos()) else {
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        let head = ctx.head_to_base(info.base_space, info.time);
        for (slot, ray) in out.gaze.iter_mut().zip([&sample.left, &sample.right]) {
            match (&head, ray.valid) {
                (Some((view_in_base, _)), true) => {
                    slot.is_valid = sys::TRUE;
                    slot.gaze_pose = in_base(view_in_base, &ray_pose(ray));
                    // A tracker unsure of the sample (a LOW report) says so here too.
                    let low = sample
                        .report
                        .is_some_and(|r| r.confidence == vitreous_trace::TrackerConfidence::Low);
                    slot.gaze_confidence = if low { 0.1 } else { 1.0 };
                }
                _ => {
                    slot.is_valid = sys::FALSE;
                    slot.gaze_pose = sys::Posef::IDENTITY;
                    slot.gaze_confidence = 0.0;
                }
            }
        }
        out.time = sys::Time::from_nanos(sample.sample_time_ns);
        sys::Result::SUCCESS
    })
}
