//! Whether a loaded scene could exist: a real plane standing between the light and the object
//! (a real wall there would shade the whole table, which neither the shadow nor the caustic
//! bake knows), a real plane standing between the viewer's head and the object (the object
//! would be out of sight, yet the display draws it over the plane), and an object sunk into
//! the floor. Each is a warning naming the scene file and the fields to change, not an error:
//! the paper's own layouts are kept loadable. The resting placement is checked, and so is
//! every placement its `[motion]` goes through, from the viewer's `head_position_m`.

use glam::{Mat4, Vec3};

use crate::{Light, Motion, Object, Placement, RealPlane};

/// Depth an object may reach below the floor before it counts as sunk into it, metres: a ball
/// resting on the floor touches it within the mesh's tessellation.
pub const FLOOR_TOLERANCE_M: f32 = 0.002;

/// Placements checked between two consecutive keyframe times, besides the keyframes: the
/// light's path to a moving object sweeps a surface, not a line.
pub const BETWEEN_KEYFRAMES: usize = 4;

/// Most placements checked along a motion; a longer list is checked at this many times spread
/// evenly over the motion's span.
pub const MAX_CHECKED: usize = 4096;

/// What makes a placement impossible in a real room.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Finding {
    /// A plane (`"background"` or `"floor"`) stands between the light and the object, its
    /// path crossing it here.
    Between(&'static str, Vec3),
    /// A plane stands between the viewer's head and the object, the line of sight crossing
    /// it here.
    Hidden(&'static str, Vec3),
    /// The object reaches this far into the floor, metres.
    Sunk(f32),
}

impl Finding {
    /// Whether `other` is the same kind of finding (for the same plane).
    fn same_kind(&self, other: &Finding) -> bool {
        match (self, other) {
            (Finding::Between(a, _), Finding::Between(b, _))
            | (Finding::Hidden(a, _), Finding::Hidden(b, _)) => a == b,
            (Finding::Sunk(_), Finding::Sunk(_)) => true,
            _ => false,
        }
    }
}

/// The warnings for a scene seen from `viewer_m` (`[viewer] head_position_m`): its resting
/// placement (the object and light as loaded), then the placements its `motion` goes through
/// ([`motion_warnings`]); `light_in_frame_m` is `[light] position_m` as written.
pub fn warnings(
    object: &Object,
    light: &Light,
    floor: &RealPlane,
    background: &RealPlane,
    viewer_m: Vec3,
    motion: &Motion,
    light_in_frame_m: Vec3,
) -> Vec<String> {
    let placed = Placed {
        object,
        world_from_model: object.world_from_model,
        center_m: object.center_m,
        light_m: light.position_m,
        viewer_m,
    };
    let mut out: Vec<String> = placed
        .findings(floor, background)
        .iter()
        .map(at_rest)
        .collect();
    let rest = Placement {
        object_position_m: object.center_m,
        object_rotation: object.rotation,
        light_position_m: light.position_m,
    };
    out.extend(motion_warnings(
        object,
        motion,
        rest,
        light_in_frame_m,
        viewer_m,
        floor,
        background,
    ));
    out
}

/// The warnings for the placements `motion` goes through (at every keyframe, at
/// [`BETWEEN_KEYFRAMES`] times between two, at most [`MAX_CHECKED`] in all) that the resting
/// placement `rest` does not already give, each kind once, at the first time it happens.
/// `rest_light_in_frame_m` is `[light] position_m` as written; the viewer stays at
/// `viewer_m`.
fn motion_warnings(
    object: &Object,
    motion: &Motion,
    rest: Placement,
    rest_light_in_frame_m: Vec3,
    viewer_m: Vec3,
    floor: &RealPlane,
    background: &RealPlane,
) -> Vec<String> {
    if motion.object.is_empty() && motion.light.is_empty() {
        return Vec::new();
    }
    let placed_at = |p: Placement| Placed {
        object,
        world_from_model: object.world_from_model_at(p.object_position_m, p.object_rotation),
        center_m: p.object_position_m,
        light_m: p.light_position_m,
        viewer_m,
    };
    let mut known = placed_at(rest).findings(floor, background);
    let mut out = Vec::new();
    for time_s in checked_times(motion) {
        let placement = motion.placement_at(time_s, rest, rest_light_in_frame_m);
        for finding in placed_at(placement).findings(floor, background) {
            if known.iter().any(|k| k.same_kind(&finding)) {
                continue;
            }
            out.push(in_motion(&finding, time_s, motion));
            known.push(finding);
        }
    }
    out
}

/// The times a motion is checked at, in order.
fn checked_times(motion: &Motion) -> Vec<f64> {
    let mut keys: Vec<f64> = motion
        .object
        .iter()
        .map(|k| k.time_s)
        .chain(motion.light.iter().map(|k| k.time_s))
        .collect();
    keys.sort_by(f64::total_cmp);
    keys.dedup();
    let (first, last) = (keys[0], keys[keys.len() - 1]);
    if keys.len() * (BETWEEN_KEYFRAMES + 1) > MAX_CHECKED {
        let step = (last - first) / (MAX_CHECKED - 1) as f64;
        return (0..MAX_CHECKED).map(|i| first + step * i as f64).collect();
    }
    let mut times = vec![first];
    for pair in keys.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for i in 1..=BETWEEN_KEYFRAMES + 1 {
            times.push(a + (b - a) * i as f64 / (BETWEEN_KEYFRAMES + 1) as f64);
        }
    }
    times
}

/// The object and the light at one placement.
struct Placed<'a> {
    object: &'a Object,
    world_from_model: Mat4,
    center_m: Vec3,
    light_m: Vec3,
    /// The viewer's head.
    viewer_m: Vec3,
}

