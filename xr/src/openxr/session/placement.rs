//! Where the scene sits in the runtime's space: placed at the first head pose, moved by the
//! re-registration commands, and the pose algebra both need.

use glam::{Quat, Vec3};
use vitreous_trace::{Command, Pose};

/// The scene frame from app space after a re-registration command: the scene moves by `d`
/// (Nudge), or turns by `a` about the vertical axis through the head at `head_m` (Rotate),
/// both in the scene frame. Other commands leave it as is.
pub(crate) fn re_register(world_from_space: &Pose, command: Command, head_m: Vec3) -> Pose {
    let change = match command {
        // The scene moving by d is everything else moving by -d in scene coordinates.
        Command::Nudge(d) => Pose {
            position: -d,
            orientation: Quat::IDENTITY,
        },
        // p' = R(-a) (p - h) + h.
        Command::Rotate(a) => {
            let r = Quat::from_rotation_y(-a);
            Pose {
                position: head_m - r * head_m,
                orientation: r,
            }
        }
        Command::Cycle(_)
        | Command::MoveObject(_)
        | Command::TurnObject(_)
        | Command::PlaceObject => return *world_from_space,
    };
    compose(&change, world_from_space)
}

/// `a` after `b`: maps `b`'s frame into `a`'s parent.
pub(crate) fn compose(a: &Pose, b: &Pose) -> Pose {
    Pose {
        position: a.transform_point(b.position),
        orientation: (a.orientation * b.orientation).normalize(),
    }
}

/// The inverse transform.
pub(crate) fn inverse(p: &Pose) -> Pose {
    let q = p.orientation.conjugate();
    Pose {
        position: -(q * p.position),
        orientation: q,
    }
}

/// The rotation about +y that faces where `orientation` faces (level, no roll).
pub(crate) fn yaw_only(orientation: Quat) -> Quat {
    let f = orientation * Vec3::NEG_Z;
    if f.x.abs() < 1e-6 && f.z.abs() < 1e-6 {
        return Quat::IDENTITY;
    }
    Quat::from_rotation_y((-f.x).atan2(-f.z))
}

/// The scene frame from app space such that the first head pose `head0` (app space) sits at
/// the viewer's position, facing the scene's -z.
pub(crate) fn place_scene(head0: &Pose, viewer_m: Vec3, origin: Option<Pose>) -> Pose {
    let level = Pose {
        position: head0.position,
        orientation: yaw_only(head0.orientation),
    };
    let viewer = Pose {
        position: viewer_m,
        orientation: Quat::IDENTITY,
    };
    let placed = compose(&viewer, &inverse(&level));
    match origin {
        Some(o) => compose(&o, &placed),
        None => placed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_is_placed_at_the_first_head_pose_facing_forward() {
        let head0 = Pose {
            position: Vec3::new(0.5, 1.6, -1.0),
            orientation: Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.2),
        };
        let w = place_scene(&head0, Vec3::ZERO, None);
        let head_world = compose(&w, &head0);
        assert!(head_world.position.length() < 1e-5, "{head_world:?}");
        // Looking forward (-z) in the scene, pitch kept.
        let f = head_world.orientation * Vec3::NEG_Z;
        assert!(f.x.abs() < 1e-5 && f.z < 0.0, "{f}");
        // Round trip of the helpers.
        let back = compose(&inverse(&w), &head_world);
        assert!((back.position - head0.position).length() < 1e-5);
    }
    #[test]
    fn a_nudge_moves_the_scene_and_a_turn_keeps_the_head_in_place() {
        let head0 = Pose {
            position: Vec3::new(0.3, 1.6, 0.2),
            orientation: Quat::from_rotation_y(0.4),
        };
        let w = place_scene(&head0, Vec3::ZERO, None);
        let head_m = compose(&w, &head0).position;
        // The scene moves 1 cm away (-z): the head's scene coordinates move 1 cm the other way.
        let d = Vec3::new(0.0, 0.0, -0.01);
        let nudged = re_register(&w, Command::Nudge(d), head_m);
        let moved = compose(&nudged, &head0).position - head_m;
        assert!((moved + d).length() < 1e-6, "{moved}");
        // A turn about the head: the head stays, its view turns the other way in the scene,
        // so the scene appears turned by +a (to the left).
        let a = 0.1;
        let turned = re_register(&w, Command::Rotate(a), head_m);
        let head = compose(&turned, &head0);
        assert!((head.position - head_m).length() < 1e-5);
        let f = head.orientation * Vec3::NEG_Z;
        let f0 = compose(&w, &head0).orientation * Vec3::NEG_Z;
        let yaw = |v: Vec3| (-v.x).atan2(-v.z);
        assert!((yaw(f) - yaw(f0) + a).abs() < 1e-5, "{f} {f0}");
        // Other commands leave the placement alone.
        assert_eq!(
            re_register(&w, Command::Cycle(vitreous_trace::Cycle::Secondary), head_m),
            w
        );
    }
}
