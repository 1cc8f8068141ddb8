//! Frame times to the scene's poses (`[motion]`, offset by the live controls' edits): what
//! `replay`, `run` and `view` hand the renderer each frame, with the count of frames that
//! moved.

use glam::{Quat, Vec3};
use serde::Serialize;
use vitreous_render::ScenePose;
use vitreous_trace::FrameInput;
use vitreous_trace::format::EditRecord;

use vitreous_trace::light::{MIN_TURN_DEG, angle_deg, light_position_along};

use crate::look::LookPlanner;
use crate::render_desc;
use crate::scene_edit::{EditState, SceneEdit, place_ray, ray_meets_plane};

/// The action of the edit line that moves the light to the room's estimated light.
pub const LIGHT_ESTIMATE_ACTION: &str = "light-estimate";

/// Smallest change of the light's share of the floor's light that an estimate makes.
pub const MIN_SHARE_STEP: f32 = 0.01;
use vitreous_scene::{CausticsMode, Motion, Placement, Scene, model_placement};

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
    /// The previous frame's placement (for the logs and summaries).
    last_placement: Option<Placement>,
    /// Frames whose pose differed from the previous frame's.
    pub moved_frames: u64,
    /// The light's keyframes are offsets from the object (`[light] frame = "object"`): it
    /// follows the object's edits too.
    light_follows_object: bool,
    /// The registered floor: a point and its unit normal (where the object is placed).
    floor: (Vec3, Vec3),
    /// The caustics come from a bake (made for the scene's own placement).
    baked_caustics: bool,
    /// A stale bake was reported.
    stale_reported: bool,
    /// What the live controls changed so far.
    edits: EditState,
    /// Edits made or replayed.
    pub edit_count: u64,
    /// `[light] share`.
    scene_share: f32,
}

