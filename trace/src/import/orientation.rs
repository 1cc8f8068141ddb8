//! Head orientation over time for imported recordings: a track of timed orientations read
//! at any time by spherical interpolation, built either from gyroscope rates (integrated) or
//! from an IMU's own orientation quaternions.

use glam::{Quat, Vec3};

use crate::sranipal::heading_rad;

/// Timed head orientations (head frame to world, OpenXR axes), strictly increasing times.
#[derive(Clone, Debug, Default)]
pub(crate) struct OrientationTrack {
    /// Times, nanoseconds on the recording's clock, strictly increasing.
    times_ns: Vec<i64>,
    /// The orientation at each time, unit quaternions.
    orientations: Vec<Quat>,
}

impl OrientationTrack {
    /// A track from timed orientations; entries whose time is not after the previous kept
    /// one are skipped, non-unit quaternions normalised (zero or non-finite ones skipped).
    pub(crate) fn new(entries: impl IntoIterator<Item = (i64, Quat)>) -> Self {
        let mut track = OrientationTrack::default();
        for (t, q) in entries {
            let Some(q) = unit(q) else { continue };
            if track.times_ns.last().is_some_and(|&last| t <= last) {
                continue;
            }
            track.times_ns.push(t);
            track.orientations.push(q);
        }
        track
    }

    /// Integrates body-frame angular velocities (head frame, radians per second) from
    /// `initial`, the orientation at the first rate's time. Each step turns by the mean of
    /// its two end rates over its length (trapezoidal rule). Rates whose time is not after
    /// the previous kept one are skipped.
    pub(crate) fn integrate_rates(initial: Quat, rates: &[(i64, Vec3)]) -> Self {
        let mut track = OrientationTrack::default();
        let mut previous: Option<(i64, Vec3)> = None;
        let mut q = initial;
        for &(t, w) in rates {
            if !w.is_finite() {
                continue;
            }
            if let Some((t0, w0)) = previous {
                if t <= t0 {
                    continue;
                }
                let dt_s = (t - t0) as f32 * 1e-9;
                q = (q * Quat::from_scaled_axis((w0 + w) * 0.5 * dt_s)).normalize();
            }
            track.times_ns.push(t);
            track.orientations.push(q);
            previous = Some((t, w));
        }
        track
    }

    /// Whether the track holds no orientation.
    pub(crate) fn is_empty(&self) -> bool {
        self.times_ns.is_empty()
    }

    /// Number of timed orientations.
    pub(crate) fn len(&self) -> usize {
        self.times_ns.len()
    }

    /// The orientation at `t_ns`: interpolated between the two neighbouring entries, the
    /// first or last entry outside the track, the identity for an empty track.
    pub(crate) fn at(&self, t_ns: i64) -> Quat {
        let i = self.times_ns.partition_point(|&t| t <= t_ns);
        match (i.checked_sub(1), self.orientations.get(i)) {
            (None, Some(&q)) => q,
            (None, None) => Quat::IDENTITY,
            (Some(k), None) => self.orientations[k],
            (Some(k), Some(&next)) => {
                let (t0, t1) = (self.times_ns[k], self.times_ns[i]);
                let s = (t_ns - t0) as f64 / (t1 - t0) as f64;
                self.orientations[k].slerp(next, s as f32).normalize()
            }
        }
    }
}

/// `q` normalised, or `None` when it is zero or not finite.
fn unit(q: Quat) -> Option<Quat> {
    let n = q.length();
    (n.is_finite() && n > 1e-6).then(|| q / n)
}

/// The rotation that removes the heading of `orientation`: a turn about +y after which the
/// head faces -z in the horizontal plane (pitch and roll kept).
pub(crate) fn unyaw(orientation: Quat) -> Quat {
    Quat::from_rotation_y(-heading_rad(orientation))
}

/// A head orientation with no heading whose up direction agrees with a measured specific
/// force (an accelerometer at rest reads +g along the world's up), given in the head frame.
/// `None` when the reading is not close to 1 g (the head was accelerating, or no reading).
pub(crate) fn level_from_gravity(specific_force_head: Vec3) -> Option<Quat> {
    let g = specific_force_head.length();
    if !(7.0..=12.5).contains(&g) {
        return None;
    }
    let q = Quat::from_rotation_arc(specific_force_head / g, Vec3::Y);
    Some((unyaw(q) * q).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_rate_integrates_to_the_expected_turn() {
        // 90 deg/s about +y (a turn to the left) for one second at 100 Hz.
        let w = Vec3::new(0.0, 90f32.to_radians(), 0.0);
        let rates: Vec<_> = (0..=100).map(|i| (i * 10_000_000, w)).collect();
        let track = OrientationTrack::integrate_rates(Quat::IDENTITY, &rates);
        let forward = track.at(1_000_000_000) * Vec3::NEG_Z;
        assert!(forward.abs_diff_eq(Vec3::NEG_X, 1e-4), "{forward}");
        // Half-way between two entries is interpolated.
        let half = track.at(505_000_000) * Vec3::NEG_Z;
        let expected = Quat::from_rotation_y(45.45f32.to_radians()) * Vec3::NEG_Z;
        assert!(half.abs_diff_eq(expected, 1e-4), "{half} vs {expected}");
        // Outside the track: held.
        assert_eq!(track.at(-5), Quat::IDENTITY);
        assert!((track.at(9_000_000_000) * Vec3::NEG_Z).abs_diff_eq(Vec3::NEG_X, 1e-4));
    }

    #[test]
    fn body_frame_rates_compose_on_the_right() {
        // Pitch up 90 degrees, then a body-frame yaw rate: the head turns about its own up
        // axis (now world +z), so forward (world +y after the pitch) swings toward -x.
        let initial = Quat::from_rotation_x(90f32.to_radians());
        let w = Vec3::new(0.0, 90f32.to_radians(), 0.0);
        let rates = [(0, w), (1_000_000_000, w)];
        let track = OrientationTrack::integrate_rates(initial, &rates);
        let forward = track.at(1_000_000_000) * Vec3::NEG_Z;
        assert!(forward.abs_diff_eq(Vec3::NEG_X, 1e-4), "{forward}");
    }

    #[test]
    fn gravity_levels_pitch_and_roll_without_heading() {
        // Head pitched 20 degrees down: world up is tilted toward the head's forward (-z).
        let truth = Quat::from_rotation_x(-20f32.to_radians());
        let up_in_head = truth.inverse() * Vec3::Y * 9.81;
        let q = level_from_gravity(up_in_head).unwrap();
        assert!((q * Vec3::NEG_Z).abs_diff_eq(truth * Vec3::NEG_Z, 1e-5));
        assert!(heading_rad(q).abs() < 1e-5);
        assert_eq!(level_from_gravity(Vec3::ZERO), None);
        assert_eq!(level_from_gravity(Vec3::new(0.0, 30.0, 0.0)), None);
    }

    #[test]
    fn tracks_skip_unordered_and_degenerate_entries() {
        let track = OrientationTrack::new([
            (0, Quat::IDENTITY),
            (0, Quat::from_rotation_y(1.0)),
            (10, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
            (20, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)),
        ]);
        assert_eq!(track.len(), 2);
        assert_eq!(track.at(20), Quat::IDENTITY);
        assert!(OrientationTrack::new([]).is_empty());
    }
}
