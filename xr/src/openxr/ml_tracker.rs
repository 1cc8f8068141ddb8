//! The XR_ML_eye_tracker gaze source (Magic Leap 2): per-eye, combined and fixation poses,
//! pupil diameters, and the tracker's own report of each sample, through the extension's raw
//! functions ([`super::ml_eye_tracker`]; the `openxr` crate does not carry them).
//!
//! Each frame makes three calls, in this order: `xrGetEyeTrackerPosesML` (its failure is a
//! frame without gaze), `xrGetEyeTrackerPupilDataML` (its failure: no pupil measurement) and
//! `xrGetEyeTrackerGazeBehaviorML` (its failure, or a runtime without it: the behaviour is
//! [`GazeBehaviour::Unknown`], logged once; the sample is kept). The sample's
//! [`TrackerReport`] holds the fixation pose's confidence (LOW when that pose is not valid:
//! the vergence estimate is then not usable) and the classified behaviour: unknown when the
//! tracker marks it not valid, blink for a blink of either or both eyes.

use std::ffi::CStr;

use glam::Vec3;
use openxr as xr;
use vitreous_trace::format::PUPIL_RANGE_M;
use vitreous_trace::{GazeBehaviour, GazeRay, GazeSample, TrackerConfidence, TrackerReport};

use super::convert::ray_of;
use super::ml_eye_tracker as ml;
use super::{OpenXrError, Result, XrContext};

/// An XR_ML_eye_tracker tracker and the functions it is used with (loaded through
/// xrGetInstanceProcAddr: the `openxr` crate does not carry the extension).
pub(super) struct MlTracker {
    /// The tracker handle; destroyed on drop.
    tracker: ml::EyeTrackerML,
    /// `xrDestroyEyeTrackerML`.
    destroy: ml::DestroyEyeTrackerML,
    /// `xrGetEyeTrackerPosesML`.
    get_poses: ml::GetEyeTrackerPosesML,
    /// `xrGetEyeTrackerPupilDataML`.
    get_pupils: ml::GetEyeTrackerPupilDataML,
    /// `xrGetEyeTrackerGazeBehaviorML`, when the runtime gives it.
    get_behaviour: Option<ml::GetEyeTrackerGazeBehaviorML>,
    /// Whether the behaviour's absence or a failed call has been logged (once per tracker).
    behaviour_warned: bool,
}

/// Loads an instance function by name.
///
/// # Safety
/// `T` must be the function pointer type of the function named `name`.
pub(super) unsafe fn load<T: Copy>(instance: &xr::Instance, name: &CStr) -> Result<T> {
    let mut f: Option<xr::sys::pfn::VoidFunction> = None;
    // SAFETY: a live instance and a nul-terminated name; `f` outlives the call.
    let r = unsafe {
        (instance.entry().fp().get_instance_proc_addr)(instance.as_raw(), name.as_ptr(), &mut f)
    };
    match f {
        Some(f) if r == xr::sys::Result::SUCCESS => {
            const {
                assert!(
                    std::mem::size_of::<T>() == std::mem::size_of::<xr::sys::pfn::VoidFunction>()
                )
            };
            // SAFETY: the runtime returned the function named `name`, whose type is `T` (this
            // function's contract); both are plain function pointers of the same size.
            Ok(unsafe { std::mem::transmute_copy::<xr::sys::pfn::VoidFunction, T>(&f) })
        }
        _ => Err(OpenXrError::Call {
            call: "xrGetInstanceProcAddr",
            result: if r == xr::sys::Result::SUCCESS {
                xr::sys::Result::ERROR_FUNCTION_UNSUPPORTED
            } else {
                r
            },
        }),
    }
}

