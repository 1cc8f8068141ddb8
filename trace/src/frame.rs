//! Plain data handed from an XR backend to the frame loop: poses, fields of view, eye views,
//! gaze samples and what a tracker says of them, the display's blend mode, one frame's input.

use std::fmt;

use glam::{Quat, Vec3};

/// A rigid transform: where something is and which way it faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Position in metres.
    pub position: Vec3,
    /// Orientation as a unit quaternion.
    pub orientation: Quat,
}

impl Pose {
    /// The pose at the origin looking down -z.
    pub const IDENTITY: Pose = Pose {
        position: Vec3::ZERO,
        orientation: Quat::IDENTITY,
    };

    /// Maps a point from this pose's local frame into the parent frame.
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.position + self.orientation * p
    }

    /// Maps a direction from this pose's local frame into the parent frame.
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.orientation * v
    }
}

/// The angle of the turn from orientation `a` to `b`, radians, from the turn's axis part (its
/// length against its scalar part). `Quat::angle_between` takes the arc cosine of a dot
/// product, which in `f32` reads any turn below about 0.04 degrees as 0 or 0.0396 degrees.
pub fn turn_between(a: Quat, b: Quat) -> f32 {
    let turn = a.inverse() * b;
    2.0 * turn.xyz().length().atan2(turn.w.abs())
}

/// A field of view as OpenXR gives it: four signed half-angles in radians
/// (left and down are negative for a symmetric view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fov {
    /// Angle of the left edge, radians (negative to the left).
    pub angle_left_rad: f32,
    /// Angle of the right edge, radians.
    pub angle_right_rad: f32,
    /// Angle of the top edge, radians.
    pub angle_up_rad: f32,
    /// Angle of the bottom edge, radians (negative downwards).
    pub angle_down_rad: f32,
}

impl Fov {
    /// A symmetric field of view from full horizontal and vertical angles in radians.
    pub fn symmetric(horizontal_rad: f32, vertical_rad: f32) -> Fov {
        Fov {
            angle_left_rad: -horizontal_rad / 2.0,
            angle_right_rad: horizontal_rad / 2.0,
            angle_up_rad: vertical_rad / 2.0,
            angle_down_rad: -vertical_rad / 2.0,
        }
    }
}

/// One eye's view for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeView {
    /// The eye's pose in the world (scene) frame: position of the eye, orientation of the view.
    pub pose: Pose,
    /// The eye's field of view.
    pub fov: Fov,
}

/// A gaze ray in the head frame (OpenXR axes, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeRay {
    /// Ray origin in the head frame, metres.
    pub origin: Vec3,
    /// Unit direction in the head frame.
    pub direction: Vec3,
    /// False while the tracker lost the eye (blink, glare): origin and direction are then
    /// meaningless.
    pub valid: bool,
}

impl GazeRay {
    /// An invalid ray (no measurement).
    pub const INVALID: GazeRay = GazeRay {
        origin: Vec3::ZERO,
        direction: Vec3::NEG_Z,
        valid: false,
    };
}

/// One eye-tracker sample, in the head frame of the same instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeSample {
    /// The tracker's own time for this sample, nanoseconds on the trace/runtime clock.
    /// Filters must use this, not the render frame time: one tracker sample may be seen by
    /// several render frames.
    pub sample_time_ns: i64,
    /// Left eye gaze ray.
    pub left: GazeRay,
    /// Right eye gaze ray.
    pub right: GazeRay,
    /// A combined (cyclopean) ray, when the source gives one.
    pub combined: Option<GazeRay>,
    /// A fixation point in the head frame (metres), when the source computed one.
    pub fixation: Option<Vec3>,
    /// Measured pupil diameters (left, right), metres, when the source reports them.
    pub pupil_diameter_m: [Option<f32>; 2],
    /// What the tracker itself says about this sample (its confidence and its classification
    /// of the eye movement), when the source reports it (Magic Leap 2's `XR_ML_eye_tracker`).
    pub report: Option<TrackerReport>,
}

