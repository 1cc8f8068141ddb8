//! `vitreous run --record`: each frame's head pose and gaze written as a trace, with a views
//! line whenever the eyes the headset drew from change, and the check that a replay of that
//! trace with the null backend reproduces the session's views.

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::Quat;
use serde::Serialize;
use vitreous_trace::format::{HeadView, TraceSample, ViewsRecord, read_recording};
use vitreous_trace::frame::turn_between;
use vitreous_trace::{Fov, FrameInput, GazeSample, Pose};
use vitreous_xr::Backend;
use vitreous_xr::null::{NullBackend, NullConfig};

/// How well a replay of the recording reproduces the session's views.
#[derive(Clone, Debug, Serialize)]
pub struct ReplayCheck {
    /// Samples in the recording.
    pub samples: u64,
    /// Replay frames compared.
    pub frames: u64,
    /// Largest head position difference, metres.
    pub max_head_position_m: f32,
    /// Largest head orientation difference, degrees.
    pub max_head_angle_deg: f32,
    /// Largest eye position difference, metres (the replay draws from the recorded views).
    pub max_eye_position_m: f32,
    /// Largest difference of a view's orientation, degrees.
    pub max_eye_angle_deg: f32,
}

/// The angle between two orientations, degrees ([`turn_between`]).
fn angle_deg(a: Quat, b: Quat) -> f32 {
    turn_between(a, b).to_degrees()
}

/// The views line a frame needs recorded before its sample: the first frame's, then one
/// whenever an eye moved or turned or its field changed against `last` (the eyes of the line
/// written before).
pub(super) fn views_due(input: &FrameInput, last: Option<&[HeadView; 2]>) -> Option<ViewsRecord> {
    let eyes = input
        .views
        .each_ref()
        .map(|v| HeadView::of(&input.head, &v.pose, v.fov));
    let changed = last.is_none_or(|last| last.iter().zip(&eyes).any(|(a, b)| a.differs(b)));
    changed.then_some(ViewsRecord {
        time_ns: input.time_ns,
        eyes,
    })
}

/// A trace sample for a frame: its head pose and gaze. A frame without gaze gets an invalid
/// gaze stamped with the newest gaze time recorded before it, `newest_gaze_ns` (nothing new:
/// a later frame's sample may be stamped before this frame's display time, and a trace's gaze
/// times must not go back), or with its own time when none was.
pub(super) fn trace_sample(input: &FrameInput, newest_gaze_ns: Option<i64>) -> TraceSample {
    TraceSample {
        time_ns: input.time_ns,
        head: input.head,
        gaze: input
            .gaze
            .unwrap_or(GazeSample::none(newest_gaze_ns.unwrap_or(input.time_ns))),
    }
}

