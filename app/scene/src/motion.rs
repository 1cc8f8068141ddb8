//! `[motion]`: the object's pose and the light's position over time, as keyframes
//! interpolated piecewise linearly (positions) and spherically (rotations), so that replays,
//! benchmarks and tests can move the scene. A scene without keyframes stands still.

use glam::{Quat, Vec3};
use toml::Spanned;

use super::SceneError;
use super::file::{LightFrame, MotionToml};
use super::load::Loader;

/// Most keyframes accepted in each list.
pub const MAX_KEYFRAMES: usize = 100_000;

/// Latest keyframe time accepted, seconds (a day).
pub const MAX_TIME_S: f64 = 86_400.0;

/// One keyframe of the object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectKey {
    /// Seconds from the first frame.
    pub time_s: f64,
    /// World position of the object's bounding-box centre, metres.
    pub position_m: Vec3,
    /// Orientation (as `rotation_deg` describes it).
    pub rotation: Quat,
}

/// One keyframe of the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightKey {
    /// Seconds from the first frame.
    pub time_s: f64,
    /// Position in the `[light] frame`: world, or an offset from the object's position at
    /// that time (world axes), metres.
    pub position_m: Vec3,
}

/// How the object and the light move; empty lists keep them where `[object]` and `[light]`
/// put them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Motion {
    /// Period after which the motion starts again, seconds; `None`: the last keyframe holds.
    pub repeat_s: Option<f64>,
    /// Object keyframes, strictly increasing in time.
    pub object: Vec<ObjectKey>,
    /// Light keyframes, strictly increasing in time.
    pub light: Vec<LightKey>,
    /// The light's position is an offset from the object's (`[light] frame = "object"`): it
    /// follows the object when only the object moves.
    pub light_follows_object: bool,
}

/// Where the object and the light are at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// World position of the object's bounding-box centre, metres.
    pub object_position_m: Vec3,
    /// The object's orientation.
    pub object_rotation: Quat,
    /// World position of the light, metres.
    pub light_position_m: Vec3,
}

impl Motion {
    /// Whether anything moves.
    pub fn is_animated(&self) -> bool {
        self.object.len() > 1 || self.light.len() > 1
    }

    /// The placement at `time_s` seconds from the first frame. `rest` is where `[object]` and
    /// `[light]` put things (used where a list is empty); `rest_light_in_frame_m` is the
    /// `[light] position_m` as written (an offset when the light follows the object).
    pub fn placement_at(
        &self,
        time_s: f64,
        rest: Placement,
        rest_light_in_frame_m: Vec3,
    ) -> Placement {
        let t = match self.repeat_s {
            Some(period) if period > 0.0 => time_s.rem_euclid(period),
            _ => time_s,
        };
        let (object_position_m, object_rotation) = match segment(&self.object, t, |k| k.time_s) {
            None => (rest.object_position_m, rest.object_rotation),
            Some((a, b, f)) => (
                a.position_m.lerp(b.position_m, f),
                a.rotation.slerp(b.rotation, f),
            ),
        };
        let light_in_frame = match segment(&self.light, t, |k| k.time_s) {
            None => rest_light_in_frame_m,
            Some((a, b, f)) => a.position_m.lerp(b.position_m, f),
        };
        let light_position_m = if self.light_follows_object {
            object_position_m + light_in_frame
        } else {
            light_in_frame
        };
        Placement {
            object_position_m,
            object_rotation,
            light_position_m,
        }
    }
}

/// The two keyframes around `t` and the fraction of the way from the first to the second
/// (clamped: before the first and after the last keyframe it holds); `None` when empty.
fn segment<K>(keys: &[K], t: f64, time: impl Fn(&K) -> f64) -> Option<(&K, &K, f32)> {
    let first = keys.first()?;
    let after = keys.partition_point(|k| time(k) <= t);
    Some(match after {
        0 => (first, first, 0.0),
        n if n == keys.len() => (&keys[n - 1], &keys[n - 1], 0.0),
        n => {
            let (a, b) = (&keys[n - 1], &keys[n]);
            let f = (t - time(a)) / (time(b) - time(a));
            (a, b, f.clamp(0.0, 1.0) as f32)
        }
    })
}