/// How sure a tracker is of a sample's fixation (vergence) estimate, in its own three steps
/// (`XrEyeTrackerConfidenceML`: LOW, MEDIUM, HIGH).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TrackerConfidence {
    /// The estimate should not be relied on.
    Low,
    /// Usable with caution.
    Medium,
    /// Reliable.
    High,
}

/// What the eyes are doing, as the tracker classifies it (`XrEyeTrackerGazeBehaviorTypeML`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GazeBehaviour {
    /// The tracker does not say.
    Unknown,
    /// Both eyes closed.
    EyesClosed,
    /// A blink (of both eyes, or of one: `BLINK_LEFT` and `BLINK_RIGHT` read as this too).
    Blink,
    /// A fixation.
    Fixation,
    /// A smooth pursuit.
    Pursuit,
    /// A saccade.
    Saccade,
}

/// The tracker's own account of one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TrackerReport {
    /// Confidence of the fixation (vergence) estimate.
    pub confidence: TrackerConfidence,
    /// The eye movement the sample belongs to.
    pub behaviour: GazeBehaviour,
}

impl GazeSample {
    /// A sample at `sample_time_ns` of the two eyes' rays alone: no combined ray, fixation,
    /// pupil measurement or tracker report (what a tracker that gives only per-eye rays
    /// reports).
    pub const fn binocular(sample_time_ns: i64, left: GazeRay, right: GazeRay) -> GazeSample {
        GazeSample {
            sample_time_ns,
            left,
            right,
            combined: None,
            fixation: None,
            pupil_diameter_m: [None, None],
            report: None,
        }
    }

    /// A sample at `sample_time_ns` that holds no gaze: both eyes' rays invalid, no combined
    /// ray, fixation or pupil measurement (a tracker's dropout; a frame without a tracker,
    /// as recorded in a trace).
    pub const fn none(sample_time_ns: i64) -> GazeSample {
        GazeSample::binocular(sample_time_ns, GazeRay::INVALID, GazeRay::INVALID)
    }
}

/// How the display combines rendered light with the real world (OpenXR environment blend
/// modes, as far as vitreous cares).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    /// Light added onto the real world: optical see-through (Magic Leap 2). What vitreous is for.
    Additive,
    /// Rendered pixels blended over a camera view of the world by their alpha.
    AlphaBlend,
    /// Only the rendered picture is shown (VR): vitreous draws the scene's real-world photos
    /// behind the glass so the whole picture is visible.
    Opaque,
}

impl Blend {
    /// Whether the app must draw the real world itself.
    pub fn needs_world_behind(self) -> bool {
        self == Blend::Opaque
    }

    /// Whether the submitted image's alpha is used: ALPHA_BLEND shows premultiplied colour
    /// over the real world by its alpha (vitreous submits alpha 0, so the light adds onto the
    /// world); ADDITIVE and OPAQUE ignore alpha.
    pub fn uses_source_alpha(self) -> bool {
        self == Blend::AlphaBlend
    }

    /// Parses `additive`, `alpha-blend` (or `alpha`) and `opaque`.
    pub fn parse(s: &str) -> Option<Blend> {
        match s.trim().to_ascii_lowercase().as_str() {
            "additive" => Some(Blend::Additive),
            "alpha-blend" | "alpha_blend" | "alpha" => Some(Blend::AlphaBlend),
            "opaque" => Some(Blend::Opaque),
            _ => None,
        }
    }
}

impl fmt::Display for Blend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Blend::Additive => "additive",
            Blend::AlphaBlend => "alpha-blend",
            Blend::Opaque => "opaque",
        })
    }
}

/// What a backend hands the frame loop for one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameInput {
    /// Index of the frame since the session started.
    pub index: u64,
    /// Predicted display time of the frame, nanoseconds.
    pub time_ns: i64,
    /// Head pose in the world (scene) frame.
    pub head: Pose,
    /// Left and right eye views, in that order.
    pub views: [EyeView; 2],
    /// The newest gaze sample at or before `time_ns`, if the source has any.
    pub gaze: Option<GazeSample>,
}
