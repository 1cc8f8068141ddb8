//! The headset's eye views over a live session, against a replay's.
//!
//! Live, each eye is drawn from the view the runtime locates: its own distance between the
//! eyes, its displays' turn and fields of view. `--record` writes those eyes into the trace
//! (version 1.5's views lines, in the head's frame) and `vitreous replay` of it draws from them,
//! with the scene's `[output]` field of view (a replay's images are its own size); a trace
//! without views lines replays from eyes at the running mean of the eye tracker's gaze origins,
//! parallel (the null backend, `vitreous_xr::null`). [`ViewWatch`] measures the headset's eyes in
//! the head's frame over the session; the summary records them, how far the replay of the
//! recording put an eye from the headset's (its position and its view's direction), and a
//! recorded session whose replay does not draw from the same eyes ends with a warning.

use glam::Vec3;
use serde::Serialize;
use vitreous_trace::format::HeadView;
use vitreous_trace::{EyeView, Fov, FrameInput, Pose};

/// Farthest an eye may be from where a replay puts it, unremarked, millimetres (half of a
/// 0.5 mm difference in the distance between the eyes, a tenth of the 5 mm between common
/// ipd steps).
pub const EYE_TOLERANCE_MM: f32 = 0.25;
/// Largest turn of a replay's view against the headset's, or difference of a field's edge,
/// unremarked, degrees.
pub const ANGLE_TOLERANCE_DEG: f32 = 0.1;

/// The headset's eyes over the frames drawn (`summary.json`'s `headset_views`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeadsetViews {
    /// Frames measured.
    pub frames: u64,
    /// Distance between the eyes: least, mean and most, millimetres.
    pub ipd_mm: [f32; 3],
    /// How far each eye's view is turned outwards from the head's forward, about its up axis,
    /// degrees (left, right; the mean over the frames).
    pub toe_out_deg: [f32; 2],
    /// Each eye's field of view in its last frame: left, right, up, down edge, degrees (left,
    /// right eye).
    pub fov_deg: [[f32; 4]; 2],
    /// The scene's field of view (`[output]`), what a replay draws.
    pub scene_fov_deg: [f32; 4],
    /// The farthest the replay of the recording put an eye from the headset's, millimetres
    /// (`None`: not recorded).
    pub replay_eye_mm: Option<f32>,
    /// The most the replay of the recording turned a view from the headset's, degrees
    /// (`None`: not recorded).
    pub replay_eye_deg: Option<f32>,
    /// Where the replay of the recording drew from other eyes than the headset (empty: the
    /// same, within [`EYE_TOLERANCE_MM`] and [`ANGLE_TOLERANCE_DEG`], or not recorded).
    pub differences: Vec<String>,
    /// Whether the headset's fields differ from the scene's, which a replay draws.
    pub fields_differ: bool,
}

/// Watches each frame's views (module docs).
#[derive(Clone, Debug, Default)]
pub struct ViewWatch {
    frames: u64,
    ipd_m: (f32, f64, f32),
    toe_out_rad: [f64; 2],
    fov: Option<[Fov; 2]>,
}

/// An eye's position and forward direction in the head's frame.
fn in_head(head: &Pose, eye: &EyeView) -> (Vec3, Vec3) {
    let view = HeadView::of(head, &eye.pose, eye.fov).pose;
    (view.position, view.orientation * Vec3::NEG_Z)
}

/// The fields' edges in degrees: left, right, up, down.
fn degrees(fov: &Fov) -> [f32; 4] {
    [
        fov.angle_left_rad,
        fov.angle_right_rad,
        fov.angle_up_rad,
        fov.angle_down_rad,
    ]
    .map(f32::to_degrees)
}

impl ViewWatch {
    /// Takes one drawn frame's views.
    pub fn watch(&mut self, input: &FrameInput) {
        let [(left, left_forward), (right, right_forward)] =
            input.views.each_ref().map(|v| in_head(&input.head, v));
        let ipd = left.distance(right);
        if !ipd.is_finite() {
            return;
        }
        let (least, sum, most) = &mut self.ipd_m;
        if self.frames == 0 {
            (*least, *most) = (ipd, ipd);
        }
        (*least, *most) = (least.min(ipd), most.max(ipd));
        *sum += f64::from(ipd);
        // Turned to the left about +y is positive; outwards is left for the left eye.
        let yaw = |f: Vec3| f64::from((-f.x).atan2(-f.z));
        self.toe_out_rad[0] += yaw(left_forward);
        self.toe_out_rad[1] -= yaw(right_forward);
        self.fov = Some([input.views[0].fov, input.views[1].fov]);
        self.frames += 1;
    }

    /// What the frames showed, with, for a recorded session, the farthest its replay put an
    /// eye from the headset's and the most it turned a view (`replay`: metres, degrees;
    /// `None`: not recorded). `None` when no frame was drawn.
    pub fn summary(&self, scene_fov: &Fov, replay: Option<(f32, f32)>) -> Option<HeadsetViews> {
        let fov = self.fov?;
        let n = self.frames as f64;
        let (least, sum, most) = self.ipd_m;
        let ipd_mm = [least * 1e3, (sum / n * 1e3) as f32, most * 1e3];
        let toe_out_deg = self.toe_out_rad.map(|t| (t / n).to_degrees() as f32);
        let fov_deg = fov.each_ref().map(degrees);
        let scene_fov_deg = degrees(scene_fov);
        let replay_eye_mm = replay.map(|(m, _)| m * 1e3);
        let replay_eye_deg = replay.map(|(_, deg)| deg);
        let mut differences = Vec::new();
        if let Some(eye_mm) = replay_eye_mm.filter(|&mm| mm > EYE_TOLERANCE_MM) {
            differences.push(format!(
                "an eye up to {eye_mm:.2} mm from the headset's (its eyes {:.1} mm apart)",
                ipd_mm[1]
            ));
        }
        if let Some(deg) = replay_eye_deg.filter(|&deg| deg > ANGLE_TOLERANCE_DEG) {
            differences.push(format!(
                "a view turned up to {deg:.2} degrees from the headset's (its views {:.2} and \
                 {:.2} degrees outwards)",
                toe_out_deg[0], toe_out_deg[1]
            ));
        }
        let fields_differ = fov_deg.iter().any(|edges| {
            edges
                .iter()
                .zip(&scene_fov_deg)
                .any(|(a, b)| (a - b).abs() > ANGLE_TOLERANCE_DEG)
        });
        Some(HeadsetViews {
            frames: self.frames,
            ipd_mm,
            toe_out_deg,
            fov_deg,
            scene_fov_deg,
            replay_eye_mm,
            replay_eye_deg,
            differences,
            fields_differ,
        })
    }
}

