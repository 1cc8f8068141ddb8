//! Version 1.5's views lines: the eyes the headset drew each frame from (where each eye is in
//! the head's frame, the way its view looks, its field of view), so a replay of a recording
//! draws from the wearer's eyes rather than the scene's: the headset's distance between the
//! eyes and canted displays included.
//!
//! A views line starts with the word `views` and holds [`VIEWS_FIELDS`] fields:
//!
//! ```text
//! views,time_ns,left_x_m,left_y_m,left_z_m,left_qx,left_qy,left_qz,left_qw,left_fov_left_rad,left_fov_right_rad,left_fov_up_rad,left_fov_down_rad,right_x_m,...,right_fov_down_rad
//! views,0,-0.029,0,0,0,0.0174524,0,0.9998477,-0.7417,0.7417,0.7787,-0.7787,0.029,0,0,0,-0.0174524,0,0.9998477,-0.7417,0.7417,0.7787,-0.7787
//! ```
//!
//! Poses are in the head's frame (the sample lines' head pose): the eye's position in metres
//! and the view's orientation, a unit quaternion; the field's four edges are angles in
//! radians, as OpenXR gives them (left and down negative). A line holds from its `time_ns`
//! (the display time of the first frame drawn from these views) until the next one; a recorder
//! writes one at its first frame and another whenever the views change.

use glam::{Quat, Vec3};

use super::{QUAT_NORM_TOLERANCE, TraceError};
use crate::frame::{Fov, Pose, turn_between};
use crate::records::Record;

/// The first field of a views line.
pub const VIEWS_TAG: &str = "views";

/// The names of a views line's fields, in file order (the first is the tag itself).
pub const VIEWS_FIELDS: [&str; 24] = [
    "views",
    "time_ns",
    "left_x_m",
    "left_y_m",
    "left_z_m",
    "left_qx",
    "left_qy",
    "left_qz",
    "left_qw",
    "left_fov_left_rad",
    "left_fov_right_rad",
    "left_fov_up_rad",
    "left_fov_down_rad",
    "right_x_m",
    "right_y_m",
    "right_z_m",
    "right_qx",
    "right_qy",
    "right_qz",
    "right_qw",
    "right_fov_left_rad",
    "right_fov_right_rad",
    "right_fov_up_rad",
    "right_fov_down_rad",
];

/// Farthest an eye may be from the head's origin, metres: further is a unit mistake or a
/// pose in the wrong frame.
pub const MAX_EYE_OFFSET_M: f32 = 0.5;

/// One eye's view in the head's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadView {
    /// The eye's position and the view's orientation, in the head's frame.
    pub pose: Pose,
    /// The view's field.
    pub fov: Fov,
}

impl HeadView {
    /// The view in the world for the head at `head`.
    pub fn in_world(&self, head: &Pose) -> Pose {
        Pose {
            position: head.position + head.orientation * self.pose.position,
            orientation: (head.orientation * self.pose.orientation).normalize(),
        }
    }

    /// The view in the head's frame of a view `eye` in the world, for the head at `head`.
    pub fn of(head: &Pose, eye: &Pose, fov: Fov) -> HeadView {
        let inverse = head.orientation.inverse();
        HeadView {
            pose: Pose {
                position: inverse * (eye.position - head.position),
                orientation: (inverse * eye.orientation).normalize(),
            },
            fov,
        }
    }

    /// Whether `other` differs by more than a hundredth of a millimetre in position or about
    /// 0.006 degrees in orientation or any edge of its field: a new views line is due.
    pub fn differs(&self, other: &HeadView) -> bool {
        const POSITION_M: f32 = 1e-5;
        const ANGLE_RAD: f32 = 1e-4;
        let edges = |f: &Fov| {
            [
                f.angle_left_rad,
                f.angle_right_rad,
                f.angle_up_rad,
                f.angle_down_rad,
            ]
        };
        self.pose.position.distance(other.pose.position) > POSITION_M
            || turn_between(self.pose.orientation, other.pose.orientation) > ANGLE_RAD
            || edges(&self.fov)
                .iter()
                .zip(edges(&other.fov))
                .any(|(a, b)| (a - b).abs() > ANGLE_RAD)
    }
}

