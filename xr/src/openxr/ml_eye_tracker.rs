//! Raw definitions of Magic Leap 2's `XR_ML_eye_tracker` extension, which the `openxr` crate
//! does not carry: structure types, flags, the per-call structs and the function pointer types,
//! laid out as Magic Leap's SDK declares them (C layout, `XrStructureType` values
//! 1000484000-1000484014).
//!
//! The app reads per-eye, fixation (vergence) and pupil data, the fixation pose's confidence
//! and the gaze behaviour through them ([`super::ml_tracker`]); the simulated headset layer
//! (`vitreous-sim-layer`) answers the same calls.
//!
//! Units: poses in metres in the base space given per call; pupil diameters in metres; times
//! are `XrTime` nanoseconds.

use openxr::sys;

/// The extension's name.
pub const EXTENSION_NAME: &str = "XR_ML_eye_tracker";

/// `XrObjectType` of an eye tracker handle.
pub const OBJECT_TYPE_EYE_TRACKER_ML: i32 = 1_000_484_000;

/// `XrStructureType` values of the extension, raw (`sys::StructureType::from_raw` makes the
/// typed value; [`structure_type::is`] compares).
pub mod structure_type {
    use openxr::sys::StructureType;

    /// Whether `ty` is the raw structure type `raw`.
    pub fn is(ty: StructureType, raw: i32) -> bool {
        ty.into_raw() == raw
    }

    /// `XrEyeTrackerCreateInfoML`.
    pub const CREATE_INFO: i32 = 1_000_484_001;
    /// `XrEyeTrackerStaticDataGetInfoML`.
    pub const STATIC_DATA_GET_INFO: i32 = 1_000_484_002;
    /// `XrEyeTrackerStaticDataML`.
    pub const STATIC_DATA: i32 = 1_000_484_003;
    /// `XrEyeTrackerGazeBehaviorGetInfoML`.
    pub const GAZE_BEHAVIOR_GET_INFO: i32 = 1_000_484_004;
    /// `XrEyeTrackerGazeBehaviorML`.
    pub const GAZE_BEHAVIOR: i32 = 1_000_484_005;
    /// `XrEyeTrackerGazeBehaviorMetaDataML`.
    pub const GAZE_BEHAVIOR_META_DATA: i32 = 1_000_484_006;
    /// `XrEyeTrackerGeometricDataGetInfoML`.
    pub const GEOMETRIC_DATA_GET_INFO: i32 = 1_000_484_007;
    /// `XrEyeTrackerGeometricDataML`.
    pub const GEOMETRIC_DATA: i32 = 1_000_484_008;
    /// `XrEyeTrackerPupilDataGetInfoML`.
    pub const PUPIL_DATA_GET_INFO: i32 = 1_000_484_009;
    /// `XrEyeTrackerPupilDataML`.
    pub const PUPIL_DATA: i32 = 1_000_484_010;
    /// `XrSystemEyeTrackerPropertiesML`, chained to `XrSystemProperties`.
    pub const SYSTEM_PROPERTIES: i32 = 1_000_484_011;
    /// `XrEyeTrackerPosesGetInfoML`.
    pub const POSES_GET_INFO: i32 = 1_000_484_012;
    /// `XrEyeTrackerPosesML`.
    pub const POSES: i32 = 1_000_484_013;
    /// `XrEyeTrackerPoseML`.
    pub const POSE: i32 = 1_000_484_014;
}

/// `XrEyeTrackerML`: an eye tracker handle.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct EyeTrackerML(pub u64);

impl EyeTrackerML {
    /// `XR_NULL_HANDLE`.
    pub const NULL: EyeTrackerML = EyeTrackerML(0);
}

/// `XrEyeML`: which eye a per-eye datum belongs to.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct EyeML(pub i32);

impl EyeML {
    /// The left eye.
    pub const LEFT: EyeML = EyeML(1);
    /// The right eye.
    pub const RIGHT: EyeML = EyeML(2);
}

/// `XrEyeTrackerConfidenceML`.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ConfidenceML(pub u32);

