//! The headset's eyes as `VITREOUS_SIM_VIEWS` asks for them: each `xrLocateViews` answer moved
//! to the given distance apart and turned outwards, as a headset whose wearer's eyes are
//! further apart or closer than the runtime's default, or whose displays are canted, answers.
//!
//! The two views keep their midpoint and the head's orientation there (halfway between the
//! runtime's two orientations); each eye moves along the head's x axis and turns about its y
//! axis (the left eye to the left, the right to the right, for a positive turn). Fields of view
//! are the runtime's.

use glam::{Quat, Vec3};
use openxr::sys;

use crate::config::SimViews;

fn vec3(v: sys::Vector3f) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

fn quat(q: sys::Quaternionf) -> Quat {
    Quat::from_xyzw(q.x, q.y, q.z, q.w)
}

fn to_vector(v: Vec3) -> sys::Vector3f {
    sys::Vector3f {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

fn to_quaternion(q: Quat) -> sys::Quaternionf {
    sys::Quaternionf {
        x: q.x,
        y: q.y,
        z: q.z,
        w: q.w,
    }
}

/// The two eyes' poses (left, right) as `views` asks, from the runtime's.
pub fn respaced(poses: [sys::Posef; 2], views: SimViews) -> [sys::Posef; 2] {
    let (p, q) = (
        [vec3(poses[0].position), vec3(poses[1].position)],
        [quat(poses[0].orientation), quat(poses[1].orientation)],
    );
    let head = q[0].normalize().slerp(q[1].normalize(), 0.5).normalize();
    let middle = (p[0] + p[1]) / 2.0;
    let across = head * Vec3::X * (views.ipd_m / 2.0);
    let turn = views.toe_out_deg.to_radians();
    let eye = |side: f32| sys::Posef {
        position: to_vector(middle + across * side),
        orientation: to_quaternion(head * Quat::from_rotation_y(-side * turn)),
    };
    [eye(-1.0), eye(1.0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(position: Vec3, orientation: Quat) -> sys::Posef {
        sys::Posef {
            position: to_vector(position),
            orientation: to_quaternion(orientation),
        }
    }

    #[test]
    fn the_eyes_move_apart_along_the_heads_x_axis_and_turn_outwards() {
        // A head turned 30 degrees to the left, eyes 63 mm apart, parallel.
        let head = Quat::from_rotation_y(30f32.to_radians());
        let centre = Vec3::new(0.2, 1.6, -0.4);
        let x = head * Vec3::X;
        let runtime = [
            pose(centre - x * 0.0315, head),
            pose(centre + x * 0.0315, head),
        ];
        let [l, r] = respaced(
            runtime,
            SimViews {
                ipd_m: 0.058,
                toe_out_deg: 4.0,
            },
        );
        let (lp, rp) = (vec3(l.position), vec3(r.position));
        assert!((lp.distance(rp) - 0.058).abs() < 1e-6);
        assert!(((lp + rp) / 2.0).distance(centre) < 1e-6);
        assert!((rp - lp).normalize().dot(x) > 0.999_999);
        // Each view's forward (-z) turned 4 degrees outwards from the head's, about its y.
        let forward = head * Vec3::NEG_Z;
        let (lf, rf) = (
            quat(l.orientation) * Vec3::NEG_Z,
            quat(r.orientation) * Vec3::NEG_Z,
        );
        for f in [lf, rf] {
            assert!((f.angle_between(forward).to_degrees() - 4.0).abs() < 1e-3);
        }
        assert!(lf.dot(x) < 0.0 && rf.dot(x) > 0.0, "outwards: {lf} {rf}");
    }
}