/// Replays the recording with the null backend at the session's mean frame rate and compares
/// its views with the session's at the replay's frame times: the head interpolated between the
/// session's frames, each eye where the earlier frame had it in the head.
/// `fov` and `ipd_m` are the scene's (what a replay draws with where the recording has no
/// views lines).
pub(super) fn replay_check(
    path: &Path,
    session: &[FrameInput],
    fov: Fov,
    ipd_m: f32,
) -> Result<ReplayCheck> {
    let recording =
        read_recording(path).with_context(|| format!("reading back {}", path.display()))?;
    let samples = recording.samples;
    if samples.len() < 2 || session.len() < 2 {
        bail!("the recording {} has fewer than 2 samples", path.display());
    }
    let span_ns = session[session.len() - 1].time_ns - session[0].time_ns;
    let rate_hz = (session.len() - 1) as f64 * 1e9 / span_ns as f64;
    let mut null = NullBackend::new(
        samples.clone(),
        NullConfig {
            frame_rate_hz: rate_hz,
            max_frames: None,
            fov,
            ipd_m,
            at_samples: false,
        },
    )?
    .with_views(recording.views);
    let (mut frames, mut max_pos, mut max_ang, mut max_eye) = (0u64, 0f32, 0f32, 0f32);
    let mut max_eye_angle = 0f32;
    while let Some(frame) = null.wait_frame()? {
        null.end_frame(&frame)?;
        let t = frame.time_ns;
        let Some(b) = session.iter().position(|s| s.time_ns >= t) else {
            break;
        };
        let expected = if session[b].time_ns == t || b == 0 {
            session[b].clone()
        } else {
            let a = &session[b - 1];
            let f = (t - a.time_ns) as f32 / (session[b].time_ns - a.time_ns) as f32;
            let lerp = |p: &Pose, q: &Pose| Pose {
                position: p.position.lerp(q.position, f),
                orientation: p.orientation.slerp(q.orientation, f),
            };
            // The eyes keep frame a's place in the head until frame b (a views line holds
            // from its time on), carried by the head between the two.
            let mut e = a.clone();
            e.head = lerp(&a.head, &session[b].head);
            for eye in 0..2 {
                let view = &a.views[eye];
                e.views[eye].pose = HeadView::of(&a.head, &view.pose, view.fov).in_world(&e.head);
            }
            e
        };
        frames += 1;
        max_pos = max_pos.max((frame.head.position - expected.head.position).length());
        max_ang = max_ang.max(angle_deg(frame.head.orientation, expected.head.orientation));
        for eye in 0..2 {
            let (got, want) = (&frame.views[eye].pose, &expected.views[eye].pose);
            max_eye = max_eye.max((got.position - want.position).length());
            max_eye_angle = max_eye_angle.max(angle_deg(got.orientation, want.orientation));
        }
    }
    Ok(ReplayCheck {
        samples: samples.len() as u64,
        frames,
        max_head_position_m: max_pos,
        max_head_angle_deg: max_ang,
        max_eye_position_m: max_eye,
        max_eye_angle_deg: max_eye_angle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::test_frame as frame;

    #[test]
    fn small_turns_are_measured_below_the_arc_cosines_floor() {
        let a = Quat::from_rotation_y(0.7);
        for deg in [0.0f32, 0.001, 0.01, 0.1, 2.0, 30.0] {
            let b = a * Quat::from_rotation_x(deg.to_radians());
            assert!(
                (angle_deg(a, b) - deg).abs() < 1e-4 + deg * 1e-4,
                "{deg}: {}",
                angle_deg(a, b)
            );
        }
        // The same turn with the sign of a quaternion flipped.
        assert!(angle_deg(a, -a) < 1e-4);
    }

    #[test]
    fn views_are_due_at_the_first_frame_and_when_they_change() {
        let mut f = frame();
        f.head.position = glam::Vec3::new(0.1, 1.6, 0.0);
        f.views[0].pose.position = f.head.position - glam::Vec3::X * 0.029;
        f.views[1].pose.position = f.head.position + glam::Vec3::X * 0.029;
        let first = views_due(&f, None).expect("the first frame's views");
        assert_eq!(first.time_ns, 5);
        assert!(
            (first.eyes[1].pose.position.x - 0.029).abs() < 1e-6,
            "in the head's frame"
        );
        // The head moves with the eyes: nothing new.
        let mut moved = f.clone();
        moved.head.position.z -= 0.2;
        for v in &mut moved.views {
            v.pose.position.z -= 0.2;
        }
        assert_eq!(views_due(&moved, Some(&first.eyes)), None);
        // The eyes 2 mm further apart: a new line.
        moved.views[1].pose.position.x += 0.002;
        let next = views_due(&moved, Some(&first.eyes)).expect("new views");
        assert!((next.eyes[1].pose.position.x - 0.031).abs() < 1e-6);
    }

    #[test]
    fn the_replay_check_follows_eyes_that_change_mid_session() {
        use vitreous_trace::format::{TraceVersion, TraceWriter};
        // 40 frames 50 ms apart, give or take 7 ms, the head moving and turning; the eyes 63
        // mm apart and parallel, then from frame 20 on 58 mm apart and turned 2 degrees out.
        let session: Vec<FrameInput> = (0..40i64)
            .map(|i| {
                let mut f = frame();
                f.index = i as u64;
                f.time_ns = 1_000_000_000 + i * 50_000_000 + (i * 37 % 15 - 7) * 1_000_000;
                f.head = Pose {
                    position: glam::Vec3::new(0.01 * i as f32, 1.6, -0.005 * i as f32),
                    orientation: Quat::from_rotation_y(0.02 * i as f32),
                };
                let (half, turn) = if i < 20 { (0.0315, 0.0) } else { (0.029, 2f32) };
                for (view, side) in f.views.iter_mut().zip([-1.0f32, 1.0]) {
                    view.pose = HeadView {
                        pose: Pose {
                            position: glam::Vec3::X * half * side,
                            orientation: Quat::from_rotation_y(-side * turn.to_radians()),
                        },
                        fov: view.fov,
                    }
                    .in_world(&f.head);
                }
                f
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("recorded.trace");
        let mut writer = TraceWriter::create_version(&path, TraceVersion::V1_5).unwrap();
        let mut last = None;
        for f in &session {
            if let Some(views) = views_due(f, last.as_ref()) {
                writer.write_views(&views).unwrap();
                last = Some(views.eyes);
            }
            writer.write(&trace_sample(f, None)).unwrap();
        }
        writer.finish().unwrap();
        let check = replay_check(&path, &session, Fov::symmetric(1.0, 1.0), 0.063).unwrap();
        assert!(check.frames >= 38, "{check:?}");
        // Between two frames the replay's eyes are where the earlier one had them (interpolating
        // the session's eyes across the change would put them up to 2.5 mm and 2 degrees off).
        assert!(check.max_eye_position_m < 2e-6, "{check:?}");
        assert!(check.max_eye_angle_deg < 1e-3, "{check:?}");
    }

    #[test]
    fn a_frame_without_gaze_records_an_invalid_gaze_at_its_time() {
        let s = trace_sample(&frame(), None);
        assert_eq!(s.gaze.sample_time_ns, 5);
        assert!(!s.gaze.left.valid && !s.gaze.right.valid);
        // After a sample stamped 3: nothing new, at 3.
        let s = trace_sample(&frame(), Some(3));
        assert_eq!(s.gaze.sample_time_ns, 3);
        assert!(!s.gaze.left.valid && !s.gaze.right.valid);
    }
}