impl ConfidenceML {
    /// Low confidence.
    pub const LOW: ConfidenceML = ConfidenceML(0);
    /// Medium confidence.
    pub const MEDIUM: ConfidenceML = ConfidenceML(1);
    /// High confidence.
    pub const HIGH: ConfidenceML = ConfidenceML(2);
}

/// `XrEyeTrackerGazeBehaviorTypeML`.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct GazeBehaviorTypeML(pub i32);

impl GazeBehaviorTypeML {
    /// Nothing known.
    pub const UNKNOWN: GazeBehaviorTypeML = GazeBehaviorTypeML(0);
    /// Both eyes closed.
    pub const EYES_CLOSED: GazeBehaviorTypeML = GazeBehaviorTypeML(1);
    /// A blink of both eyes.
    pub const BLINK: GazeBehaviorTypeML = GazeBehaviorTypeML(2);
    /// A blink of the left eye.
    pub const BLINK_LEFT: GazeBehaviorTypeML = GazeBehaviorTypeML(3);
    /// A blink of the right eye.
    pub const BLINK_RIGHT: GazeBehaviorTypeML = GazeBehaviorTypeML(4);
    /// A fixation.
    pub const FIXATION: GazeBehaviorTypeML = GazeBehaviorTypeML(5);
    /// A smooth pursuit.
    pub const PURSUIT: GazeBehaviorTypeML = GazeBehaviorTypeML(6);
    /// A saccade.
    pub const SACCADE: GazeBehaviorTypeML = GazeBehaviorTypeML(7);
}

/// `XrEyeTrackerPoseFlagsML`: which poses `xrGetEyeTrackerPosesML` should fill.
pub mod pose_flags {
    /// The combined gaze pose.
    pub const GAZE: u64 = 0x1;
    /// The left eye's pose.
    pub const LEFT: u64 = 0x2;
    /// The right eye's pose.
    pub const RIGHT: u64 = 0x4;
    /// The fixation (vergence) pose.
    pub const FIXATION: u64 = 0x8;
    /// All four.
    pub const ALL: u64 = GAZE | LEFT | RIGHT | FIXATION;
}

/// `XrSystemEyeTrackerPropertiesML`, chained to `XrSystemProperties`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SystemEyeTrackerPropertiesML {
    /// [`structure_type::SYSTEM_PROPERTIES`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// Whether the system has an eye tracker.
    pub supports_eye_tracking: sys::Bool32,
}

/// `XrEyeTrackerCreateInfoML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerCreateInfoML {
    /// [`structure_type::CREATE_INFO`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *const std::ffi::c_void,
}

/// `XrEyeTrackerStaticDataGetInfoML` (also the layout of the other argument-less get-infos:
/// geometric data, pupil data, gaze behaviour).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerGetInfoML {
    /// The get-info's structure type.
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *const std::ffi::c_void,
}

/// `XrEyeTrackerStaticDataML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerStaticDataML {
    /// [`structure_type::STATIC_DATA`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// Largest eye width the tracker reports, in its own units.
    pub eye_width_max: f32,
    /// Largest eye height the tracker reports.
    pub eye_height_max: f32,
}

/// `XrEyeTrackerPupilDataML`: one eye's pupil.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerPupilDataML {
    /// [`structure_type::PUPIL_DATA`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// Which eye.
    pub eye: EyeML,
    /// When the pupil was measured.
    pub time: sys::Time,
    /// Whether `pupil_diameter` holds a measurement.
    pub valid: sys::Bool32,
    /// Pupil diameter, metres.
    pub pupil_diameter: f32,
}

/// `XrEyeTrackerGeometricDataML`: one eye's openness and position in the skull.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerGeometricDataML {
    /// [`structure_type::GEOMETRIC_DATA`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// Which eye.
    pub eye: EyeML,
    /// When it was measured.
    pub time: sys::Time,
    /// Whether the fields hold a measurement.
    pub valid: sys::Bool32,
    /// 0 (closed) to 1 (open).
    pub eye_openness: f32,
    /// The eye's position in the skull, normalised.
    pub eye_in_skull_position: sys::Vector2f,
}