impl MlTracker {
    /// Loads the extension's functions and creates the tracker (the extension must be enabled
    /// on the session's instance).
    pub(super) fn new(session: &xr::Session<xr::Vulkan>) -> Result<MlTracker> {
        let instance = session.instance();
        // SAFETY: each name is paired with its function pointer type from the extension's
        // declarations (ml_eye_tracker).
        let (create, destroy, get_poses, get_pupils) = unsafe {
            (
                load::<ml::CreateEyeTrackerML>(instance, c"xrCreateEyeTrackerML")?,
                load::<ml::DestroyEyeTrackerML>(instance, c"xrDestroyEyeTrackerML")?,
                load::<ml::GetEyeTrackerPosesML>(instance, c"xrGetEyeTrackerPosesML")?,
                load::<ml::GetEyeTrackerPupilDataML>(instance, c"xrGetEyeTrackerPupilDataML")?,
            )
        };
        // Optional: without it the behaviour is unknown, the rest of the sample is still read.
        // SAFETY: the name is paired with its function pointer type.
        let get_behaviour = unsafe {
            load::<ml::GetEyeTrackerGazeBehaviorML>(instance, c"xrGetEyeTrackerGazeBehaviorML")
        }
        .ok();
        let info = ml::EyeTrackerCreateInfoML {
            ty: xr::sys::StructureType::from_raw(ml::structure_type::CREATE_INFO),
            next: std::ptr::null(),
        };
        let mut tracker = ml::EyeTrackerML::NULL;
        // SAFETY: `create` is the runtime's xrCreateEyeTrackerML; the session is live and
        // `info`, `tracker` are valid for the call.
        let r = unsafe { create(session.as_raw(), &info, &mut tracker) };
        if r != xr::sys::Result::SUCCESS {
            return Err(r).xr("xrCreateEyeTrackerML");
        }
        Ok(MlTracker {
            tracker,
            destroy,
            get_poses,
            get_pupils,
            get_behaviour,
            behaviour_warned: false,
        })
    }

    /// Per-eye rays, the combined ray and the fixation point in the head frame, the pupil
    /// diameters and the tracker's report; the sample time is the newest valid pose's.
    pub(super) fn sample(
        &mut self,
        view_space: &xr::Space,
        display: xr::Time,
    ) -> Option<GazeSample> {
        let info = ml::EyeTrackerPosesGetInfoML {
            ty: xr::sys::StructureType::from_raw(ml::structure_type::POSES_GET_INFO),
            next: std::ptr::null(),
            base_space: view_space.as_raw(),
            time: display,
            pose_flags: ml::pose_flags::ALL,
        };
        let mut poses = ml::EyeTrackerPosesML::empty();
        // SAFETY: the tracker is live until drop; `info` and `poses` are typed and outlive the
        // call.
        let r = unsafe { (self.get_poses)(self.tracker, &info, &mut poses) };
        if r != xr::sys::Result::SUCCESS {
            return None;
        }
        let valid = |p: &ml::EyeTrackerPoseML| p.valid == xr::sys::TRUE;
        let ray = |p: &ml::EyeTrackerPoseML| {
            if valid(p) {
                ray_of(&p.pose)
            } else {
                GazeRay::INVALID
            }
        };
        let all = [
            &poses.left_pose,
            &poses.right_pose,
            &poses.gaze_pose,
            &poses.fixation_pose,
        ];
        // A blink (no valid pose) is a sample too: the filters hold through it. Its time is the
        // newest the runtime stamped, else the display time asked for.
        let newest = |only_valid: bool| {
            all.iter()
                .filter(|p| !only_valid || valid(p))
                .map(|p| p.time.as_nanos())
                .filter(|&t| t > 0)
                .max()
        };
        let sample_time_ns = newest(true)
            .or_else(|| newest(false))
            .unwrap_or(display.as_nanos());
        let fixation = valid(&poses.fixation_pose).then(|| {
            let p = poses.fixation_pose.pose.position;
            Vec3::new(p.x, p.y, p.z)
        });
        let pupil_diameter_m = self.pupils();
        let report = TrackerReport {
            confidence: fixation_confidence(&poses.fixation_pose),
            behaviour: self.behaviour(),
        };
        Some(GazeSample {
            sample_time_ns,
            left: ray(&poses.left_pose),
            right: ray(&poses.right_pose),
            combined: Some(ray(&poses.gaze_pose)),
            fixation,
            pupil_diameter_m,
            report: Some(report),
        })
    }

