//! The axis and unit conversions from SRanipal gaze and Unity head poses into the OpenXR
//! conventions of this crate (see the parent module for the rules).

use glam::{Quat, Vec3};

use crate::format::clean_ray;
use crate::frame::{GazeRay, Pose};

/// Converts an SRanipal gaze ray (origin in millimetres, +x to the wearer's left, +z forward)
/// into the OpenXR head frame (metres, +x right, -z forward). Non-finite values or a zero
/// direction give [`GazeRay::INVALID`].
pub fn sranipal_ray_to_openxr(origin_mm: Vec3, direction: Vec3) -> GazeRay {
    let flip = Vec3::new(-1.0, 1.0, -1.0);
    clean_ray(GazeRay {
        origin: origin_mm * flip / 1000.0,
        direction: direction * flip,
        valid: true,
    })
}

/// Converts a Unity head pose (left-handed world, +z forward; Euler angles in degrees applied
/// Z, then X, then Y) into the right-handed OpenXR frame by mirroring z.
pub fn unity_pose_to_openxr(position_m: Vec3, euler_deg: Vec3) -> Pose {
    let q = Quat::from_rotation_y(euler_deg.y.to_radians())
        * Quat::from_rotation_x(euler_deg.x.to_radians())
        * Quat::from_rotation_z(euler_deg.z.to_radians());
    Pose {
        position: Vec3::new(position_m.x, position_m.y, -position_m.z),
        orientation: Quat::from_xyzw(-q.x, -q.y, q.z, q.w).normalize(),
    }
}

/// The heading of an orientation: the angle about +y that turns -z toward the horizontal
/// direction the head faces. Looking straight up or down, the top of the head gives it.
pub fn heading_rad(orientation: Quat) -> f32 {
    let forward = orientation * Vec3::NEG_Z;
    let h = if forward.x * forward.x + forward.z * forward.z > 1e-6 {
        forward
    } else {
        let up = orientation * Vec3::Y;
        if forward.y < 0.0 { up } else { -up }
    };
    // Rotating -z by a about +y gives (-sin a, 0, -cos a).
    (-h.x).atan2(-h.z)
}
