//! Eye rays as poses: the pose whose -z axis runs along a ray, the combined (cyclopean) ray,
//! the vergence point of two rays, and the rigid-transform algebra that moves them between
//! spaces. Axes are OpenXR's (+x right, +y up, -z forward, metres).

use glam::{Mat3, Quat, Vec3};
use openxr::sys;
use vitreous_trace::crossing::{RayCrossing, closest_approach};
use vitreous_trace::{GazeRay, GazeSample, Pose};

/// The pose at `origin` whose -z axis points along `direction` and whose +y axis is as close
/// to the frame's +y (head up) as it can be, so a gaze pose has no roll of its own.
pub fn pose_along(origin: Vec3, direction: Vec3) -> Pose {
    let forward = direction.normalize_or(Vec3::NEG_Z);
    let z = -forward;
    let x = Vec3::Y.cross(z);
    let orientation = if x.length_squared() < 1e-12 {
        // Looking straight up or down: any roll is as good; take the shortest arc.
        Quat::from_rotation_arc(Vec3::NEG_Z, forward)
    } else {
        let x = x.normalize();
        let y = z.cross(x);
        Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize()
    };
    Pose {
        position: origin,
        orientation,
    }
}

/// The pose of a valid ray (see [`pose_along`]).
pub fn ray_pose(ray: &GazeRay) -> Pose {
    pose_along(ray.origin, ray.direction)
}

/// The combined gaze of a sample: the sample's own combined ray when it has one (valid or
/// not), else the normalised mean of the valid eye rays from the mid-point of their origins
/// (one valid eye: that eye's ray; none: invalid).
pub fn combined_ray(sample: &GazeSample) -> GazeRay {
    if let Some(ray) = sample.combined {
        return ray;
    }
    let valid: Vec<&GazeRay> = [&sample.left, &sample.right]
        .into_iter()
        .filter(|r| r.valid)
        .collect();
    if valid.is_empty() {
        return GazeRay::INVALID;
    }
    let n = valid.len() as f32;
    let origin = valid.iter().map(|r| r.origin).sum::<Vec3>() / n;
    let direction = valid.iter().map(|r| r.direction).sum::<Vec3>();
    if direction.length_squared() < 1e-12 {
        return GazeRay::INVALID;
    }
    GazeRay {
        origin,
        direction: direction.normalize(),
        valid: true,
    }
}

/// The vergence point of two rays: the mid-point of the shortest segment between them.
/// `None` when they are parallel or when that segment lies behind either origin (the eyes
/// diverge).
pub fn vergence_point(left: &GazeRay, right: &GazeRay) -> Option<Vec3> {
    match closest_approach(left, right) {
        RayCrossing::Converge { point_m, .. } => Some(point_m),
        RayCrossing::Parallel | RayCrossing::Divergent => None,
    }
}

/// The fixation point of a sample in the head frame: the sample's own when it has one, else
/// the vergence point of the two eye rays when both are valid.
pub fn fixation_point(sample: &GazeSample) -> Option<Vec3> {
    sample.fixation.or_else(|| {
        (sample.left.valid && sample.right.valid)
            .then(|| vergence_point(&sample.left, &sample.right))
            .flatten()
    })
}

/// `a ∘ b`: `b` given in `a`'s frame, expressed in `a`'s parent frame.
pub fn compose(a: &Pose, b: &Pose) -> Pose {
    Pose {
        position: a.position + a.orientation * b.position,
        orientation: (a.orientation * b.orientation).normalize(),
    }
}

/// The inverse transform.
pub fn inverse(a: &Pose) -> Pose {
    let inv = a.orientation.inverse();
    Pose {
        position: -(inv * a.position),
        orientation: inv,
    }
}

/// The pose of `a` in `b`'s frame, both given in one reference frame.
pub fn relative(a_in_ref: &Pose, b_in_ref: &Pose) -> Pose {
    compose(&inverse(b_in_ref), a_in_ref)
}

/// An OpenXR pose as a [`Pose`] (the orientation normalised; a zero quaternion is identity).
pub fn from_posef(p: &sys::Posef) -> Pose {
    let q = Quat::from_xyzw(
        p.orientation.x,
        p.orientation.y,
        p.orientation.z,
        p.orientation.w,
    );
    Pose {
        position: Vec3::new(p.position.x, p.position.y, p.position.z),
        orientation: if q.length_squared() > 1e-12 {
            q.normalize()
        } else {
            Quat::IDENTITY
        },
    }
}