impl Loader<'_> {
    /// Reads `[motion]`; `rest_rotation` is `[object] rotation_deg`, the default of object
    /// keyframes that give none.
    pub(super) fn motion(
        &self,
        raw: &MotionToml,
        frame: LightFrame,
        rest_rotation: Quat,
    ) -> Result<Motion, SceneError> {
        let mut object = Vec::with_capacity(raw.object.len());
        let mut previous = None;
        for (i, key) in raw.object.iter().enumerate() {
            let field = format!("motion.object[{i}]");
            let time_s = self.key_time(&field, &key.time_s, previous, raw.object.len())?;
            previous = Some(time_s);
            object.push(ObjectKey {
                time_s,
                position_m: self.vec3(&format!("{field}.position_m"), &key.position_m)?,
                rotation: match &key.rotation_deg {
                    None => rest_rotation,
                    Some(r) => self.rotation(&format!("{field}.rotation_deg"), Some(r))?,
                },
            });
        }
        let mut light = Vec::with_capacity(raw.light.len());
        let mut previous = None;
        for (i, key) in raw.light.iter().enumerate() {
            let field = format!("motion.light[{i}]");
            let time_s = self.key_time(&field, &key.time_s, previous, raw.light.len())?;
            previous = Some(time_s);
            light.push(LightKey {
                time_s,
                position_m: self.vec3(&format!("{field}.position_m"), &key.position_m)?,
            });
        }
        let repeat_s = match &raw.repeat_s {
            None => None,
            Some(r) => {
                let period = *r.get_ref();
                let last = object
                    .last()
                    .map(|k| k.time_s)
                    .into_iter()
                    .chain(light.last().map(|k| k.time_s))
                    .fold(0.0f64, f64::max);
                if !(period.is_finite() && period > 0.0 && period <= MAX_TIME_S && period >= last) {
                    return Err(self.src.invalid(
                        r.span(),
                        "motion.repeat_s",
                        format!(
                            "expected a period in seconds > 0, <= {MAX_TIME_S} and not before \
                             the last keyframe ({last} s), found {period}"
                        ),
                    ));
                }
                Some(period)
            }
        };
        Ok(Motion {
            repeat_s,
            object,
            light,
            light_follows_object: frame == LightFrame::Object,
        })
    }

    /// A keyframe's time: finite, within 0..=MAX_TIME_S, after the previous keyframe's.
    fn key_time(
        &self,
        field: &str,
        time: &Spanned<f64>,
        previous: Option<f64>,
        count: usize,
    ) -> Result<f64, SceneError> {
        let field = format!("{field}.time_s");
        if count > MAX_KEYFRAMES {
            return Err(self.src.invalid(
                time.span(),
                &field,
                format!("at most {MAX_KEYFRAMES} keyframes per list, found {count}"),
            ));
        }
        let t = *time.get_ref();
        if !(t.is_finite() && (0.0..=MAX_TIME_S).contains(&t)) {
            return Err(self.src.invalid(
                time.span(),
                &field,
                format!("expected a time in seconds within 0..={MAX_TIME_S}, found {t}"),
            ));
        }
        if let Some(p) = previous
            && t <= p
        {
            return Err(self.src.invalid(
                time.span(),
                &field,
                format!(
                    "keyframe times must increase strictly: {t} s follows the previous \
                     keyframe's {p} s"
                ),
            ));
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rest() -> Placement {
        Placement {
            object_position_m: Vec3::new(0.0, -0.26, -1.5),
            object_rotation: Quat::IDENTITY,
            light_position_m: Vec3::new(0.0, 0.74, -2.5),
        }
    }

    fn light_key(time_s: f64, x: f32) -> LightKey {
        LightKey {
            time_s,
            position_m: Vec3::new(x, 1.0, 0.0),
        }
    }

    #[test]
    fn positions_interpolate_linearly_and_hold_outside_the_keyframes() {
        let motion = Motion {
            light: vec![light_key(1.0, 0.0), light_key(3.0, 2.0)],
            ..Motion::default()
        };
        let at = |t| {
            motion
                .placement_at(t, rest(), Vec3::ZERO)
                .light_position_m
                .x
        };
        assert_eq!(at(0.0), 0.0);
        assert_eq!(at(1.0), 0.0);
        assert!((at(2.5) - 1.5).abs() < 1e-6);
        assert_eq!(at(3.0), 2.0);
        assert_eq!(at(10.0), 2.0);
        // Without object keyframes the object stays at rest.
        assert_eq!(
            motion
                .placement_at(2.0, rest(), Vec3::ZERO)
                .object_position_m,
            rest().object_position_m
        );
    }

    #[test]
    fn repeat_wraps_time_and_object_frame_lights_follow_the_object() {
        let q = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let motion = Motion {
            repeat_s: Some(2.0),
            object: vec![
                ObjectKey {
                    time_s: 0.0,
                    position_m: Vec3::ZERO,
                    rotation: Quat::IDENTITY,
                },
                ObjectKey {
                    time_s: 2.0,
                    position_m: Vec3::new(0.2, 0.0, 0.0),
                    rotation: q,
                },
            ],
            light: Vec::new(),
            light_follows_object: true,
        };
        let offset = Vec3::new(0.0, 1.0, -1.0);
        let p = motion.placement_at(5.0, rest(), offset);
        assert!(
            p.object_position_m
                .abs_diff_eq(Vec3::new(0.1, 0.0, 0.0), 1e-6)
        );
        assert!(
            p.light_position_m
                .abs_diff_eq(Vec3::new(0.1, 1.0, -1.0), 1e-6)
        );
        let half = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(p.object_rotation.abs_diff_eq(half, 1e-5));
        assert!(motion.is_animated());
        assert!(!Motion::default().is_animated());
    }
}