    /// The pupil diameters (left, right), metres, where the tracker measured them.
    fn pupils(&mut self) -> [Option<f32>; 2] {
        let info = ml::EyeTrackerGetInfoML {
            ty: xr::sys::StructureType::from_raw(ml::structure_type::PUPIL_DATA_GET_INFO),
            next: std::ptr::null(),
        };
        let mut data = [ml::EyeTrackerPupilDataML::empty(); 2];
        let mut count = 0u32;
        // SAFETY: the tracker is live; `data` has room for the capacity given and outlives
        // the call, every element typed.
        let r = unsafe {
            (self.get_pupils)(
                self.tracker,
                &info,
                data.len() as u32,
                &mut count,
                data.as_mut_ptr(),
            )
        };
        let mut out = [None, None];
        if r != xr::sys::Result::SUCCESS {
            return out;
        }
        for d in data.iter().take(count as usize) {
            let eye = match d.eye {
                ml::EyeML::LEFT => 0,
                ml::EyeML::RIGHT => 1,
                _ => continue,
            };
            if let Some(diameter_m) = measured_pupil(d.valid, d.pupil_diameter) {
                out[eye] = Some(diameter_m);
            }
        }
        out
    }

    /// The tracker's classification of the current gaze; unknown when it has none, or when the
    /// call is missing or fails (logged once).
    fn behaviour(&mut self) -> GazeBehaviour {
        let Some(get_behaviour) = self.get_behaviour else {
            self.warn_behaviour_once(
                "the runtime does not give xrGetEyeTrackerGazeBehaviorML: gaze behaviour \
                 recorded as unknown"
                    .to_owned(),
            );
            return GazeBehaviour::Unknown;
        };
        let info = ml::EyeTrackerGetInfoML {
            ty: xr::sys::StructureType::from_raw(ml::structure_type::GAZE_BEHAVIOR_GET_INFO),
            next: std::ptr::null(),
        };
        let mut out = ml::EyeTrackerGazeBehaviorML::empty();
        // SAFETY: the tracker is live until drop; `info` and `out` are typed and outlive the
        // call.
        let r = unsafe { get_behaviour(self.tracker, &info, &mut out) };
        if r != xr::sys::Result::SUCCESS {
            self.warn_behaviour_once(format!(
                "xrGetEyeTrackerGazeBehaviorML failed ({r}); gaze behaviour recorded as unknown \
                 while it fails"
            ));
            return GazeBehaviour::Unknown;
        }
        classified_behaviour(&out)
    }

    /// Logs `message` as a warning, the first time only.
    fn warn_behaviour_once(&mut self, message: String) {
        if !self.behaviour_warned {
            self.behaviour_warned = true;
            tracing::warn!("{message}");
        }
    }
}

/// The confidence of the fixation (vergence) estimate: the fixation pose's, or LOW when the
/// pose is not valid; a value the extension does not define reads as LOW.
fn fixation_confidence(pose: &ml::EyeTrackerPoseML) -> TrackerConfidence {
    if pose.valid != xr::sys::TRUE {
        return TrackerConfidence::Low;
    }
    match pose.confidence {
        ml::ConfidenceML::HIGH => TrackerConfidence::High,
        ml::ConfidenceML::MEDIUM => TrackerConfidence::Medium,
        _ => TrackerConfidence::Low,
    }
}

