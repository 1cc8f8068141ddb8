//! The headset's eye views over a live session, held against the scene's.
//!
//! Live, each eye is drawn from the view the runtime locates: its own distance between the
//! eyes, its displays' turn and fields of view. A recording keeps the head's pose and the gaze,
//! not the views, so `vitreous replay` of it draws other eyes: at the running mean of the eye
//! tracker's gaze origins (the scene's `[viewer] ipd_mm` apart before one is valid), parallel
//! to the head, with the scene's `[output]` field of view (the null backend,
//! `vitreous_xr::null`). [`ViewWatch`] measures the headset's eyes in the head's frame over
//! the session, the summary records them, and a recorded session warns where its replay draws
//! other views than the wearer saw.

use glam::Vec3;
use serde::Serialize;
use vitreous_trace::{EyeView, Fov, FrameInput, Pose};

/// Farthest an eye may be from where a replay puts it, unremarked, millimetres (half of a
/// 0.5 mm difference in the distance between the eyes, a tenth of the 5 mm between common
/// ipd steps).
pub const EYE_TOLERANCE_MM: f32 = 0.25;
/// Largest turn of a view against the head, or difference of a field's edge, a replay may
/// draw unremarked, degrees.
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
    /// The scene's distance between the eyes (`[viewer] ipd_mm`), where a replay puts the
    /// eyes before the eye tracker gives an origin.
    pub scene_ipd_mm: f32,
    /// The scene's field of view (`[output]`), what a replay draws.
    pub scene_fov_deg: [f32; 4],
    /// Where a replay of the recording puts an eye farthest from the headset's, millimetres
    /// (`None`: not recorded).
    pub replay_eye_mm: Option<f32>,
    /// Where a replay's views differ from the headset's (empty: the same, within
    /// [`EYE_TOLERANCE_MM`] and [`ANGLE_TOLERANCE_DEG`]).
    pub differences: Vec<String>,
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
    let inverse = head.orientation.inverse();
    (
        inverse * (eye.pose.position - head.position),
        inverse * eye.pose.orientation * Vec3::NEG_Z,
    )
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

    /// What the frames showed against the scene's eyes, and, for a recorded session, how far
    /// its replay put an eye from the headset's (`replay_eye_m`, metres; `None`: not
    /// recorded). `None` when no frame was drawn.
    pub fn summary(
        &self,
        scene_ipd_m: f32,
        scene_fov: &Fov,
        replay_eye_m: Option<f32>,
    ) -> Option<HeadsetViews> {
        let fov = self.fov?;
        let n = self.frames as f64;
        let (least, sum, most) = self.ipd_m;
        let ipd_mm = [least * 1e3, (sum / n * 1e3) as f32, most * 1e3];
        let toe_out_deg = self.toe_out_rad.map(|t| (t / n).to_degrees() as f32);
        let fov_deg = fov.each_ref().map(degrees);
        let scene_fov_deg = degrees(scene_fov);
        let scene_ipd_mm = scene_ipd_m * 1e3;
        let replay_eye_mm = replay_eye_m.map(|m| m * 1e3);
        let mut differences = Vec::new();
        if let Some(eye_mm) = replay_eye_mm.filter(|&mm| mm > EYE_TOLERANCE_MM) {
            differences.push(format!(
                "the eyes {:.1} mm apart, up to {eye_mm:.1} mm from where a replay puts them \
                 (the eye tracker's mean gaze origins; the scene's [viewer] ipd_mm = \
                 {scene_ipd_mm:.1} before one is valid)",
                ipd_mm[1]
            ));
        }
        if toe_out_deg.iter().any(|t| t.abs() > ANGLE_TOLERANCE_DEG) {
            differences.push(format!(
                "the views turned {:.2} and {:.2} degrees outwards (a replay's are parallel)",
                toe_out_deg[0], toe_out_deg[1]
            ));
        }
        for (eye, edges) in ["left", "right"].iter().zip(&fov_deg) {
            if edges
                .iter()
                .zip(&scene_fov_deg)
                .any(|(a, b)| (a - b).abs() > ANGLE_TOLERANCE_DEG)
            {
                differences.push(format!(
                    "the {eye} eye's field {:.1}/{:.1}/{:.1}/{:.1} degrees left/right/up/down \
                     (a replay draws the scene's {:.1}/{:.1}/{:.1}/{:.1})",
                    edges[0],
                    edges[1],
                    edges[2],
                    edges[3],
                    scene_fov_deg[0],
                    scene_fov_deg[1],
                    scene_fov_deg[2],
                    scene_fov_deg[3]
                ));
            }
        }
        Some(HeadsetViews {
            frames: self.frames,
            ipd_mm,
            toe_out_deg,
            fov_deg,
            scene_ipd_mm,
            scene_fov_deg,
            replay_eye_mm,
            differences,
        })
    }
}