/// `XrEyeTrackerGazeBehaviorML`: the tracker's own classification of the gaze.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerGazeBehaviorML {
    /// [`structure_type::GAZE_BEHAVIOR`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// When it was classified.
    pub time: sys::Time,
    /// Whether the fields hold a classification.
    pub valid: sys::Bool32,
    /// Fixation, saccade, blink, ...
    pub gaze_behavior_type: GazeBehaviorTypeML,
    /// When the behaviour began.
    pub onset_time: sys::Time,
    /// How long it has lasted, nanoseconds.
    pub duration: u64,
}

/// `XrEyeTrackerPosesGetInfoML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerPosesGetInfoML {
    /// [`structure_type::POSES_GET_INFO`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *const std::ffi::c_void,
    /// The space the poses are given in.
    pub base_space: sys::Space,
    /// The time the poses are wanted for.
    pub time: sys::Time,
    /// Which poses to fill ([`pose_flags`]).
    pub pose_flags: u64,
}

/// `XrEyeTrackerPoseML`: one pose with its confidence.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerPoseML {
    /// [`structure_type::POSE`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// Whether `pose` holds a measurement.
    pub valid: sys::Bool32,
    /// The pose in the base space; the gaze looks along its -z axis. For the fixation pose,
    /// the position is the fixation (vergence) point.
    pub pose: sys::Posef,
    /// When it was measured.
    pub time: sys::Time,
    /// How sure the tracker is.
    pub confidence: ConfidenceML,
}

/// `XrEyeTrackerPosesML`: the four poses.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct EyeTrackerPosesML {
    /// [`structure_type::POSES`].
    pub ty: sys::StructureType,
    /// Next structure in the chain.
    pub next: *mut std::ffi::c_void,
    /// The combined gaze.
    pub gaze_pose: EyeTrackerPoseML,
    /// The left eye.
    pub left_pose: EyeTrackerPoseML,
    /// The right eye.
    pub right_pose: EyeTrackerPoseML,
    /// The fixation point.
    pub fixation_pose: EyeTrackerPoseML,
}

impl EyeTrackerPoseML {
    /// An empty pose with its structure type set, for the runtime to fill.
    pub fn empty() -> EyeTrackerPoseML {
        EyeTrackerPoseML {
            ty: sys::StructureType::from_raw(structure_type::POSE),
            next: std::ptr::null_mut(),
            valid: sys::FALSE,
            pose: sys::Posef::IDENTITY,
            time: sys::Time::from_nanos(0),
            confidence: ConfidenceML::LOW,
        }
    }
}

impl EyeTrackerPosesML {
    /// An empty output structure with every structure type set, for the runtime to fill.
    pub fn empty() -> EyeTrackerPosesML {
        EyeTrackerPosesML {
            ty: sys::StructureType::from_raw(structure_type::POSES),
            next: std::ptr::null_mut(),
            gaze_pose: EyeTrackerPoseML::empty(),
            left_pose: EyeTrackerPoseML::empty(),
            right_pose: EyeTrackerPoseML::empty(),
            fixation_pose: EyeTrackerPoseML::empty(),
        }
    }
}

impl EyeTrackerPupilDataML {
    /// An empty output structure with its structure type set, for the runtime to fill.
    pub fn empty() -> EyeTrackerPupilDataML {
        EyeTrackerPupilDataML {
            ty: sys::StructureType::from_raw(structure_type::PUPIL_DATA),
            next: std::ptr::null_mut(),
            eye: EyeML::LEFT,
            time: sys::Time::from_nanos(0),
            valid: sys::FALSE,
            pupil_diameter: 0.0,
        }
    }
}

