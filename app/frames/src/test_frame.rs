//! A frame input for the crate's tests (the run's parts, the frame log, the look planner, the
//! motion clock).

use vitreous_trace::FrameInput;

/// A frame at time 5 ns with identity poses and no gaze.
pub fn test_frame() -> FrameInput {
    use vitreous_trace::{EyeView, Fov, Pose};
    let view = EyeView {
        pose: Pose::IDENTITY,
        fov: Fov::symmetric(1.0, 1.0),
    };
    FrameInput {
        index: 0,
        time_ns: 5,
        head: Pose::IDENTITY,
        views: [view, view],
        gaze: None,
    }
}

/// A tracker sample taken at `time_ns` with both eyes (63 mm apart, identity head) fixating
/// the point `depth_m` straight ahead.
pub fn sample_looking_at(time_ns: i64, depth_m: f32) -> vitreous_trace::GazeSample {
    use glam::Vec3;
    use vitreous_trace::{GazeRay, GazeSample};
    let target = Vec3::new(0.0, 0.0, -depth_m);
    let eye = |x: f32| {
        let origin = Vec3::new(x, 0.0, 0.0);
        GazeRay {
            origin,
            direction: (target - origin).normalize(),
            valid: true,
        }
    };
    GazeSample::binocular(time_ns, eye(-0.0315), eye(0.0315))
}

/// Frame `index` at 60 Hz (identity head) whose gaze sample, taken at the frame's time, has
/// both eyes fixating the point `depth_m` straight ahead ([`sample_looking_at`]).
pub fn frame_fixating(index: u64, depth_m: f32) -> FrameInput {
    let time_ns = 1_000_000_000 + index as i64 * 16_666_667;
    FrameInput {
        index,
        time_ns,
        gaze: Some(sample_looking_at(time_ns, depth_m)),
        ..test_frame()
    }
}
