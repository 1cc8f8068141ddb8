//! Live controls: moving and turning the glass, placing it where the gaze meets the floor,
//! moving the light, and re-registering the world, in `vitreous run` and `vitreous view`, and
//! their replay from a recorded trace (version 1.2's edit lines).
//!
//! An edit never replaces the scene's own placement: it *offsets* it. The object's position
//! is the keyframed (or resting) position plus [`EditState::object_offset_m`], its rotation
//! the keyframed rotation followed by [`EditState::object_turn`] (a turn about the vertical
//! through its centre), the light's position the keyframed one plus
//! [`EditState::light_offset_m`] (plus the object's offset when the light is in the object's
//! frame). A `[motion]` scene keeps moving after an edit, offset by it.
//!
//! Re-registration (the paper's keyboard correction for tracking drift) moves the whole
//! registered world (floor, background, object, light) against the tracking; the backend
//! carries it out on the head pose (the OpenXR session's scene placement, the viewer's head),
//! so the recorded head poses already hold it and a replay only reports it.

use std::fmt;

use glam::{Quat, Vec3};
use vitreous_trace::FrameInput;
use vitreous_trace::format::EditRecord;

/// The fine and coarse move steps of the keys and buttons, metres (1 mm, 1 cm).
pub const MOVE_STEPS_M: [f32; 2] = [0.001, 0.01];

/// The fine and coarse turn steps of the keys and buttons, degrees.
pub const TURN_STEPS_DEG: [f32; 2] = [1.0, 10.0];

/// The largest single move accepted from a command line, metres.
pub const MAX_MOVE_M: f32 = 1.0;

/// Farthest floor point the place ray may reach, metres.
pub const MAX_PLACE_DISTANCE_M: f32 = 20.0;

/// A world axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// +x: right.
    X,
    /// +y: up.
    Y,
    /// +z: towards the viewer at the start (the scene looks down -z).
    Z,
}

impl Axis {
    /// The unit vector.
    pub fn unit(self) -> Vec3 {
        match self {
            Axis::X => Vec3::X,
            Axis::Y => Vec3::Y,
            Axis::Z => Vec3::Z,
        }
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }

    fn parse(s: &str) -> Option<Axis> {
        Some(match s {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            _ => return None,
        })
    }
}

/// One live control.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneEdit {
    /// Move the object along a world axis by this many metres.
    MoveObject(Axis, f32),
    /// Turn the object about the vertical through its centre, degrees (positive: counter-
    /// clockwise seen from above).
    TurnObject(f32),
    /// Put the object where the gaze ray (the head's forward ray without gaze) meets the
    /// floor, keeping its height above the floor.
    PlaceObject,
    /// Move the light along a world axis, metres.
    MoveLight(Axis, f32),
    /// Move the whole registered world along an axis, metres (re-registration).
    Register(Axis, f32),
}

impl SceneEdit {
    /// Parses a command: `object AXIS MM`, `turn DEG`, `place`, `light AXIS MM`,
    /// `register AXIS MM` (AXIS is x, y or z; MM a signed step in millimetres).
    pub fn parse(text: &str) -> Result<SceneEdit, String> {
        let words: Vec<&str> = text.split_whitespace().collect();
        let usage = "expected `object x|y|z MM`, `turn DEG`, `place`, `light x|y|z MM` or \
                     `register x|y|z MM`";
        let step_m = |axis: &str, mm: &str| -> Result<(Axis, f32), String> {
            let axis = Axis::parse(axis).ok_or_else(|| format!("axis `{axis}`: {usage}"))?;
            let m = mm
                .parse::<f32>()
                .ok()
                .map(|mm| mm / 1000.0)
                .filter(|m| m.is_finite() && *m != 0.0 && m.abs() <= MAX_MOVE_M)
                .ok_or_else(|| {
                    format!(
                        "step `{mm}`: expected non-zero millimetres within +-{}",
                        MAX_MOVE_M * 1000.0
                    )
                })?;
            Ok((axis, m))
        };
        match words.as_slice() {
            ["object", axis, mm] => step_m(axis, mm).map(|(a, m)| SceneEdit::MoveObject(a, m)),
            ["light", axis, mm] => step_m(axis, mm).map(|(a, m)| SceneEdit::MoveLight(a, m)),
            ["register", axis, mm] => step_m(axis, mm).map(|(a, m)| SceneEdit::Register(a, m)),
            ["turn", deg] => deg
                .parse::<f32>()
                .ok()
                .filter(|d| d.is_finite() && *d != 0.0 && d.abs() <= 180.0)
                .map(SceneEdit::TurnObject)
                .ok_or_else(|| format!("turn `{deg}`: expected non-zero degrees within +-180")),
            ["place"] => Ok(SceneEdit::PlaceObject),
            _ => Err(format!("`{}`: {usage}", text.trim())),
        }
    }

