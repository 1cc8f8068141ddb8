//! Planes a headset detected in the room (XR_EXT_plane_detection): where each lies, and where a
//! ray meets the nearest. A plane is a rectangle centred on its pose, `extents` wide along the
//! pose's x axis and high along its y axis; its normal (the side it faces) is the pose's +z, as
//! the extension defines it.

use glam::{Vec2, Vec3};

use crate::frame::Pose;

/// Largest distance along a ray at which a plane is still met, metres.
pub const MAX_RAY_M: f32 = 20.0;

/// A detected plane, in the scene frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectedPlane {
    /// Its centre and orientation (+z its normal).
    pub pose: Pose,
    /// Its width (along the pose's x) and height (along its y), metres.
    pub extents: Vec2,
}

impl DetectedPlane {
    /// The side the plane faces.
    pub fn normal(&self) -> Vec3 {
        self.pose.transform_vector(Vec3::Z)
    }

    /// Whether it faces up, within `max_tilt_deg` of the scene's +y (a table, a floor).
    pub fn faces_up(&self, max_tilt_deg: f32) -> bool {
        self.normal().dot(Vec3::Y) >= max_tilt_deg.to_radians().cos()
    }

    /// Where the ray `origin + t dir` (t > 0, at most [`MAX_RAY_M`]) meets the plane's
    /// rectangle, and `t`; `None` when it misses or runs along the plane.
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(Vec3, f32)> {
        let n = self.normal();
        let denom = dir.dot(n);
        if denom.abs() < 1e-6 {
            return None;
        }
        let t = (self.pose.position - origin).dot(n) / denom;
        if !(t > 0.0 && t <= MAX_RAY_M) {
            return None;
        }
        let p = origin + dir * t;
        let local = self.pose.orientation.conjugate() * (p - self.pose.position);
        (local.x.abs() <= self.extents.x / 2.0 && local.y.abs() <= self.extents.y / 2.0)
            .then_some((p, t))
    }
}

/// The nearest of `planes` facing up (within 10 degrees) that the ray meets: the plane and
/// the point.
pub fn nearest_up_hit(
    planes: &[DetectedPlane],
    origin: Vec3,
    dir: Vec3,
) -> Option<(DetectedPlane, Vec3)> {
    planes
        .iter()
        .filter(|p| p.faces_up(10.0))
        .filter_map(|p| p.hit(origin, dir).map(|(at, t)| (*p, at, t)))
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(p, at, _)| (p, at))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// A table top `w` x `d` metres at height `y`, centred on `(x, z)`, facing up.
    fn table(x: f32, y: f32, z: f32, w: f32, d: f32) -> DetectedPlane {
        DetectedPlane {
            pose: Pose {
                position: Vec3::new(x, y, z),
                // +z (the normal) to +y.
                orientation: Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            },
            extents: Vec2::new(w, d),
        }
    }

    #[test]
    fn a_ray_meets_a_table_top_inside_its_rectangle_only() {
        let t = table(0.0, -0.25, -1.5, 0.6, 0.4);
        assert!(t.faces_up(1.0));
        assert!((t.normal() - Vec3::Y).length() < 1e-6);
        let dir = (Vec3::new(0.1, -0.25, -1.4) - Vec3::ZERO).normalize();
        let (at, _) = t.hit(Vec3::ZERO, dir).expect("the table is met");
        assert!((at - Vec3::new(0.1, -0.25, -1.4)).length() < 1e-5, "{at}");
        // Past its edge (0.3 m either side of x = 0): missed.
        let beside = (Vec3::new(0.4, -0.25, -1.5)).normalize();
        assert!(t.hit(Vec3::ZERO, beside).is_none());
        // Looking up: the plane is behind the ray.
        assert!(t.hit(Vec3::ZERO, Vec3::Y).is_none());
    }

    #[test]
    fn the_nearest_upward_plane_is_the_one_met_first() {
        let floor = table(0.0, -1.2, -2.0, 20.0, 20.0);
        let top = table(0.0, -0.25, -1.5, 0.6, 0.6);
        let wall = DetectedPlane {
            pose: Pose {
                position: Vec3::new(0.0, 0.0, -1.0),
                orientation: Quat::IDENTITY,
            },
            extents: Vec2::new(4.0, 4.0),
        };
        let dir = Vec3::new(0.0, -0.25, -1.5).normalize();
        let (plane, at) = nearest_up_hit(&[floor, wall, top], Vec3::ZERO, dir).unwrap();
        assert_eq!(plane, top);
        assert!((at.y + 0.25).abs() < 1e-5);
        // Without the table, the floor behind it; the wall never (it does not face up).
        let (plane, _) = nearest_up_hit(&[wall, floor], Vec3::ZERO, dir).unwrap();
        assert_eq!(plane, floor);
    }
}