/// The eyes a headset drew from, from a time on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewsRecord {
    /// Display time of the first frame drawn from these views, nanoseconds on the trace clock.
    pub time_ns: i64,
    /// Left and right eye.
    pub eyes: [HeadView; 2],
}

/// Checks a views line at `time_ns` after the line before it (at `previous_ns`): not before
/// it, every number finite, each eye within [`MAX_EYE_OFFSET_M`] of the head, each
/// orientation a unit quaternion (within [`QUAT_NORM_TOLERANCE`], then normalised), each field
/// with its left edge left of its right, its down edge below its up, all within 90 degrees.
pub(super) fn check_views(
    file: &str,
    line: usize,
    views: &ViewsRecord,
    previous_ns: Option<i64>,
) -> Result<ViewsRecord, TraceError> {
    let bad = |reason: String| TraceError::BadViews {
        file: file.to_owned(),
        line,
        reason,
    };
    if let Some(p) = previous_ns
        && views.time_ns < p
    {
        return Err(bad(format!(
            "time_ns {} is before the line it follows ({p})",
            views.time_ns
        )));
    }
    let mut out = *views;
    for (eye, (name, view)) in ["left", "right"]
        .iter()
        .zip(out.eyes.iter_mut())
        .enumerate()
    {
        let base = 2 + eye * 11;
        let numbers = [
            view.pose.position.x,
            view.pose.position.y,
            view.pose.position.z,
            view.pose.orientation.x,
            view.pose.orientation.y,
            view.pose.orientation.z,
            view.pose.orientation.w,
            view.fov.angle_left_rad,
            view.fov.angle_right_rad,
            view.fov.angle_up_rad,
            view.fov.angle_down_rad,
        ];
        if let Some(i) = numbers.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!(
                "{} is {}: expected a finite number",
                VIEWS_FIELDS[base + i],
                numbers[i]
            )));
        }
        let offset = view.pose.position.length();
        if offset > MAX_EYE_OFFSET_M {
            return Err(bad(format!(
                "the {name} eye is {offset} m from the head: at most {MAX_EYE_OFFSET_M} m \
                 (positions are in metres, in the head's frame)"
            )));
        }
        let norm = view.pose.orientation.length();
        if (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
            return Err(bad(format!(
                "the {name} view's quaternion has norm {norm}: expected 1 (within \
                 {QUAT_NORM_TOLERANCE})"
            )));
        }
        view.pose.orientation = view.pose.orientation.normalize();
        let f = view.fov;
        let quarter = std::f32::consts::FRAC_PI_2;
        let within = |a: f32| a.abs() < quarter;
        if !(f.angle_left_rad < f.angle_right_rad
            && f.angle_down_rad < f.angle_up_rad
            && [
                f.angle_left_rad,
                f.angle_right_rad,
                f.angle_up_rad,
                f.angle_down_rad,
            ]
            .into_iter()
            .all(within))
        {
            return Err(bad(format!(
                "the {name} eye's field (left {}, right {}, up {}, down {} rad) is not one: \
                 expected left < right and down < up, each within 90 degrees",
                f.angle_left_rad, f.angle_right_rad, f.angle_up_rad, f.angle_down_rad
            )));
        }
    }
    Ok(out)
}

/// Parses a views line (its first field is [`VIEWS_TAG`]) without the checks.
pub(super) fn parse_views(record: &Record<'_>) -> Result<ViewsRecord, TraceError> {
    record.expect_len(VIEWS_FIELDS.len())?;
    let time_ns = record.i64(1, VIEWS_FIELDS[1], "an integer number of nanoseconds")?;
    let number = |i: usize| record.f32(i, VIEWS_FIELDS[i]);
    let eye = |base: usize| -> Result<HeadView, TraceError> {
        Ok(HeadView {
            pose: Pose {
                position: Vec3::new(number(base)?, number(base + 1)?, number(base + 2)?),
                orientation: Quat::from_xyzw(
                    number(base + 3)?,
                    number(base + 4)?,
                    number(base + 5)?,
                    number(base + 6)?,
                ),
            },
            fov: Fov {
                angle_left_rad: number(base + 7)?,
                angle_right_rad: number(base + 8)?,
                angle_up_rad: number(base + 9)?,
                angle_down_rad: number(base + 10)?,
            },
        })
    };
    Ok(ViewsRecord {
        time_ns,
        eyes: [eye(2)?, eye(13)?],
    })
}

