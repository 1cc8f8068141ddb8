//! Frame times to the scene's poses (`[motion]`): what `replay` and `run` hand the renderer
//! each frame, with the count of frames that moved.

use glam::Vec3;
use vitreous_render::ScenePose;

use crate::look::LookPlanner;
use crate::scene::{Motion, Placement, Scene, model_placement};
use crate::views;

/// Turns frame times into the scene's poses and counts the frames that moved. Owns what it
/// needs of the scene (the keyframes, the rest placement, the object's scale and centre).
#[derive(Clone, Debug)]
pub struct MotionClock {
    /// The keyframes; `None` for a scene that stands still.
    motion: Option<Motion>,
    /// Where `[object]` and `[light]` put things.
    rest: Placement,
    /// `[light] position_m` as written.
    light_in_frame_m: Vec3,
    /// The object's scale, model units to metres.
    scale: f32,
    /// The centre of the mesh's bounding box, model units.
    model_center: Vec3,
    /// Time of the first frame, the backend's clock, nanoseconds.
    start_ns: Option<i64>,
    /// The previous frame's pose.
    last: Option<ScenePose>,
    /// Frames whose pose differed from the previous frame's.
    pub moved_frames: u64,
}

impl MotionClock {
    /// A clock for `scene`; it gives poses only when the scene moves.
    pub fn new(scene: &Scene) -> MotionClock {
        MotionClock {
            motion: scene.motion.is_animated().then(|| scene.motion.clone()),
            rest: scene.rest_placement(),
            light_in_frame_m: scene.light_in_frame_m,
            scale: scene.object.scale,
            model_center: scene.object.model_center,
            start_ns: None,
            last: None,
            moved_frames: 0,
        }
    }

    /// The placement of the frame at `time_ns` (seconds from the first frame given); `None`
    /// for a scene that stands still.
    pub fn placement(&mut self, time_ns: i64) -> Option<Placement> {
        let motion = self.motion.as_ref()?;
        let start = *self.start_ns.get_or_insert(time_ns);
        Some(motion.placement_at(
            views::seconds_since(start, time_ns),
            self.rest,
            self.light_in_frame_m,
        ))
    }

    /// The renderer's pose of the frame at `time_ns`, moving the planner's object centre
    /// with it; `None` for a scene that stands still.
    pub fn pose(&mut self, time_ns: i64, planner: &mut LookPlanner) -> Option<ScenePose> {
        let placement = self.placement(time_ns)?;
        planner.set_object_center(placement.object_position_m);
        Some(self.pose_of(&placement))
    }

    /// The renderer's pose for a placement, counted as this frame's.
    pub fn pose_of(&mut self, placement: &Placement) -> ScenePose {
        let pose = ScenePose {
            world_from_model: model_placement(
                self.scale,
                self.model_center,
                placement.object_position_m,
                placement.object_rotation,
            ),
            light_position_m: placement.light_position_m,
        };
        if self.last.is_some_and(|last| last != pose) {
            self.moved_frames += 1;
        }
        self.last = Some(pose);
        pose
    }
}