    /// The name a trace's edit line gives it (`object+x10mm`, `turn-1`, `place`, ...).
    pub fn action(&self) -> String {
        let mm = |m: f32| {
            let mm = m * 1000.0;
            format!("{}{}mm", if mm < 0.0 { "-" } else { "+" }, mm.abs())
        };
        match self {
            SceneEdit::MoveObject(a, m) => format!("object{}{}", mm(*m), a.name()),
            SceneEdit::TurnObject(d) => {
                format!("turn{}{}", if *d < 0.0 { "-" } else { "+" }, d.abs())
            }
            SceneEdit::PlaceObject => "place".into(),
            SceneEdit::MoveLight(a, m) => format!("light{}{}", mm(*m), a.name()),
            SceneEdit::Register(a, m) => format!("register{}{}", mm(*m), a.name()),
        }
    }
}

impl fmt::Display for SceneEdit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneEdit::MoveObject(a, m) => {
                write!(f, "move the object {:+.1} mm along {}", m * 1e3, a.name())
            }
            SceneEdit::TurnObject(d) => write!(f, "turn the object {d:+} deg"),
            SceneEdit::PlaceObject => {
                f.write_str("place the object where the gaze meets the floor")
            }
            SceneEdit::MoveLight(a, m) => {
                write!(f, "move the light {:+.1} mm along {}", m * 1e3, a.name())
            }
            SceneEdit::Register(a, m) => write!(
                f,
                "move the registered world {:+.1} mm along {}",
                m * 1e3,
                a.name()
            ),
        }
    }
}

/// What the edits so far add to the scene's own placement (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditState {
    /// Added to the object's position, world axes, metres.
    pub object_offset_m: Vec3,
    /// Turn about the object's centre after its own rotation.
    pub object_turn: Quat,
    /// Added to the light's position, world axes, metres.
    pub light_offset_m: Vec3,
    /// The re-registration so far, metres (carried out by the backend; reported).
    pub world_offset_m: Vec3,
    /// The light's share of the floor's light the room's light estimate set (`None`: the
    /// scene's).
    pub light_share: Option<f32>,
}

impl Default for EditState {
    fn default() -> EditState {
        EditState {
            object_offset_m: Vec3::ZERO,
            object_turn: Quat::IDENTITY,
            light_offset_m: Vec3::ZERO,
            world_offset_m: Vec3::ZERO,
            light_share: None,
        }
    }
}

impl EditState {
    /// Whether the object or the light is away from the scene's placement (what a caustic
    /// bake was made for).
    pub fn moves_object_or_light(&self) -> bool {
        self.object_offset_m != Vec3::ZERO
            || self.object_turn != Quat::IDENTITY
            || self.light_offset_m != Vec3::ZERO
    }

    /// The trace's line for this state after `action` at `time_ns`.
    pub fn record(&self, time_ns: i64, action: String) -> EditRecord {
        EditRecord {
            time_ns,
            action,
            object_offset_m: self.object_offset_m,
            object_turn: self.object_turn,
            light_offset_m: self.light_offset_m,
            world_offset_m: self.world_offset_m,
            light_share: self.light_share,
        }
    }

    /// The state a trace's edit line leaves.
    pub fn of_record(record: &EditRecord) -> EditState {
        EditState {
            object_offset_m: record.object_offset_m,
            object_turn: record.object_turn,
            light_offset_m: record.light_offset_m,
            world_offset_m: record.world_offset_m,
            light_share: record.light_share,
        }
    }
}

