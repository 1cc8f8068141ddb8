//! Whether a loaded scene could exist: a real plane standing between the light and the object
//! (a real wall there would shade the whole table, which neither the shadow nor the caustic
//! bake knows), and an object sunk into the floor. Each is a warning naming the scene file
//! and the fields to change, not an error: the paper's own layouts are kept loadable.

use glam::Vec3;

use crate::{Light, Object, RealPlane};

/// Depth an object may reach below the floor before it counts as sunk into it, metres: a ball
/// resting on the floor touches it within the mesh's tessellation.
pub const FLOOR_TOLERANCE_M: f32 = 0.002;

/// The warnings for a scene's static placement (its `[motion]` keyframes are not checked).
pub fn warnings(
    object: &Object,
    light: &Light,
    floor: &RealPlane,
    background: &RealPlane,
) -> Vec<String> {
    let mut out = Vec::new();
    for (name, plane) in [("background", background), ("floor", floor)] {
        if let Some(at) = crossing(plane, light.position_m, object.center_m) {
            out.push(format!(
                "the {name} ({name}.position_m, {name}.size_m) stands between the light \
                 (light.position_m) and the object (object.position_m), at [{:.2}, {:.2}, {:.2}] m: a real \
                 {name} there would shade the object and the floor around it, which neither the \
                 shadow inducer nor the caustics know; move the {name} or the light",
                at.x, at.y, at.z
            ));
        }
    }
    let depth = depth_below(floor, object);
    if depth > FLOOR_TOLERANCE_M && over(floor, object.center_m) {
        out.push(format!(
            "the object reaches {:.0} mm into the floor (object.position_m and \
             object.diameter_m against floor.position_m): a real object would rest on it; \
             raise the object",
            depth * 1000.0
        ));
    }
    out
}

/// Where the segment from `a` to `b` passes through the plane's rectangle, if it does
/// (touching an end or grazing the edge does not count).
fn crossing(plane: &RealPlane, a: Vec3, b: Vec3) -> Option<Vec3> {
    let plane_from_world = plane.world_from_plane().inverse();
    let (la, lb) = (
        plane_from_world.transform_point3(a),
        plane_from_world.transform_point3(b),
    );
    if la.z * lb.z >= 0.0 {
        return None;
    }
    let t = la.z / (la.z - lb.z);
    let hit = la + (lb - la) * t;
    (hit.x.abs() < 0.5 && hit.y.abs() < 0.5).then(|| a + (b - a) * t)
}

/// How far the object's lowest vertex lies below the floor's plane (on the side away from its
/// visible face), metres; negative when the whole object is above it.
fn depth_below(floor: &RealPlane, object: &Object) -> f32 {
    let normal = floor.normal();
    object
        .mesh
        .positions
        .iter()
        .map(|&p| -(object.world_from_model.transform_point3(p) - floor.pose.position).dot(normal))
        .fold(f32::NEG_INFINITY, f32::max)
}

/// Whether `point` lies over the floor's rectangle.
fn over(floor: &RealPlane, point: Vec3) -> bool {
    let local = floor.world_from_plane().inverse().transform_point3(point);
    local.x.abs() <= 0.5 && local.y.abs() <= 0.5
}