impl Placed<'_> {
    fn findings(&self, floor: &RealPlane, background: &RealPlane) -> Vec<Finding> {
        let mut out = Vec::new();
        for (name, plane) in [("background", background), ("floor", floor)] {
            if let Some(at) = crossing(plane, self.light_m, self.center_m) {
                out.push(Finding::Between(name, at));
            }
            if let Some(at) = crossing(plane, self.viewer_m, self.center_m) {
                out.push(Finding::Hidden(name, at));
            }
        }
        // No vertex reaches further than the bounding sphere: most placements need no look
        // at the mesh.
        let centre_height = (self.center_m - floor.pose.position).dot(floor.normal());
        if self.object.radius_m - centre_height > FLOOR_TOLERANCE_M {
            let depth = self.depth_below(floor);
            if depth > FLOOR_TOLERANCE_M && over(floor, self.center_m) {
                out.push(Finding::Sunk(depth));
            }
        }
        out
    }

    /// How far the object's lowest vertex lies below the floor's plane (on the side away from
    /// its visible face), metres; negative when the whole object is above it.
    fn depth_below(&self, floor: &RealPlane) -> f32 {
        let normal = floor.normal();
        self.object
            .mesh
            .positions
            .iter()
            .map(|&p| {
                -(self.world_from_model.transform_point3(p) - floor.pose.position).dot(normal)
            })
            .fold(f32::NEG_INFINITY, f32::max)
    }
}

/// The warning for a finding at the resting placement.
fn at_rest(finding: &Finding) -> String {
    match *finding {
        Finding::Between(name, at) => format!(
            "the {name} ({name}.position_m, {name}.size_m) stands between the light \
             (light.position_m) and the object (object.position_m), at [{:.2}, {:.2}, {:.2}] m: a \
             real {name} there would shade the object and the floor around it, which neither the \
             shadow inducer nor the caustics know; move the {name} or the light",
            at.x, at.y, at.z
        ),
        Finding::Hidden(name, at) => format!(
            "the {name} ({name}.position_m, {name}.size_m) stands between the viewer \
             (viewer.head_position_m) and the object (object.position_m), at [{:.2}, {:.2}, \
             {:.2}] m: the viewer could not see a real object there, the {name} hides it, yet \
             the display draws it over the {name}; move the object or the {name}",
            at.x, at.y, at.z
        ),
        Finding::Sunk(depth) => format!(
            "the object reaches {:.0} mm into the floor (object.position_m and \
             object.diameter_m against floor.position_m): a real object would rest on it; \
             raise the object",
            depth * 1000.0
        ),
    }
}

/// The warning for a finding `time_s` seconds into `motion`.
fn in_motion(finding: &Finding, time_s: f64, motion: &Motion) -> String {
    let keys = match (motion.object.is_empty(), motion.light.is_empty()) {
        (false, false) => "motion.object and motion.light",
        (false, true) => "motion.object",
        (true, _) => "motion.light",
    };
    match *finding {
        Finding::Between(name, at) => format!(
            "{time_s:.2} s into its motion ({keys}), the {name} ({name}.position_m, \
             {name}.size_m) stands between the light and the object, at [{:.2}, {:.2}, {:.2}] m: \
             a real {name} there would shade the object and the floor around it, which neither \
             the shadow inducer nor the caustics know; change the keyframes or move the {name}",
            at.x, at.y, at.z
        ),
        Finding::Hidden(name, at) => format!(
            "{time_s:.2} s into its motion ({keys}), the {name} ({name}.position_m, \
             {name}.size_m) stands between the viewer (viewer.head_position_m) and the object, \
             at [{:.2}, {:.2}, {:.2}] m: the viewer could not see a real object there, the \
             {name} hides it, yet the display draws it over the {name}; change the keyframes \
             or move the {name}",
            at.x, at.y, at.z
        ),
        Finding::Sunk(depth) => format!(
            "{time_s:.2} s into its motion ({keys}), the object reaches {:.0} mm into the floor \
             (floor.position_m, object.diameter_m): a real object would rest on it; raise the \
             keyframes",
            depth * 1000.0
        ),
    }
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

/// Whether `point` lies over the floor's rectangle.
fn over(floor: &RealPlane, point: Vec3) -> bool {
    let local = floor.world_from_plane().inverse().transform_point3(point);
    local.x.abs() <= 0.5 && local.y.abs() <= 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LightKey, ObjectKey};
    use glam::Quat;

    fn light_keys(times: &[f64]) -> Motion {
        Motion {
            light: times
                .iter()
                .map(|&time_s| LightKey {
                    time_s,
                    position_m: Vec3::ZERO,
                })
                .collect(),
            ..Motion::default()
        }
    }

    #[test]
    fn keyframes_and_points_between_them_are_checked_and_long_motions_are_capped() {
        let mut motion = light_keys(&[0.0, 1.0, 3.0]);
        motion.object.push(ObjectKey {
            time_s: 1.0,
            position_m: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        });
        let times = checked_times(&motion);
        // Both lists' keyframes once each (1 s is in both), four checks between two.
        assert_eq!(times.len(), 1 + 2 * (BETWEEN_KEYFRAMES + 1));
        assert_eq!((times[0], times[5], times[10]), (0.0, 1.0, 3.0));
        assert!(times.windows(2).all(|w| w[0] < w[1]));
        let long = light_keys(&(0..10_000).map(f64::from).collect::<Vec<_>>());
        let times = checked_times(&long);
        assert_eq!(times.len(), MAX_CHECKED);
        assert_eq!((times[0], times[MAX_CHECKED - 1]), (0.0, 9999.0));
    }
}