/// The ray the object is placed along: the gaze (the combined ray, else the mean of the valid
/// eyes' rays) or, without a valid gaze, the head's forward ray; world frame, unit direction.
pub fn place_ray(input: &FrameInput) -> (Vec3, Vec3) {
    let head = input.head;
    let gaze = input.gaze.and_then(|g| {
        if let Some(c) = g.combined.filter(|c| c.valid) {
            return Some((c.origin, c.direction));
        }
        let valid: Vec<_> = [g.left, g.right].into_iter().filter(|r| r.valid).collect();
        if valid.is_empty() {
            return None;
        }
        let n = valid.len() as f32;
        let origin = valid.iter().map(|r| r.origin).sum::<Vec3>() / n;
        let dir = valid.iter().map(|r| r.direction).sum::<Vec3>();
        (dir.length_squared() > 1e-12).then(|| (origin, dir.normalize()))
    });
    let (origin, dir) = gaze.unwrap_or((Vec3::ZERO, Vec3::NEG_Z));
    (
        head.transform_point(origin),
        (head.orientation * dir).normalize(),
    )
}

/// Where a ray meets a plane (point, unit normal) in front of its origin, within
/// [`MAX_PLACE_DISTANCE_M`]; `None` when it does not.
pub fn ray_meets_plane(origin: Vec3, dir: Vec3, point: Vec3, normal: Vec3) -> Option<Vec3> {
    let denom = dir.dot(normal);
    if denom.abs() < 1e-4 {
        return None;
    }
    let t = (point - origin).dot(normal) / denom;
    (t > 0.0 && t <= MAX_PLACE_DISTANCE_M).then(|| origin + dir * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_trace::{EyeView, Fov, GazeRay, GazeSample, Pose};

    fn frame(head: Pose, gaze: Option<GazeSample>) -> FrameInput {
        let view = EyeView {
            pose: head,
            fov: Fov::symmetric(1.0, 1.0),
        };
        FrameInput {
            index: 0,
            time_ns: 0,
            head,
            views: [view, view],
            gaze,
        }
    }

    #[test]
    fn commands_parse_into_edits_and_name_their_actions() {
        assert_eq!(
            SceneEdit::parse("object x 10").unwrap(),
            SceneEdit::MoveObject(Axis::X, 0.01)
        );
        assert_eq!(
            SceneEdit::parse(" light y -1 ").unwrap(),
            SceneEdit::MoveLight(Axis::Y, -0.001)
        );
        assert_eq!(
            SceneEdit::parse("turn -10").unwrap(),
            SceneEdit::TurnObject(-10.0)
        );
        assert_eq!(SceneEdit::parse("place").unwrap(), SceneEdit::PlaceObject);
        assert_eq!(
            SceneEdit::parse("register z 10").unwrap().action(),
            "register+10mmz"
        );
        assert_eq!(SceneEdit::TurnObject(-1.0).action(), "turn-1");
        for bad in [
            "object w 1",
            "object x 0",
            "object x 5000",
            "turn",
            "turn nan",
            "jump",
            "",
        ] {
            assert!(SceneEdit::parse(bad).is_err(), "{bad}");
        }
        for edit in [
            SceneEdit::MoveObject(Axis::Z, -0.001),
            SceneEdit::TurnObject(10.0),
            SceneEdit::PlaceObject,
            SceneEdit::Register(Axis::Y, 0.01),
        ] {
            assert!(
                vitreous_trace::format::valid_action(&edit.action()),
                "{edit}"
            );
        }
    }

    #[test]
    fn the_place_ray_is_the_gaze_else_the_head_and_meets_the_floor() {
        let head = Pose {
            position: Vec3::new(0.0, 1.0, 0.0),
            orientation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        };
        // No gaze: the head looks down world -x (turned left), parallel to the floor.
        let (o, d) = place_ray(&frame(head, None));
        assert!(o.abs_diff_eq(head.position, 1e-6) && d.abs_diff_eq(Vec3::NEG_X, 1e-6));
        let floor = (Vec3::ZERO, Vec3::Y);
        assert_eq!(ray_meets_plane(o, d, floor.0, floor.1), None);
        // Both eyes look 45 degrees down ahead: the floor 1 m ahead (world -x).
        let down = Vec3::new(0.0, -1.0, -1.0).normalize();
        let ray = |x: f32| GazeRay {
            origin: Vec3::new(x, 0.0, 0.0),
            direction: down,
            valid: true,
        };
        let gaze = GazeSample::binocular(0, ray(-0.03), ray(0.03));
        let (o, d) = place_ray(&frame(head, Some(gaze)));
        let hit = ray_meets_plane(o, d, floor.0, floor.1).unwrap();
        assert!(hit.abs_diff_eq(Vec3::new(-1.0, 0.0, 0.0), 1e-5), "{hit}");
        // Looking up never meets the floor below.
        assert_eq!(ray_meets_plane(o, -d, floor.0, floor.1), None);
    }
}