impl EyeTrackerGazeBehaviorML {
    /// An empty output structure with its structure type set, for the runtime to fill.
    pub fn empty() -> EyeTrackerGazeBehaviorML {
        EyeTrackerGazeBehaviorML {
            ty: sys::StructureType::from_raw(structure_type::GAZE_BEHAVIOR),
            next: std::ptr::null_mut(),
            time: sys::Time::from_nanos(0),
            valid: sys::FALSE,
            gaze_behavior_type: GazeBehaviorTypeML::UNKNOWN,
            onset_time: sys::Time::from_nanos(0),
            duration: 0,
        }
    }
}

/// `xrCreateEyeTrackerML`.
pub type CreateEyeTrackerML = unsafe extern "system" fn(
    session: sys::Session,
    create_info: *const EyeTrackerCreateInfoML,
    eye_tracker: *mut EyeTrackerML,
) -> sys::Result;

/// `xrDestroyEyeTrackerML`.
pub type DestroyEyeTrackerML = unsafe extern "system" fn(eye_tracker: EyeTrackerML) -> sys::Result;

/// `xrGetEyeTrackerStaticDataML`.
pub type GetEyeTrackerStaticDataML = unsafe extern "system" fn(
    eye_tracker: EyeTrackerML,
    get_info: *const EyeTrackerGetInfoML,
    data: *mut EyeTrackerStaticDataML,
) -> sys::Result;

/// `xrGetEyeTrackerPosesML`.
pub type GetEyeTrackerPosesML = unsafe extern "system" fn(
    eye_tracker: EyeTrackerML,
    get_info: *const EyeTrackerPosesGetInfoML,
    poses: *mut EyeTrackerPosesML,
) -> sys::Result;

/// `xrGetEyeTrackerPupilDataML` (two-call idiom: capacity, count, array).
pub type GetEyeTrackerPupilDataML = unsafe extern "system" fn(
    eye_tracker: EyeTrackerML,
    get_info: *const EyeTrackerGetInfoML,
    capacity_input: u32,
    count_output: *mut u32,
    data: *mut EyeTrackerPupilDataML,
) -> sys::Result;

/// `xrGetEyeTrackerGeometricDataML` (two-call idiom).
pub type GetEyeTrackerGeometricDataML = unsafe extern "system" fn(
    eye_tracker: EyeTrackerML,
    get_info: *const EyeTrackerGetInfoML,
    capacity_input: u32,
    count_output: *mut u32,
    data: *mut EyeTrackerGeometricDataML,
) -> sys::Result;

/// `xrGetEyeTrackerGazeBehaviorML`.
pub type GetEyeTrackerGazeBehaviorML = unsafe extern "system" fn(
    eye_tracker: EyeTrackerML,
    get_info: *const EyeTrackerGetInfoML,
    behavior: *mut EyeTrackerGazeBehaviorML,
) -> sys::Result;

#[cfg(test)]
mod tests {
    use super::*;

    /// The layouts match the C declarations on a 64-bit target: 4-byte type, padding, 8-byte
    /// `next`, then the fields at their natural alignment.
    #[test]
    fn layouts_match_the_c_declarations() {
        assert_eq!(std::mem::size_of::<EyeTrackerPoseML>(), 64);
        assert_eq!(std::mem::offset_of!(EyeTrackerPoseML, pose), 20);
        assert_eq!(std::mem::offset_of!(EyeTrackerPoseML, time), 48);
        assert_eq!(std::mem::size_of::<EyeTrackerPosesML>(), 16 + 4 * 64);
        assert_eq!(std::mem::offset_of!(EyeTrackerPosesGetInfoML, time), 24);
        assert_eq!(std::mem::size_of::<EyeTrackerPupilDataML>(), 40);
        assert_eq!(
            std::mem::offset_of!(EyeTrackerPupilDataML, pupil_diameter),
            36
        );
        assert_eq!(std::mem::size_of::<EyeTrackerGazeBehaviorML>(), 48);
        assert_eq!(
            std::mem::offset_of!(EyeTrackerGazeBehaviorML, gaze_behavior_type),
            28
        );
        assert_eq!(std::mem::offset_of!(EyeTrackerGazeBehaviorML, duration), 40);
    }
}