/// The line of a views record (with its line ending).
pub(super) fn format_views(views: &ViewsRecord) -> String {
    let mut out = format!("{VIEWS_TAG},{}", views.time_ns);
    for v in &views.eyes {
        let (p, q, f) = (v.pose.position, v.pose.orientation, v.fov);
        for n in [
            p.x,
            p.y,
            p.z,
            q.x,
            q.y,
            q.z,
            q.w,
            f.angle_left_rad,
            f.angle_right_rad,
            f.angle_up_rad,
            f.angle_down_rad,
        ] {
            out.push(',');
            out.push_str(&n.to_string());
        }
    }
    out.push('\n');
    out
}

#[cfg(test)]
mod tests {
    use super::super::test_traces::sample;
    use super::super::*;
    use super::*;

    /// Eyes `ipd_m` apart, each turned `toe_out_deg` outwards, with a field of `h` by `v`
    /// radians.
    fn views(time_ns: i64, ipd_m: f32, toe_out_deg: f32, h: f32, v: f32) -> ViewsRecord {
        let eye = |side: f32| HeadView {
            pose: Pose {
                position: Vec3::new(side * ipd_m / 2.0, 0.0, 0.0),
                orientation: Quat::from_rotation_y(-side * toe_out_deg.to_radians()),
            },
            fov: Fov::symmetric(h, v),
        };
        ViewsRecord {
            time_ns,
            eyes: [eye(-1.0), eye(1.0)],
        }
    }