/// A [`Pose`] as an OpenXR pose.
pub fn to_posef(p: &Pose) -> sys::Posef {
    sys::Posef {
        orientation: sys::Quaternionf {
            x: p.orientation.x,
            y: p.orientation.y,
            z: p.orientation.z,
            w: p.orientation.w,
        },
        position: sys::Vector3f {
            x: p.position.x,
            y: p.position.y,
            z: p.position.z,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(origin: Vec3, direction: Vec3) -> GazeRay {
        GazeRay {
            origin,
            direction: direction.normalize(),
            valid: true,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn pose_along_looks_down_the_ray_without_roll() {
        let d = Vec3::new(1.0, 0.5, -2.0).normalize();
        let p = pose_along(Vec3::new(0.1, 0.2, 0.3), d);
        assert!(close(p.orientation * Vec3::NEG_Z, d));
        // No roll: the pose's x axis stays horizontal.
        assert!((p.orientation * Vec3::X).y.abs() < 1e-6);
        assert!((p.orientation * Vec3::Y).y > 0.0);
        // Straight ahead is the identity.
        let p = pose_along(Vec3::ZERO, Vec3::NEG_Z);
        assert!(p.orientation.abs_diff_eq(Quat::IDENTITY, 1e-6));
        // Straight up still points the right way.
        let p = pose_along(Vec3::ZERO, Vec3::Y);
        assert!(close(p.orientation * Vec3::NEG_Z, Vec3::Y));
    }

    #[test]
    fn vergence_of_two_converging_rays_is_where_they_meet() {
        // Eyes 64 mm apart looking at (0, 0, -0.5).
        let target = Vec3::new(0.0, 0.0, -0.5);
        let l = Vec3::new(-0.032, 0.0, 0.0);
        let r = Vec3::new(0.032, 0.0, 0.0);
        let p = vergence_point(&ray(l, target - l), &ray(r, target - r)).unwrap();
        assert!(close(p, target), "{p}");
    }

    #[test]
    fn vergence_of_skew_rays_is_the_midpoint_of_the_shortest_segment() {
        // One ray along -z at y = +0.01, the other crossing it along x at y = -0.01, z = -1.
        let a = ray(Vec3::new(0.0, 0.01, 0.0), Vec3::NEG_Z);
        let b = ray(Vec3::new(-1.0, -0.01, -1.0), Vec3::X);
        let p = vergence_point(&a, &b).unwrap();
        assert!(close(p, Vec3::new(0.0, 0.0, -1.0)), "{p}");
    }

    #[test]
    fn parallel_or_diverging_rays_have_no_vergence_point() {
        let l = ray(Vec3::new(-0.032, 0.0, 0.0), Vec3::NEG_Z);
        let r = ray(Vec3::new(0.032, 0.0, 0.0), Vec3::NEG_Z);
        assert_eq!(vergence_point(&l, &r), None);
        let l = ray(Vec3::new(-0.032, 0.0, 0.0), Vec3::new(-0.1, 0.0, -1.0));
        let r = ray(Vec3::new(0.032, 0.0, 0.0), Vec3::new(0.1, 0.0, -1.0));
        assert_eq!(vergence_point(&l, &r), None);
    }

    #[test]
    fn combined_ray_is_the_mean_of_the_valid_eyes() {
        let l = ray(Vec3::new(-0.03, 0.0, 0.0), Vec3::new(0.1, 0.0, -1.0));
        let r = ray(Vec3::new(0.03, 0.0, 0.0), Vec3::new(-0.1, 0.0, -1.0));
        let mut s = GazeSample::binocular(0, l, r);
        let c = combined_ray(&s);
        assert!(c.valid && close(c.origin, Vec3::ZERO) && close(c.direction, Vec3::NEG_Z));
        s.right = GazeRay::INVALID;
        let c = combined_ray(&s);
        assert!(c.valid && close(c.origin, l.origin) && close(c.direction, l.direction));
        s.left = GazeRay::INVALID;
        assert!(!combined_ray(&s).valid);
        // The trace's own combined ray wins, even when invalid.
        s.left = l;
        s.combined = Some(GazeRay::INVALID);
        assert!(!combined_ray(&s).valid);
    }

    #[test]
    fn fixation_prefers_the_trace_then_vergence() {
        let target = Vec3::new(0.1, 0.0, -0.4);
        let l = Vec3::new(-0.032, 0.0, 0.0);
        let r = Vec3::new(0.032, 0.0, 0.0);
        let mut s = GazeSample::binocular(0, ray(l, target - l), ray(r, target - r));
        assert!(close(fixation_point(&s).unwrap(), target));
        s.fixation = Some(Vec3::new(0.0, 0.0, -2.0));
        assert_eq!(fixation_point(&s), Some(Vec3::new(0.0, 0.0, -2.0)));
        s.fixation = None;
        s.right = GazeRay::INVALID;
        assert_eq!(fixation_point(&s), None);
    }

    #[test]
    fn relative_pose_undoes_composition() {
        let head = Pose {
            position: Vec3::new(0.0, 1.6, 0.2),
            orientation: Quat::from_rotation_y(0.7),
        };
        let eye = pose_along(Vec3::new(-0.03, 0.0, 0.0), Vec3::new(0.2, -0.1, -1.0));
        let world = compose(&head, &eye);
        // The eye's world origin is the head transform of its head-frame origin.
        assert!(close(world.position, head.transform_point(eye.position)));
        let back = relative(&world, &head);
        assert!(close(back.position, eye.position));
        assert!(back.orientation.abs_diff_eq(eye.orientation, 1e-5));
        let p = to_posef(&world);
        let q = from_posef(&p);
        assert!(close(q.position, world.position));
    }
}