/// Where the object and the light were at the end, as the summaries report it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FinalPlacement {
    /// World position of the object's centre, metres.
    pub object_position_m: [f32; 3],
    /// The object's orientation, quaternion x, y, z, w.
    pub object_rotation_xyzw: [f32; 4],
    /// World position of the light, metres.
    pub light_position_m: [f32; 3],
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
            last_placement: None,
            moved_frames: 0,
            light_follows_object: scene.motion.light_follows_object,
            floor: (scene.floor.pose.position, scene.floor.normal()),
            baked_caustics: scene.caustics.mode == CausticsMode::Baked,
            stale_reported: false,
            edits: EditState::default(),
            edit_count: 0,
            scene_share: scene.light.share,
        }
    }

    /// The placement of the frame at `time_ns` (seconds from the first frame given), edits
    /// included; `None` for a scene that stands still and was never moved (once moved, edits
    /// undone give the resting placement back to the renderer).
    pub fn placement(&mut self, time_ns: i64) -> Option<Placement> {
        if self.motion.is_none()
            && !self.edits.moves_object_or_light()
            && self.last_placement.is_none()
        {
            return None;
        }
        let base = self.keyed_placement(time_ns);
        Some(self.edited(base))
    }

    /// The scene's own placement at `time_ns`: the keyframes', or the resting one.
    fn keyed_placement(&mut self, time_ns: i64) -> Placement {
        let start = *self.start_ns.get_or_insert(time_ns);
        match &self.motion {
            Some(motion) => motion.placement_at(
                render_desc::seconds_since(start, time_ns),
                self.rest,
                self.light_in_frame_m,
            ),
            None => self.rest,
        }
    }

    /// `base` offset by the edits (the rule in [`crate::scene_edit`]).
    fn edited(&self, base: Placement) -> Placement {
        let e = &self.edits;
        let light_follows = if self.light_follows_object {
            e.object_offset_m
        } else {
            Vec3::ZERO
        };
        Placement {
            object_position_m: base.object_position_m + e.object_offset_m,
            object_rotation: (e.object_turn * base.object_rotation).normalize(),
            light_position_m: base.light_position_m + e.light_offset_m + light_follows,
        }
    }

    /// What the edits so far change.
    pub fn edits(&self) -> EditState {
        self.edits
    }

    /// Applies a live control to the frame `input` (whose rays place the object); returns
    /// the trace's edit line for it, or why it was not applied (a place ray missing the
    /// floor). Logs the new placement.
    pub fn edit(&mut self, edit: SceneEdit, input: &FrameInput) -> Result<EditRecord, String> {
        let e = &mut self.edits;
        match edit {
            SceneEdit::MoveObject(axis, m) => e.object_offset_m += axis.unit() * m,
            SceneEdit::TurnObject(deg) => {
                e.object_turn =
                    (Quat::from_rotation_y(deg.to_radians()) * e.object_turn).normalize();
            }
            SceneEdit::MoveLight(axis, m) => e.light_offset_m += axis.unit() * m,
            SceneEdit::Register(axis, m) => e.world_offset_m += axis.unit() * m,
            SceneEdit::PlaceObject => {
                let (origin, dir) = place_ray(input);
                let (floor_point, normal) = self.floor;
                let hit = ray_meets_plane(origin, dir, floor_point, normal).ok_or_else(|| {
                    format!(
                        "frame {}: the gaze ray does not meet the floor within {} m; the object \
                         stays",
                        input.index,
                        crate::scene_edit::MAX_PLACE_DISTANCE_M
                    )
                })?;
                let base = self.keyed_placement(input.time_ns);
                let now = self.edited(base).object_position_m;
                let height = (now - floor_point).dot(normal);
                self.edits.object_offset_m += hit + normal * height - now;
            }
        }
        Ok(self.applied(edit, &edit, input))
    }

    /// Places the object over `point` in x and z, its height above the floor kept: a place
    /// on a detected plane, whose height the world's registration takes (the caller moves the
    /// world so that the floor lies on the plane). Returns the trace's edit line.
    pub fn place_over(&mut self, point: Vec3, input: &FrameInput) -> EditRecord {
        let base = self.keyed_placement(input.time_ns);
        let now = self.edited(base).object_position_m;
        self.edits.object_offset_m += Vec3::new(point.x - now.x, 0.0, point.z - now.z);
        self.applied(
            SceneEdit::PlaceObject,
            &"place the object on a detected plane under the gaze",
            input,
        )
    }

    /// The scene's floor: a point on it and its normal, in the scene frame.
    pub fn floor(&self) -> (Vec3, Vec3) {
        self.floor
    }

    /// Turns the light about the object, at its distance, so that its light travels along
    /// `direction` (the room's main light as the headset estimates it), and takes `share` as
    /// its share of the floor's light: an edit like the keyboard's light moves, recorded as
    /// [`LIGHT_ESTIMATE_ACTION`]. `None`, and nothing done, when the light already travels
    /// within [`MIN_TURN_DEG`] of it and the share moved by less than [`MIN_SHARE_STEP`].
    pub fn follow_light(
        &mut self,
        direction: Vec3,
        share: Option<f32>,
        input: &FrameInput,
    ) -> Option<EditRecord> {
        let base = self.keyed_placement(input.time_ns);
        let now = self.edited(base);
        let (center, light) = (now.object_position_m, now.light_position_m);
        let turn = angle_deg(center - light, direction);
        // A NaN turn (a zero direction) is no turn.
        let turns = turn >= MIN_TURN_DEG;
        // To a thousandth, as recorded; a share that cannot be known leaves the last one.
        let share = share
            .filter(|s| s.is_finite())
            .map(|s| (s.clamp(0.0, 1.0) * 1000.0).round() / 1000.0);
        let shares = share.is_some_and(|s| {
            (s - self.edits.light_share.unwrap_or(self.scene_share)).abs() >= MIN_SHARE_STEP
        });
        if !turns && !shares {
            return None;
        }
        if turns {
            self.edits.light_offset_m += light_position_along(center, light, direction) - light;
        }
        if shares {
            self.edits.light_share = share;
        }
        let what = format!(
            "the light turned {:.2} deg about the object to the room's light, its share of the \
             floor's light {:.3}",
            if turns { turn } else { 0.0 },
            self.light_share()
        );
        Some(self.applied_as(LIGHT_ESTIMATE_ACTION.into(), &what, input))
    }

    /// The light's share of the floor's light: the room's light estimate's, else the scene's.
    pub fn light_share(&self) -> f32 {
        self.edits.light_share.unwrap_or(self.scene_share)
    }

    /// Counts and logs (as `what`) an edit just applied; its trace line.
    fn applied(
        &mut self,
        edit: SceneEdit,
        what: &dyn std::fmt::Display,
        input: &FrameInput,
    ) -> EditRecord {
        self.applied_as(edit.action(), what, input)
    }

    /// Counts and logs (as `what`) an edit just applied; its trace line, named `action`.
    fn applied_as(
        &mut self,
        action: String,
        what: &dyn std::fmt::Display,
        input: &FrameInput,
    ) -> EditRecord {
        self.edit_count += 1;
        let base = self.keyed_placement(input.time_ns);
        let p = self.edited(base);
        let e = &self.edits;
        tracing::info!(
            "frame {}: {what}: object at ({:.4}, {:.4}, {:.4}) m turned {:+.1} deg, light at \
             ({:.4}, {:.4}, {:.4}) m, world registered {:+.4} {:+.4} {:+.4} m",
            input.index,
            p.object_position_m.x,
            p.object_position_m.y,
            p.object_position_m.z,
            turn_deg(e.object_turn),
            p.light_position_m.x,
            p.light_position_m.y,
            p.light_position_m.z,
            e.world_offset_m.x,
            e.world_offset_m.y,
            e.world_offset_m.z,
        );
        self.edits.record(input.time_ns, action)
    }

    /// Takes the edit state of a recorded edit line (`vitreous replay`), logged like the
    /// live edit.
    pub fn replay_edit(&mut self, record: &EditRecord, frame: u64) {
        self.edits = EditState::of_record(record);
        self.edit_count += 1;
        let o = self.edits.object_offset_m;
        tracing::info!(
            "frame {frame}: recorded edit {} at {} ns: object offset ({:+.4}, {:+.4}, {:+.4}) m \
             turned {:+.1} deg",
            record.action,
            record.time_ns,
            o.x,
            o.y,
            o.z,
            turn_deg(self.edits.object_turn)
        );
    }

    /// Sets the edit state without counting or logging it (a played trace going back before
    /// its first edit).
    pub fn set_edits(&mut self, state: EditState) {
        self.edits = state;
    }

    /// Whether the caustics may be drawn: not from a bake once the edits moved the object
    /// or the light away from the placement it was made for (reported once).
    pub fn caustics_valid(&mut self) -> bool {
        if !(self.baked_caustics && self.edits.moves_object_or_light()) {
            return true;
        }
        if !self.stale_reported {
            self.stale_reported = true;
            tracing::warn!(
                "the caustic bake was made for the scene's own placement of the object and \
                 light; with them moved it would be wrong, so caustics are off while they are away \
                 from it (use [caustics] mode = \"live\" to see them follow)"
            );
        }
        false
    }

    /// The placement of the last frame posed (`None` while the scene never moved).
    pub fn last_placement(&self) -> Option<Placement> {
        self.last_placement
    }

    /// Where the object and light were in the last frame posed, as `summary.json` gives it.
    pub fn final_placement(&self) -> Option<FinalPlacement> {
        self.last_placement.map(|p| FinalPlacement {
            object_position_m: p.object_position_m.to_array(),
            object_rotation_xyzw: p.object_rotation.to_array(),
            light_position_m: p.light_position_m.to_array(),
        })
    }

    /// The renderer's pose of the frame at `time_ns`, moving the planner's object centre
    /// with it; `None` for a scene that stands still.
    pub fn pose(&mut self, time_ns: i64, planner: &mut LookPlanner) -> Option<ScenePose> {
        let placement = self.placement(time_ns)?;
        let pose = self.pose_of(&placement);
        planner.set_object_pose(placement.object_position_m, pose.world_from_model);
        Some(pose)
    }

    /// The renderer's pose for a placement, counted as this frame's.
    pub fn pose_of(&mut self, placement: &Placement) -> ScenePose {
        self.last_placement = Some(*placement);
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

/// The angle of a turn about the vertical, degrees (positive: counter-clockwise from above).
fn turn_deg(turn: Quat) -> f32 {
    let (axis, angle) = turn.to_axis_angle();
    (angle * axis.y.signum()).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_edit::Axis;

    fn clock(motion: Option<Motion>) -> MotionClock {
        MotionClock {
            motion,
            rest: Placement {
                object_position_m: Vec3::new(0.3, 0.1, -0.5),
                object_rotation: Quat::IDENTITY,
                light_position_m: Vec3::new(0.0, 1.0, -1.0),
            },
            light_in_frame_m: Vec3::new(0.0, 1.0, -1.0),
            scale: 1.0,
            model_center: Vec3::ZERO,
            start_ns: None,
            last: None,
            last_placement: None,
            moved_frames: 0,
            light_follows_object: false,
            floor: (Vec3::ZERO, Vec3::Y),
            baked_caustics: true,
            stale_reported: false,
            edits: EditState::default(),
            edit_count: 0,
            scene_share: 1.0,
        }
    }

    fn input(time_ns: i64) -> FrameInput {
        let mut f = crate::test_frame::test_frame();
        f.time_ns = time_ns;
        // Head 1 m above the floor at z = 0, looking 45 degrees down ahead.
        f.head = vitreous_trace::Pose {
            position: Vec3::new(0.0, 1.0, 0.0),
            orientation: Quat::from_rotation_x(-std::f32::consts::FRAC_PI_4),
        };
        f
    }

    #[test]
    fn the_light_turns_about_the_object_to_the_estimate_and_only_past_the_threshold() {
        let mut c = clock(None);
        let object = Vec3::new(0.3, 0.1, -0.5);
        let light = Vec3::new(0.0, 1.0, -1.0);
        let along = (object - light).normalize();
        // The estimate agrees with the scene's light and share: nothing moves.
        assert!(c.follow_light(along, Some(0.995), &input(0)).is_none());
        let nearly = Quat::from_rotation_y(0.2f32.to_radians()) * along;
        assert!(c.follow_light(nearly, None, &input(1)).is_none());
        assert_eq!(c.edit_count, 0);
        // Turned 30 degrees about the vertical: the light goes round the object, as far away.
        let turned = Quat::from_rotation_y(30f32.to_radians()) * along;
        let record = c.follow_light(turned, None, &input(2)).expect("an edit");
        assert_eq!(record.action, LIGHT_ESTIMATE_ACTION);
        assert!(vitreous_trace::format::valid_action(&record.action));
        let now = c.placement(2).expect("the light moved");
        let arm = now.light_position_m - now.object_position_m;
        assert!((arm.length() - (light - object).length()).abs() < 1e-5);
        assert!((arm.normalize() + turned).length() < 1e-5, "{arm}");
        assert_eq!(now.object_position_m, object);
        assert_eq!(c.edit_count, 1);
        // The recorded state repeats it.
        assert_eq!(EditState::of_record(&record), c.edits());
        assert_eq!((record.light_share, c.light_share()), (None, 1.0));
        // The same way with another share: only the share changes, recorded to a thousandth.
        let shared = c
            .follow_light(turned, Some(0.61234), &input(3))
            .expect("an edit");
        assert_eq!((shared.light_share, c.light_share()), (Some(0.612), 0.612));
        assert_eq!(shared.light_offset_m, record.light_offset_m);
        assert!(c.follow_light(turned, Some(0.615), &input(4)).is_none());
        assert!(c.follow_light(turned, Some(f32::NAN), &input(5)).is_none());
        assert_eq!(c.light_share(), 0.612);
    }

    #[test]
    fn edits_offset_the_keyframed_pose_and_count_as_moves() {
        use vitreous_scene::ObjectKey;
        let motion = Motion {
            object: vec![
                ObjectKey {
                    time_s: 0.0,
                    position_m: Vec3::new(0.0, 0.1, -1.0),
                    rotation: Quat::IDENTITY,
                },
                ObjectKey {
                    time_s: 1.0,
                    position_m: Vec3::new(1.0, 0.1, -1.0),
                    rotation: Quat::IDENTITY,
                },
            ],
            ..Motion::default()
        };
        let mut c = clock(Some(motion));
        let mut planner = LookPlanner::new(vitreous_render::Look::default(), None);
        c.pose(0, &mut planner);
        c.edit(SceneEdit::MoveObject(Axis::Z, 0.01), &input(0))
            .unwrap();
        let record = c.edit(SceneEdit::TurnObject(10.0), &input(0)).unwrap();
        assert_eq!(record.action, "turn+10");
        assert!((turn_deg(record.object_turn) - 10.0).abs() < 1e-4);
        // Half way through the keyframes: the keyframed x, the edited z, the turn.
        let p = c.placement(500_000_000).unwrap();
        assert!(
            p.object_position_m
                .abs_diff_eq(Vec3::new(0.5, 0.1, -0.99), 1e-5),
            "{p:?}"
        );
        assert!(
            p.object_rotation
                .abs_diff_eq(Quat::from_rotation_y(10f32.to_radians()), 1e-5)
        );
        c.pose(500_000_000, &mut planner);
        assert_eq!(c.moved_frames, 1);
        assert_eq!(c.edit_count, 2);
    }

    #[test]
    fn undone_edits_give_the_resting_placement_back() {
        let mut c = clock(None);
        let mut planner = LookPlanner::new(vitreous_render::Look::default(), None);
        c.edit(SceneEdit::MoveObject(Axis::X, 0.01), &input(0))
            .unwrap();
        c.pose(0, &mut planner).unwrap();
        c.edit(SceneEdit::MoveObject(Axis::X, -0.01), &input(1))
            .unwrap();
        let p = c
            .placement(1)
            .expect("the renderer must hear of the way back");
        assert!(
            p.object_position_m
                .abs_diff_eq(c.rest.object_position_m, 1e-6)
        );
        assert!(c.caustics_valid(), "the bake fits again");
    }

    #[test]
    fn a_still_scene_moves_only_once_edited_and_the_bake_goes_stale() {
        let mut c = clock(None);
        assert_eq!(c.placement(0), None);
        assert!(c.caustics_valid());
        // Re-registration moves nothing of the object or light.
        c.edit(SceneEdit::Register(Axis::X, 0.01), &input(0))
            .unwrap();
        assert_eq!(c.placement(0), None);
        assert!(c.caustics_valid());
        c.edit(SceneEdit::MoveLight(Axis::Y, -0.001), &input(0))
            .unwrap();
        let p = c.placement(0).unwrap();
        assert!((p.light_position_m.y - 0.999).abs() < 1e-6);
        assert!(!c.caustics_valid());
        assert!(c.stale_reported);
        assert!(!c.caustics_valid(), "stays off");
    }

    #[test]
    fn place_puts_the_object_where_the_head_ray_meets_the_floor_at_its_height() {
        let mut c = clock(None);
        let record = c.edit(SceneEdit::PlaceObject, &input(0)).unwrap();
        // The head ray meets the floor 1 m ahead; the centre stays 0.1 m above the floor.
        let p = c.placement(0).unwrap();
        assert!(
            p.object_position_m
                .abs_diff_eq(Vec3::new(0.0, 0.1, -1.0), 1e-5),
            "{p:?}"
        );
        assert_eq!(record.action, "place");
        let mut up = input(0);
        up.head.orientation = Quat::from_rotation_x(0.3);
        assert!(c.edit(SceneEdit::PlaceObject, &up).is_err());
        // Replaying the record gives the same state.
        let mut r = clock(None);
        r.replay_edit(&record, 0);
        assert_eq!(r.edits(), c.edits());
    }
}
