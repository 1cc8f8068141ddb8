//! OpenXR's poses as vitreous's types: a pose, and the gaze ray along a pose's forward axis.

use glam::{Quat, Vec3};
use openxr as xr;

use vitreous_trace::{GazeRay, Pose};

/// A pose from OpenXR's (orientation normalised).
pub(super) fn pose_of(p: &xr::Posef) -> Pose {
    Pose {
        position: Vec3::new(p.position.x, p.position.y, p.position.z),
        orientation: Quat::from_xyzw(
            p.orientation.x,
            p.orientation.y,
            p.orientation.z,
            p.orientation.w,
        )
        .normalize(),
    }
}

/// OpenXR's pose of one of vitreous's.
pub(super) fn posef_of(p: &Pose) -> xr::Posef {
    xr::Posef {
        orientation: xr::Quaternionf {
            x: p.orientation.x,
            y: p.orientation.y,
            z: p.orientation.z,
            w: p.orientation.w,
        },
        position: xr::Vector3f {
            x: p.position.x,
            y: p.position.y,
            z: p.position.z,
        },
    }
}

/// A valid ray from a pose's position along its forward axis (-z).
pub(super) fn ray_of(pose: &xr::Posef) -> GazeRay {
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
