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

/// Whether a pose's position is finite: a runtime may hand out anything where it marks a
/// position valid by mistake (or leaves one it marks not valid undefined).
pub(super) fn usable_position(p: &xr::Posef) -> bool {
    [p.position.x, p.position.y, p.position.z]
        .iter()
        .all(|v| v.is_finite())
}

/// Whether a pose's orientation is a unit quaternion, within a tenth (OpenXR asks for unit
/// length; runtimes have handed out all-zero ones marked valid at start-up): anything else
/// cannot be normalised into a turn.
pub(super) fn usable_orientation(p: &xr::Posef) -> bool {
    let q = &p.orientation;
    let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
    (norm - 1.0).abs() < 0.1
}

/// Whether a view's field of view is one an image can be drawn with: every angle a finite
/// number within a right angle of straight ahead, left of right and below up (runtimes have
/// answered four zero angles when asked too early).
pub(super) fn usable_field(f: &xr::Fovf) -> bool {
    let angles = [f.angle_left, f.angle_right, f.angle_up, f.angle_down];
    let within = |a: &f32| a.is_finite() && a.abs() < std::f32::consts::FRAC_PI_2;
    angles.iter().all(within) && f.angle_left < f.angle_right && f.angle_down < f.angle_up
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

#[cfg(test)]
mod tests {
    use super::*;

    fn posef(position: [f32; 3], q: [f32; 4]) -> xr::Posef {
        xr::Posef {
            orientation: xr::Quaternionf {
                x: q[0],
                y: q[1],
                z: q[2],
                w: q[3],
            },
            position: xr::Vector3f {
                x: position[0],
                y: position[1],
                z: position[2],
            },
        }
    }

    #[test]
    fn a_pose_marked_valid_is_used_only_when_it_holds_a_place_and_a_turn() {
        let turn = Quat::from_rotation_y(0.4).to_array();
        let good = posef([0.1, 1.6, -0.2], turn);
        assert!(usable_position(&good) && usable_orientation(&good));
        // A runtime's rounding (a norm off by a few parts in a thousand) is still a turn.
        let rounded = posef([0.0; 3], turn.map(|c| c * 1.004));
        assert!(usable_orientation(&rounded));
        for bad in [f32::NAN, f32::INFINITY] {
            assert!(!usable_position(&posef([0.0, bad, 0.0], turn)));
            assert!(!usable_orientation(&posef([0.0; 3], [0.0, bad, 0.0, 1.0])));
        }
        // All zero (handed out marked valid at start-up), or far from unit length.
        assert!(!usable_orientation(&posef([0.0; 3], [0.0; 4])));
        assert!(!usable_orientation(&posef([0.0; 3], [0.0, 0.0, 0.0, 0.5])));
    }

    #[test]
    fn a_field_of_view_is_one_when_it_spans_left_to_right_and_down_to_up() {
        let fov = |l: f32, r: f32, u: f32, d: f32| xr::Fovf {
            angle_left: l,
            angle_right: r,
            angle_up: u,
            angle_down: d,
        };
        // Magic Leap 2's left eye (about 44 by 53 degrees, off centre), and a narrow one.
        assert!(usable_field(&fov(-0.42, 0.35, 0.48, -0.44)));
        assert!(usable_field(&fov(0.01, 0.02, 0.02, 0.01)));
        for bad in [
            fov(0.0, 0.0, 0.0, 0.0),
            fov(0.4, -0.4, 0.4, -0.4),
            fov(-0.4, 0.4, -0.4, 0.4),
            fov(-0.4, f32::NAN, 0.4, -0.4),
            fov(-1.6, 0.4, 0.4, -0.4),
            fov(-0.4, 0.4, f32::INFINITY, -0.4),
        ] {
            assert!(!usable_field(&bad), "{bad:?}");
        }
    }
}
