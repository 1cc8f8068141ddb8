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
use vitreous_trace::Pose;

use crate::config::SimViews;
use crate::eye_geometry::{from_posef, to_posef};

/// The two eyes' poses (left, right) as `views` asks, from the runtime's.
pub fn respaced(poses: [sys::Posef; 2], views: SimViews) -> [sys::Posef; 2] {
    let [left, right] = poses.each_ref().map(from_posef);
    let head = left.orientation.slerp(right.orientation, 0.5).normalize();
    let middle = (left.position + right.position) / 2.0;
    let across = head * Vec3::X * (views.ipd_m / 2.0);
    let turn = views.toe_out_deg.to_radians();
    let eye = |side: f32| {
        to_posef(&Pose {
            position: middle + across * side,
            orientation: head * Quat::from_rotation_y(-side * turn),
        })
    };
    [eye(-1.0), eye(1.0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(position: Vec3, orientation: Quat) -> sys::Posef {
        to_posef(&Pose {
            position,
            orientation,
        })
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
        let (l, r) = (from_posef(&l), from_posef(&r));
        let (lp, rp) = (l.position, r.position);
        assert!((lp.distance(rp) - 0.058).abs() < 1e-6);
        assert!(((lp + rp) / 2.0).distance(centre) < 1e-6);
        assert!((rp - lp).normalize().dot(x) > 0.999_999);
        // Each view's forward (-z) turned 4 degrees outwards from the head's, about its y.
        let forward = head * Vec3::NEG_Z;
        let (lf, rf) = (l.orientation * Vec3::NEG_Z, r.orientation * Vec3::NEG_Z);
        for f in [lf, rf] {
            assert!((f.angle_between(forward).to_degrees() - 4.0).abs() < 1e-3);
        }
        assert!(lf.dot(x) < 0.0 && rf.dot(x) > 0.0, "outwards: {lf} {rf}");
    }
}
