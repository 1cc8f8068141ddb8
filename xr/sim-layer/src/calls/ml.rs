//! `XR_ML_eye_tracker` (Magic Leap 2): combined, per-eye and fixation poses with confidence,
//! pupil diameters, gaze behaviour, and the simplest honest answers for what a trace does not
//! hold.
//!
//! - Fixation pose: its position is the vergence point (the trace's fixation column when
//!   present, else the closest point between the two eye rays), its -z axis looks there from
//!   the mid-point of the eyes; HIGH confidence with both eyes valid, else LOW, or the
//!   confidence of the trace's own report (trace v1.3) when the sample carries one.
//! - Pupil data: the trace's per-eye pupil diameter, else `valid = FALSE`.
//! - Geometric data: openness 1 for a valid eye ray, 0 otherwise; the eye-in-skull position
//!   is not simulated (0, 0).
//! - Gaze behaviour: the trace's own report (v1.3) where a sample carries one, else the layer's
//!   stand-in classifier ([`crate::behaviour`]: blink while no eye is valid, eyes closed after
//!   500 ms of it, else saccade above 30 deg/s, pursuit from 5 deg/s, fixation below, from the
//!   gaze's angular velocity between trace samples; not Magic Leap's classifier); onset when
//!   the behaviour began, duration since. `valid = FALSE` (type UNKNOWN) only without a trace.
//! - Static data: a maximum eye width and height of 1 (the layer's openness is already 0..1).
//!
//! The calls without a time (pupil, geometric, behaviour) answer for the display time of the
//! session's newest frame.

use openxr::sys::{self, Handle};
use vitreous_trace::{GazeBehaviour, GazeRay, GazeSample, Pose, TrackerConfidence};
use vitreous_xr::openxr::ml_eye_tracker::{
    ConfidenceML, EyeML, EyeTrackerCreateInfoML, EyeTrackerGazeBehaviorML,
    EyeTrackerGeometricDataML, EyeTrackerGetInfoML, EyeTrackerML, EyeTrackerPoseML,
    EyeTrackerPosesGetInfoML, EyeTrackerPosesML, EyeTrackerPupilDataML, EyeTrackerStaticDataML,
    GazeBehaviorTypeML, pose_flags, structure_type,
};

use super::{SessionContext, in_base};
use crate::config::GazeExtension;
use crate::eye_geometry::{combined_ray, fixation_point, pose_along, ray_pose};
use crate::guard::guard;
use crate::registry::registry;
use crate::two_call;

/// The session context of an ML tracker the layer made.
fn tracker_context(tracker: EyeTrackerML) -> Option<SessionContext> {
    let reg = registry();
    let t = reg.trackers.get(&tracker.0)?;
    if t.kind != GazeExtension::Ml {
        return None;
    }
    SessionContext::of(&reg, t.session)
}

/// Whether a structure pointer is non-null and of raw type `raw`.
///
/// # Safety
/// `ty` must be null or point to a structure's readable `type` field.
unsafe fn typed(ty: *const sys::StructureType, raw: i32) -> bool {
    // SAFETY: guaranteed by the caller.
    unsafe { ty.as_ref() }.is_some_and(|t| structure_type::is(*t, raw))
}

