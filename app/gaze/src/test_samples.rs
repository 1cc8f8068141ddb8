//! Tracker samples the decisions' tests are made of.

use glam::Vec3;
use vitreous_trace::{GazeRay, GazeSample};

/// A sample at `t_ns` whose eyes (63 mm apart) look at a point `depth_m` ahead, `offset_deg` to
/// the right.
pub(crate) fn looking(t_ns: i64, depth_m: f32, offset_deg: f32) -> GazeSample {
    let a = offset_deg.to_radians();
    let target = Vec3::new(depth_m * a.sin(), 0.0, -depth_m * a.cos());
    let eye = |x: f32| GazeRay {
        origin: Vec3::new(x, 0.0, 0.0),
        direction: (target - Vec3::new(x, 0.0, 0.0)).normalize(),
        valid: true,
    };
    GazeSample {
        left: eye(-0.0315),
        right: eye(0.0315),
        ..GazeSample::none(t_ns)
    }
}
