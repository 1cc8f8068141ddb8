//! A frame input for the crate's tests (the run's parts, the frame log, the look planner, the
//! motion clock).

use vitreous_xr::FrameInput;

/// A frame at time 5 ns with identity poses and no gaze.
pub fn test_frame() -> FrameInput {
    use vitreous_xr::{EyeView, Fov, Pose};
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