/// `xrCreateEyeTrackerML`.
///
/// # Safety
/// As `xrCreateEyeTrackerML`.
pub unsafe extern "system" fn create_eye_tracker(
    session: sys::Session,
    info: *const EyeTrackerCreateInfoML,
    tracker: *mut EyeTrackerML,
) -> sys::Result {
    guard("xrCreateEyeTrackerML", || {
        // SAFETY: the app's create info, null or valid; `type` is its first field.
        if !unsafe { typed(info.cast(), structure_type::CREATE_INFO) } {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: the app's output, null or valid.
        let Some(out) = (unsafe { tracker.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let Some(h) = registry().new_tracker(session.into_raw(), GazeExtension::Ml) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        *out = EyeTrackerML(h);
        sys::Result::SUCCESS
    })
}

/// `xrDestroyEyeTrackerML`.
///
/// # Safety
/// As `xrDestroyEyeTrackerML`.
pub unsafe extern "system" fn destroy_eye_tracker(tracker: EyeTrackerML) -> sys::Result {
    guard("xrDestroyEyeTrackerML", || {
        let mut reg = registry();
        match reg.trackers.get(&tracker.0) {
            Some(t) if t.kind == GazeExtension::Ml => {
                reg.trackers.remove(&tracker.0);
                sys::Result::SUCCESS
            }
            _ => sys::Result::ERROR_HANDLE_INVALID,
        }
    })
}

/// `xrGetEyeTrackerStaticDataML`.
///
/// # Safety
/// As `xrGetEyeTrackerStaticDataML`.
pub unsafe extern "system" fn get_static_data(
    tracker: EyeTrackerML,
    info: *const EyeTrackerGetInfoML,
    data: *mut EyeTrackerStaticDataML,
) -> sys::Result {
    guard("xrGetEyeTrackerStaticDataML", || {
        if tracker_context(tracker).is_none() {
            return sys::Result::ERROR_HANDLE_INVALID;
        }
        // SAFETY: the app's structures, null or valid; `type` is their first field.
        let ok = unsafe {
            typed(info.cast(), structure_type::STATIC_DATA_GET_INFO)
                && typed(data.cast(), structure_type::STATIC_DATA)
        };
        if !ok {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: checked non-null and typed above.
        let out = unsafe { &mut *data };
        out.eye_width_max = 1.0;
        out.eye_height_max = 1.0;
        sys::Result::SUCCESS
    })
}

/// The four poses of a sample in the head frame, with validity and confidence:
/// gaze, left, right, fixation (its confidence the sample's report's when it has one).
pub fn head_frame_poses(sample: &GazeSample) -> [(Option<Pose>, ConfidenceML); 4] {
    let both = sample.left.valid && sample.right.valid;
    let either = sample.left.valid || sample.right.valid;
    let eye = |r: &GazeRay| {
        if r.valid {
            (Some(ray_pose(r)), ConfidenceML::HIGH)
        } else {
            (None, ConfidenceML::LOW)
        }
    };
    let combined = combined_ray(sample);
    let gaze = if combined.valid {
        let confidence = if both || (sample.combined.is_some() && !either) {
            ConfidenceML::HIGH
        } else {
            ConfidenceML::MEDIUM
        };
        (Some(ray_pose(&combined)), confidence)
    } else {
        (None, ConfidenceML::LOW)
    };
    let fixation = match fixation_point(sample) {
        Some(point) => {
            // Look at the point from between the eyes (or the combined origin).
            let from = if both {
                (sample.left.origin + sample.right.origin) * 0.5
            } else {
                combined.origin
            };
            let mut pose = pose_along(from, point - from);
            pose.position = point;
            let confidence = match sample.report {
                Some(report) => confidence_ml(report.confidence),
                None if both => ConfidenceML::HIGH,
                None => ConfidenceML::LOW,
            };
            (Some(pose), confidence)
        }
        None => (None, ConfidenceML::LOW),
    };
    [gaze, eye(&sample.left), eye(&sample.right), fixation]
}

/// The extension's value of a confidence.
fn confidence_ml(confidence: TrackerConfidence) -> ConfidenceML {
    match confidence {
        TrackerConfidence::Low => ConfidenceML::LOW,
        TrackerConfidence::Medium => ConfidenceML::MEDIUM,
        TrackerConfidence::High => ConfidenceML::HIGH,
    }
}

/// The extension's type of a gaze behaviour.
fn behaviour_type_ml(behaviour: GazeBehaviour) -> GazeBehaviorTypeML {
    match behaviour {
        GazeBehaviour::Unknown => GazeBehaviorTypeML::UNKNOWN,
        GazeBehaviour::EyesClosed => GazeBehaviorTypeML::EYES_CLOSED,
        GazeBehaviour::Blink => GazeBehaviorTypeML::BLINK,
        GazeBehaviour::Fixation => GazeBehaviorTypeML::FIXATION,
        GazeBehaviour::Pursuit => GazeBehaviorTypeML::PURSUIT,
        GazeBehaviour::Saccade => GazeBehaviorTypeML::SACCADE,
    }
}

/// `xrGetEyeTrackerPosesML`: the requested poses in `baseSpace` at `time`.
///
/// # Safety
/// As `xrGetEyeTrackerPosesML`.
pub unsafe extern "system" fn get_poses(
    tracker: EyeTrackerML,
    info: *const EyeTrackerPosesGetInfoML,
    poses: *mut EyeTrackerPosesML,
) -> sys::Result {
    guard("xrGetEyeTrackerPosesML", || {
        let Some(ctx) = tracker_context(tracker) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structures, null or valid; `type` is their first field.
        let ok = unsafe {
            typed(info.cast(), structure_type::POSES_GET_INFO)
                && typed(poses.cast(), structure_type::POSES)
        };
        if !ok {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: checked non-null and typed above.
        let (info, out) = unsafe { (&*info, &mut *poses) };
        let Some(sample) = ctx.gaze_at(info.time.as_nanos()) else {
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        let head = ctx.head_to_base(info.base_space, info.time);
        let wanted = [
            pose_flags::GAZE,
            pose_flags::LEFT,
            pose_flags::RIGHT,
            pose_flags::FIXATION,
        ];
        let slots: [&mut EyeTrackerPoseML; 4] = [
            &mut out.gaze_pose,
            &mut out.left_pose,
            &mut out.right_pose,
            &mut out.fixation_pose,
        ];
        let time = sys::Time::from_nanos(sample.sample_time_ns);
        for ((slot, (pose, confidence)), flag) in
            slots.into_iter().zip(head_frame_poses(&sample)).zip(wanted)
        {
            slot.time = time;
            match (info.pose_flags & flag != 0, pose, &head) {
                (true, Some(pose), Some((view_in_base, _))) => {
                    slot.valid = sys::TRUE;
                    slot.pose = in_base(view_in_base, &pose);
                    slot.confidence = confidence;
                }
                _ => {
                    slot.valid = sys::FALSE;
                    slot.pose = sys::Posef::IDENTITY;
                    slot.confidence = ConfidenceML::LOW;
                }
            }
        }
        sys::Result::SUCCESS
    })
}

/// `xrGetEyeTrackerPupilDataML` (two-call idiom, left then right).
///
/// # Safety
/// As `xrGetEyeTrackerPupilDataML`.
pub unsafe extern "system" fn get_pupil_data(
    tracker: EyeTrackerML,
    info: *const EyeTrackerGetInfoML,
    capacity: u32,
    count: *mut u32,
    data: *mut EyeTrackerPupilDataML,
) -> sys::Result {
    guard("xrGetEyeTrackerPupilDataML", || {
        let Some(ctx) = tracker_context(tracker) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's get info, null or valid; `type` is its first field.
        if !unsafe { typed(info.cast(), structure_type::PUPIL_DATA_GET_INFO) } {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(sample) = ctx.gaze_now() else {
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        // SAFETY: the app's pointers, valid as the call defines them.
        let (count, out) = unsafe { (count.as_mut(), two_call::out_slice(capacity, data)) };
        two_call::answer_with(
            2,
            capacity,
            count,
            out,
            |slot: &mut EyeTrackerPupilDataML, i| {
                slot.eye = if i == 0 { EyeML::LEFT } else { EyeML::RIGHT };
                slot.time = sys::Time::from_nanos(sample.sample_time_ns);
                match sample.pupil_diameter_m[i] {
                    Some(d) => {
                        slot.valid = sys::TRUE;
                        slot.pupil_diameter = d;
                    }
                    None => {
                        slot.valid = sys::FALSE;
                        slot.pupil_diameter = 0.0;
                    }
                }
            },
        )
    })
}

/// `xrGetEyeTrackerGeometricDataML` (two-call idiom, left then right).
///
/// # Safety
/// As `xrGetEyeTrackerGeometricDataML`.
pub unsafe extern "system" fn get_geometric_data(
    tracker: EyeTrackerML,
    info: *const EyeTrackerGetInfoML,
    capacity: u32,
    count: *mut u32,
    data: *mut EyeTrackerGeometricDataML,
) -> sys::Result {
    guard("xrGetEyeTrackerGeometricDataML", || {
        let Some(ctx) = tracker_context(tracker) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's get info, null or valid; `type` is its first field.
        if !unsafe { typed(info.cast(), structure_type::GEOMETRIC_DATA_GET_INFO) } {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(sample) = ctx.gaze_now() else {
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        let rays = [sample.left, sample.right];
        // SAFETY: the app's pointers, valid as the call defines them.
        let (count, out) = unsafe { (count.as_mut(), two_call::out_slice(capacity, data)) };
        two_call::answer_with(
            2,
            capacity,
            count,
            out,
            |slot: &mut EyeTrackerGeometricDataML, i| {
                slot.eye = if i == 0 { EyeML::LEFT } else { EyeML::RIGHT };
                slot.time = sys::Time::from_nanos(sample.sample_time_ns);
                slot.valid = sys::TRUE;
                slot.eye_openness = if rays[i].valid { 1.0 } else { 0.0 };
                slot.eye_in_skull_position = sys::Vector2f { x: 0.0, y: 0.0 };
            },
        )
    })
}

/// `xrGetEyeTrackerGazeBehaviorML`: the behaviour at the newest frame's display time (see the
/// module doc); `valid = FALSE` without a trace.
///
/// # Safety
/// As `xrGetEyeTrackerGazeBehaviorML`.
pub unsafe extern "system" fn get_gaze_behavior(
    tracker: EyeTrackerML,
    info: *const EyeTrackerGetInfoML,
    behavior: *mut EyeTrackerGazeBehaviorML,
) -> sys::Result {
    guard("xrGetEyeTrackerGazeBehaviorML", || {
        let Some(ctx) = tracker_context(tracker) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structures, null or valid; `type` is their first field.
        let ok = unsafe {
            typed(info.cast(), structure_type::GAZE_BEHAVIOR_GET_INFO)
                && typed(behavior.cast(), structure_type::GAZE_BEHAVIOR)
        };
        if !ok {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: checked non-null and typed above.
        let out = unsafe { &mut *behavior };
        let now_ns = ctx.latest_display_ns.unwrap_or(0);
        out.time = sys::Time::from_nanos(now_ns);
        match ctx.behaviour_at(now_ns) {
            Some(b) => {
                out.valid = sys::TRUE;
                out.gaze_behavior_type = behaviour_type_ml(b.behaviour);
                out.onset_time = sys::Time::from_nanos(b.onset_ns);
                out.duration = b.duration_ns.max(0) as u64;
            }
            None => {
                out.valid = sys::FALSE;
                out.gaze_behavior_type = GazeBehaviorTypeML::UNKNOWN;
                out.onset_time = sys::Time::from_nanos(0);
                out.duration = 0;
            }
        }
        sys::Result::SUCCESS
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn ray(origin: Vec3, to: Vec3) -> GazeRay {
        GazeRay {
            origin,
            direction: (to - origin).normalize(),
            valid: true,
        }
    }

    #[test]
    fn fixation_pose_sits_at_the_vergence_point_looking_from_between_the_eyes() {
        let target = Vec3::new(0.05, -0.02, -0.6);
        let l = Vec3::new(-0.032, 0.0, 0.0);
        let r = Vec3::new(0.032, 0.0, 0.0);
        let s = GazeSample::binocular(0, ray(l, target), ray(r, target));
        let [gaze, left, right, fixation] = head_frame_poses(&s);
        let (p, c) = fixation;
        let p = p.unwrap();
        assert_eq!(c, ConfidenceML::HIGH);
        assert!((p.position - target).length() < 1e-5);
        let look = p.orientation * Vec3::NEG_Z;
        assert!((look - target.normalize()).length() < 1e-5);
        assert_eq!(gaze.1, ConfidenceML::HIGH);
        assert!(left.0.is_some() && right.0.is_some());
    }

    #[test]
    fn one_eye_lost_lowers_confidence_and_drops_the_vergence() {
        let s = GazeSample::binocular(
            0,
            ray(Vec3::new(-0.032, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0)),
            GazeRay::INVALID,
        );
        let [gaze, _, right, fixation] = head_frame_poses(&s);
        assert_eq!(gaze.1, ConfidenceML::MEDIUM);
        assert!(right.0.is_none() && fixation.0.is_none());
    }

    #[test]
    fn a_trace_report_sets_the_fixation_confidence() {
        let target = Vec3::new(0.0, 0.0, -0.5);
        let mut s = GazeSample {
            sample_time_ns: 0,
            left: ray(Vec3::new(-0.032, 0.0, 0.0), target),
            right: ray(Vec3::new(0.032, 0.0, 0.0), target),
            combined: None,
            fixation: None,
            pupil_diameter_m: [None, None],
            report: Some(vitreous_trace::TrackerReport {
                confidence: TrackerConfidence::Medium,
                behaviour: GazeBehaviour::Pursuit,
            }),
        };
        let [gaze, left, _, fixation] = head_frame_poses(&s);
        assert_eq!(fixation.1, ConfidenceML::MEDIUM);
        // The other poses keep the layer's own confidence.
        assert_eq!((gaze.1, left.1), (ConfidenceML::HIGH, ConfidenceML::HIGH));
        // No fixation point (one eye lost): no pose, whatever the report says.
        s.right = GazeRay::INVALID;
        let [.., fixation] = head_frame_poses(&s);
        assert_eq!(fixation, (None, ConfidenceML::LOW));
    }

    #[test]
    fn every_behaviour_has_its_extension_type() {
        use GazeBehaviour::*;
        let types: Vec<i32> = [Unknown, EyesClosed, Blink, Fixation, Pursuit, Saccade]
            .into_iter()
            .map(|b| behaviour_type_ml(b).0)
            .collect();
        assert_eq!(types, [0, 1, 2, 5, 6, 7]);
    }
}
