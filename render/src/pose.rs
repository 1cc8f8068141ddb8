//! Where the glass object and the light are for a frame: the part of the scene that may move.

use glam::{Mat4, Vec3};

use crate::scene::SceneDesc;

/// The object's placement and the light's position for a frame. A renderer starts with the
/// pose of its [`SceneDesc`]; [`crate::Renderer::set_pose`] moves both from the next frame on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenePose {
    /// Model to world transform of the object.
    pub world_from_model: Mat4,
    /// World position of the point light, metres.
    pub light_position_m: Vec3,
}

impl ScenePose {
    /// The pose a scene description starts in.
    pub fn of(desc: &SceneDesc) -> ScenePose {
        ScenePose {
            world_from_model: desc.world_from_model,
            light_position_m: desc.light.position_m,
        }
    }
}