    #[test]
    fn views_round_trip_in_version_1_5_among_samples_and_events() {
        let first = views(1000, 0.058, 2.0, 1.48, 1.56);
        let second = views(3000, 0.061, 0.0, 1.48, 1.56);
        let mut w = TraceWriter::with_version(Vec::new(), "v", TraceVersion::V1_5).unwrap();
        // Before the first sample it waits for the header, as events do.
        w.write_views(&first).unwrap();
        w.write(&sample(1000)).unwrap();
        w.write(&sample(2000)).unwrap();
        w.write_views(&second).unwrap();
        w.write(&sample(3000)).unwrap();
        // Not before the line it follows.
        assert!(matches!(
            w.write_views(&views(2999, 0.06, 0.0, 1.0, 1.0)),
            Err(TraceError::BadViews { .. })
        ));
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], VERSION_LINE_V1_5);
        assert!(
            lines[2].starts_with("views,1000,-0.029,0,0,"),
            "{}",
            lines[2]
        );
        assert_eq!(lines[2].split(',').count(), VIEWS_FIELDS.len());
        assert!(lines[5].starts_with("views,3000,"), "{}", lines[5]);
        let mut r = TraceReader::new(text.as_bytes(), "v").unwrap();
        let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(read.len(), 3);
        let got = r.take_views();
        assert_eq!(got.len(), 2);
        for (g, want) in got.iter().zip([first, second]) {
            assert_eq!(g.time_ns, want.time_ns);
            for (a, b) in g.eyes.iter().zip(want.eyes) {
                assert!(!a.differs(&b), "{a:?} {b:?}");
            }
        }
        // Earlier versions hold no views lines.
        let mut w = TraceWriter::with_version(Vec::new(), "v", TraceVersion::V1_4).unwrap();
        assert!(matches!(
            w.write_views(&first),
            Err(TraceError::ViewsNotInVersion { .. })
        ));
    }

    #[test]
    fn bad_views_lines_name_the_line_and_what_is_wrong() {
        let head = format!("{VERSION_LINE_V1_5}\n{}\n", COLUMNS_V1_3.join(","));
        let good: Vec<String> = format_views(&views(10, 0.063, 0.0, 1.4, 1.2))
            .trim_end()
            .split(',')
            .map(str::to_owned)
            .collect();
        let with = |i: usize, value: &str| {
            let mut f = good.clone();
            f[i] = value.to_owned();
            f.join(",")
        };
        for (line, says) in [
            (with(1, "x"), "time_ns"),
            (with(2, "nan"), "left_x_m is NaN"),
            (with(13, "0.7"), "the right eye is 0.7 m from the head"),
            (with(8, "2"), "the left view's quaternion has norm"),
            (with(9, "0.9"), "the left eye's field"),
            (with(23, "-1.6"), "the right eye's field"),
            (format!("{},1", good.join(",")), "fields"),
        ] {
            let text = format!("{head}{line}\n");
            let mut r = TraceReader::new(text.as_bytes(), "bad.trace").unwrap();
            let e = r.next().unwrap().unwrap_err().to_string();
            assert!(e.contains("bad.trace:3") && e.contains(says), "{line}: {e}");
        }
        // In version 1.4 a views line is a sample line that does not parse.
        let text = format!(
            "{VERSION_LINE_V1_4}\n{}\n{}\n",
            COLUMNS_V1_3.join(","),
            good.join(",")
        );
        let mut r = TraceReader::new(text.as_bytes(), "old.trace").unwrap();
        assert!(r.next().unwrap().is_err());
    }

    #[test]
    fn a_view_in_the_head_frame_goes_back_to_the_world() {
        let head = Pose {
            position: Vec3::new(0.4, 1.6, -0.3),
            orientation: Quat::from_rotation_y(0.6) * Quat::from_rotation_x(-0.3),
        };
        let eye = Pose {
            position: head.position + head.orientation * Vec3::new(0.031, 0.002, 0.01),
            orientation: head.orientation * Quat::from_rotation_y(-0.05),
        };
        let fov = Fov::symmetric(1.0, 0.8);
        let v = HeadView::of(&head, &eye, fov);
        assert!((v.pose.position - Vec3::new(0.031, 0.002, 0.01)).length() < 1e-6);
        let back = v.in_world(&head);
        assert!(back.position.distance(eye.position) < 1e-6);
        assert!(back.orientation.angle_between(eye.orientation) < 1e-5);
        // A hundredth of a millimetre is the same line; a tenth is a new one.
        let mut moved = v;
        moved.pose.position.x += 5e-6;
        assert!(!v.differs(&moved));
        moved.pose.position.x += 1e-4;
        assert!(v.differs(&moved));
        let mut wider = v;
        wider.fov.angle_left_rad -= 1e-3;
        assert!(v.differs(&wider));
    }

    #[test]
    fn a_turned_eye_carried_by_a_moving_head_is_the_same_line() {
        // An eye turned half a degree outwards, seen from a head that walks and turns: the
        // round trip through the world moves it by f32 rounding only, which must not read as a
        // turn (an arc cosine of the quaternions' dot product reads it as 0.04 degrees).
        let fov = Fov::symmetric(1.0, 0.8);
        let eye = HeadView {
            pose: Pose {
                position: Vec3::new(-0.02775, 0.0, 0.0),
                orientation: Quat::from_rotation_y(0.5f32.to_radians()),
            },
            fov,
        };
        for k in 0..500 {
            let t = k as f32 * 0.05;
            let head = Pose {
                position: Vec3::new(t.sin() * 0.3, 1.6 + 0.01 * t.cos(), -0.02 * t),
                orientation: Quat::from_rotation_y(0.4 * t.sin()) * Quat::from_rotation_x(0.1 * t),
            };
            let again = HeadView::of(&head, &eye.in_world(&head), fov);
            assert!(!eye.differs(&again), "head {k}: {again:?}");
        }
        // A hundredth of a degree more is a new line.
        let mut turned = eye;
        turned.pose.orientation *= Quat::from_rotation_y(0.01f32.to_radians());
        assert!(eye.differs(&turned));
    }
}