impl HeadsetViews {
    /// The warning for a recorded session whose replay drew from other eyes (`None`: the
    /// same).
    pub fn replay_warning(&self, recording: &str) -> Option<String> {
        if self.differences.is_empty() {
            return None;
        }
        Some(format!(
            "the replay of {recording} does not draw from the headset's eyes: {}",
            self.differences.join("; ")
        ))
    }

    /// What a replay draws for the field of view, when it is not the headset's.
    pub fn field_note(&self) -> Option<String> {
        let [l, r] = &self.fov_deg;
        let s = &self.scene_fov_deg;
        self.fields_differ.then(|| {
            format!(
                "the headset's fields are {:.1}/{:.1}/{:.1}/{:.1} and {:.1}/{:.1}/{:.1}/{:.1} \
                 degrees left/right/up/down; a replay draws the scene's [output] field, \
                 {:.1}/{:.1}/{:.1}/{:.1}",
                l[0], l[1], l[2], l[3], r[0], r[1], r[2], r[3], s[0], s[1], s[2], s[3]
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// A frame with the head at `head` and eyes `ipd_m` apart, each turned `toe_out_deg`
    /// outwards, with `fov`.
    fn frame(head: Pose, ipd_m: f32, toe_out_deg: f32, fov: Fov) -> FrameInput {
        let eye = |side: f32| EyeView {
            pose: Pose {
                position: head.position + head.orientation * Vec3::X * (side * ipd_m / 2.0),
                orientation: head.orientation
                    * Quat::from_rotation_y(-side * toe_out_deg.to_radians()),
            },
            fov,
        };
        FrameInput {
            index: 0,
            time_ns: 0,
            head,
            views: [eye(-1.0), eye(1.0)],
            gaze: None,
        }
    }

    fn turned_head() -> Pose {
        Pose {
            position: Vec3::new(0.3, 1.6, -0.2),
            orientation: Quat::from_rotation_y(0.7) * Quat::from_rotation_x(-0.2),
        }
    }

    #[test]
    fn eyes_replayed_where_they_were_differ_in_nothing() {
        let fov = Fov::symmetric(1.2, 0.9);
        let mut w = ViewWatch::default();
        for _ in 0..3 {
            w.watch(&frame(turned_head(), 0.063, 0.0, fov));
        }
        let s = w.summary(&fov, Some((0.0001, 0.01))).unwrap();
        assert_eq!(s.frames, 3);
        assert!((s.ipd_mm[1] - 63.0).abs() < 1e-3, "{s:?}");
        assert!(s.toe_out_deg.iter().all(|t| t.abs() < 1e-3), "{s:?}");
        assert!(s.differences.is_empty() && !s.fields_differ, "{s:?}");
        assert_eq!(s.replay_warning("r.trace"), None);
        assert_eq!(s.field_note(), None);
        assert_eq!(ViewWatch::default().summary(&fov, None), None);
    }

    #[test]
    fn the_headsets_eyes_are_measured_and_a_replay_elsewhere_is_named() {
        let fov = Fov::symmetric(1.2, 0.9);
        let mut w = ViewWatch::default();
        w.watch(&frame(turned_head(), 0.057, 3.0, Fov::symmetric(1.3, 0.9)));
        w.watch(&frame(turned_head(), 0.059, 3.0, Fov::symmetric(1.3, 0.9)));
        let s = w.summary(&fov, Some((0.0025, 3.0))).unwrap();
        assert!((s.ipd_mm[0] - 57.0).abs() < 1e-3 && (s.ipd_mm[2] - 59.0).abs() < 1e-3);
        assert!((s.ipd_mm[1] - 58.0).abs() < 1e-3);
        for t in s.toe_out_deg {
            assert!((t - 3.0).abs() < 1e-3, "{s:?}");
        }
        assert_eq!(s.differences.len(), 2, "{:?}", s.differences);
        let warning = s.replay_warning("r.trace").unwrap();
        for part in [
            "r.trace",
            "an eye up to 2.50 mm from the headset's (its eyes 58.0 mm apart)",
            "a view turned up to 3.00 degrees from the headset's (its views 3.00 and 3.00",
        ] {
            assert!(warning.contains(part), "{part}: {warning}");
        }
        assert!(
            s.field_note()
                .unwrap()
                .contains("-37.2/37.2/25.8/-25.8 and"),
            "{:?}",
            s.field_note()
        );
        // Replayed from the same eyes (a version 1.5 recording): measured, nothing named.
        let s = w.summary(&fov, Some((0.0001, 0.001))).unwrap();
        assert!(s.differences.is_empty(), "{s:?}");
        // Not recorded: no replay to compare.
        let s = w.summary(&fov, None).unwrap();
        assert!(
            s.differences.is_empty() && s.replay_eye_mm.is_none(),
            "{s:?}"
        );
    }
}