impl HeadsetViews {
    /// The warning for a recorded session whose replay draws other views (`None`: the same).
    pub fn replay_warning(&self, recording: &str) -> Option<String> {
        if self.differences.is_empty() {
            return None;
        }
        Some(format!(
            "a replay of {recording} draws other views than the headset did (a recording keeps \
             the head and the gaze, not the views): the headset drew {}",
            self.differences.join("; ")
        ))
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
    fn the_scenes_own_eyes_differ_in_nothing() {
        let fov = Fov::symmetric(1.2, 0.9);
        let mut w = ViewWatch::default();
        for _ in 0..3 {
            w.watch(&frame(turned_head(), 0.063, 0.0, fov));
        }
        let s = w.summary(0.063, &fov, Some(0.0001)).unwrap();
        assert_eq!(s.frames, 3);
        assert!((s.ipd_mm[1] - 63.0).abs() < 1e-3, "{s:?}");
        assert!(s.toe_out_deg.iter().all(|t| t.abs() < 1e-3), "{s:?}");
        assert!(s.differences.is_empty(), "{s:?}");
        assert_eq!(s.replay_warning("r.trace"), None);
        assert_eq!(ViewWatch::default().summary(0.063, &fov, None), None);
    }

    #[test]
    fn another_ipd_a_cant_and_a_field_are_each_named() {
        let fov = Fov::symmetric(1.2, 0.9);
        let mut w = ViewWatch::default();
        w.watch(&frame(turned_head(), 0.057, 3.0, Fov::symmetric(1.3, 0.9)));
        w.watch(&frame(turned_head(), 0.059, 3.0, Fov::symmetric(1.3, 0.9)));
        let s = w.summary(0.063, &fov, Some(0.0025)).unwrap();
        assert!((s.ipd_mm[0] - 57.0).abs() < 1e-3 && (s.ipd_mm[2] - 59.0).abs() < 1e-3);
        assert!((s.ipd_mm[1] - 58.0).abs() < 1e-3);
        for t in s.toe_out_deg {
            assert!((t - 3.0).abs() < 1e-3, "{s:?}");
        }
        assert_eq!(s.differences.len(), 4, "{:?}", s.differences);
        let warning = s.replay_warning("r.trace").unwrap();
        for part in [
            "58.0 mm apart, up to 2.5 mm from where a replay puts them",
            "3.00 and 3.00 degrees outwards",
            "left eye's field",
            "r.trace",
        ] {
            assert!(warning.contains(part), "{part}: {warning}");
        }
        // Not recorded: no replay to place the eyes, the turn and fields still named.
        assert_eq!(w.summary(0.063, &fov, None).unwrap().differences.len(), 3);
        // Within the tolerances: nothing named.
        let mut w = ViewWatch::default();
        w.watch(&frame(turned_head(), 0.0633, 0.05, fov));
        let s = w.summary(0.063, &fov, Some(0.0002)).unwrap();
        assert!(s.differences.is_empty(), "{s:?}");
    }
}