/// The behaviour the tracker classified: unknown when it marks the classification not valid
/// or gives a type the extension does not define; a blink of one eye is a blink.
fn classified_behaviour(b: &ml::EyeTrackerGazeBehaviorML) -> GazeBehaviour {
    if b.valid != xr::sys::TRUE {
        return GazeBehaviour::Unknown;
    }
    match b.gaze_behavior_type {
        ml::GazeBehaviorTypeML::EYES_CLOSED => GazeBehaviour::EyesClosed,
        ml::GazeBehaviorTypeML::BLINK
        | ml::GazeBehaviorTypeML::BLINK_LEFT
        | ml::GazeBehaviorTypeML::BLINK_RIGHT => GazeBehaviour::Blink,
        ml::GazeBehaviorTypeML::FIXATION => GazeBehaviour::Fixation,
        ml::GazeBehaviorTypeML::PURSUIT => GazeBehaviour::Pursuit,
        ml::GazeBehaviorTypeML::SACCADE => GazeBehaviour::Saccade,
        _ => GazeBehaviour::Unknown,
    }
}

/// A pupil diameter the tracker marked valid, when it is one a trace can hold
/// ([`PUPIL_RANGE_M`]); anything else (0, NaN, a value in millimetres) is no measurement, so
/// that `run --record` never writes a sample the trace reader would refuse.
fn measured_pupil(valid: xr::sys::Bool32, diameter_m: f32) -> Option<f32> {
    (valid == xr::sys::TRUE && PUPIL_RANGE_M.contains(&diameter_m)).then_some(diameter_m)
}

impl Drop for MlTracker {
    fn drop(&mut self) {
        // SAFETY: the tracker was created by this table's runtime and is not used after this
        // drop.
        unsafe { (self.destroy)(self.tracker) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_valid_plausible_pupils_are_measurements() {
        assert_eq!(measured_pupil(xr::sys::TRUE, 0.004), Some(0.004));
        assert_eq!(measured_pupil(xr::sys::FALSE, 0.004), None);
        for odd in [0.0, -0.004, f32::NAN, f32::INFINITY, 4.0, 0.0004, 0.02] {
            assert_eq!(measured_pupil(xr::sys::TRUE, odd), None, "{odd}");
        }
    }

    #[test]
    fn the_report_confidence_is_the_valid_fixation_poses() {
        let mut pose = ml::EyeTrackerPoseML::empty();
        pose.valid = xr::sys::TRUE;
        for (raw, expected) in [
            (ml::ConfidenceML::LOW, TrackerConfidence::Low),
            (ml::ConfidenceML::MEDIUM, TrackerConfidence::Medium),
            (ml::ConfidenceML::HIGH, TrackerConfidence::High),
            (ml::ConfidenceML(7), TrackerConfidence::Low),
        ] {
            pose.confidence = raw;
            assert_eq!(fixation_confidence(&pose), expected, "{raw:?}");
        }
        // No vergence estimate: however sure the runtime says it is, nothing to rely on.
        pose.valid = xr::sys::FALSE;
        pose.confidence = ml::ConfidenceML::HIGH;
        assert_eq!(fixation_confidence(&pose), TrackerConfidence::Low);
    }

    #[test]
    fn every_behaviour_type_reads_as_ours_and_one_eyed_blinks_as_blinks() {
        use ml::GazeBehaviorTypeML as T;
        let mut b = ml::EyeTrackerGazeBehaviorML::empty();
        b.valid = xr::sys::TRUE;
        for (raw, expected) in [
            (T::UNKNOWN, GazeBehaviour::Unknown),
            (T::EYES_CLOSED, GazeBehaviour::EyesClosed),
            (T::BLINK, GazeBehaviour::Blink),
            (T::BLINK_LEFT, GazeBehaviour::Blink),
            (T::BLINK_RIGHT, GazeBehaviour::Blink),
            (T::FIXATION, GazeBehaviour::Fixation),
            (T::PURSUIT, GazeBehaviour::Pursuit),
            (T::SACCADE, GazeBehaviour::Saccade),
            (T(99), GazeBehaviour::Unknown),
        ] {
            b.gaze_behavior_type = raw;
            assert_eq!(classified_behaviour(&b), expected, "{raw:?}");
        }
        // Not valid: whatever the type says, the tracker does not know.
        b.valid = xr::sys::FALSE;
        b.gaze_behavior_type = T::SACCADE;
        assert_eq!(classified_behaviour(&b), GazeBehaviour::Unknown);
    }
}
