//! The visual axis of an eye from its optical axis and angle kappa, for Neon recordings
//! without a gaze stream.
//!
//! Neon's eye state gives each eye's optical axis: the line from the eyeball centre through
//! the pupil centre. The eye looks along its visual axis, through the fovea, which lies
//! temporal to the back pole of the optical axis; outside the eye the visual axis therefore
//! points nasal of the optical axis by the horizontal angle kappa. Kappa is about 5 degrees
//! in adults on average, varies by several degrees between people (and is negative in
//! some), and Neon does not measure it: one value is assumed for every wearer.

use glam::{DQuat, DVec3};

/// The angle kappa assumed when none is given, degrees: the commonly cited mean for adults,
/// a population value and not any wearer's own.
pub const DEFAULT_KAPPA_DEG: f64 = 5.0;

/// One of the wearer's eyes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    /// The wearer's left eye (at -x in the scene camera frame).
    Left,
    /// The wearer's right eye (at +x).
    Right,
}

impl Eye {
    /// Both eyes, in the order of a trace sample's rays.
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    /// The horizontal direction toward the nose, scene camera frame (+x right, +y down,
    /// +z forward).
    pub fn nasal(self) -> DVec3 {
        match self {
            Eye::Left => DVec3::X,
            Eye::Right => DVec3::NEG_X,
        }
    }

    /// The eye's name in Neon's field names (`optical_axis_left_x`).
    pub fn name(self) -> &'static str {
        match self {
            Eye::Left => "left",
            Eye::Right => "right",
        }
    }
}

/// The unit visual axis of `eye` whose optical axis is `optical` (scene camera frame, any
/// non-zero length): `optical` turned by `kappa_rad` toward the nose, in the plane of the
/// optical axis and the horizontal (about the eye's own vertical axis, perpendicular to
/// both). Positive kappa turns the two eyes toward each other. `None` when `optical` is
/// zero, not finite, or points along the horizontal, where "toward the nose" has no
/// direction.
pub fn visual_axis(optical: DVec3, eye: Eye, kappa_rad: f64) -> Option<DVec3> {
    let optical = optical.try_normalize()?;
    let vertical = optical.cross(eye.nasal()).try_normalize()?;
    (DQuat::from_axis_angle(vertical, kappa_rad) * optical).try_normalize()
}

/// The unit optical axis of `eye` whose visual axis is `visual`: the inverse of
/// [`visual_axis`] (exact while `visual` lies more than `kappa_rad` from the horizontal).
pub fn optical_axis(visual: DVec3, eye: Eye, kappa_rad: f64) -> Option<DVec3> {
    visual_axis(visual, eye, -kappa_rad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kappa_turns_each_eye_toward_the_nose_by_exactly_kappa() {
        let kappa = DEFAULT_KAPPA_DEG.to_radians();
        for optical in [
            DVec3::Z,
            DVec3::new(0.3, -0.4, 1.0),
            DVec3::new(-0.5, 0.6, 1.0),
        ] {
            let o = optical.normalize();
            for eye in Eye::BOTH {
                let v = visual_axis(optical, eye, kappa).unwrap();
                assert!((v.length() - 1.0).abs() < 1e-12);
                assert!((v.angle_between(o) - kappa).abs() < 1e-12, "{eye:?} {o}");
                // Nasal: closer to the nose than the optical axis, by kappa.
                let (from_nose_v, from_nose_o) =
                    (v.angle_between(eye.nasal()), o.angle_between(eye.nasal()));
                assert!((from_nose_o - from_nose_v - kappa).abs() < 1e-12);
                // Horizontal: in the plane of the optical axis and the horizontal.
                assert!(v.dot(o.cross(DVec3::X)).abs() < 1e-12);
                let back = optical_axis(v, eye, kappa).unwrap();
                assert!(back.abs_diff_eq(o, 1e-12), "{back} {o}");
            }
        }
        // Straight ahead, the left eye turns right (+x) and the right eye left.
        let left = visual_axis(DVec3::Z, Eye::Left, kappa).unwrap();
        let right = visual_axis(DVec3::Z, Eye::Right, kappa).unwrap();
        assert!(left.x > 0.0 && right.x < 0.0 && left.y == 0.0);
        assert_eq!(visual_axis(DVec3::ZERO, Eye::Left, kappa), None);
        assert_eq!(visual_axis(DVec3::NAN, Eye::Left, kappa), None);
        assert_eq!(visual_axis(DVec3::X, Eye::Left, kappa), None);
    }
}
