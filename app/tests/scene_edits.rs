//! A recorded session's scene edits replayed on a moving scene (`moving-light.toml`) with
//! validation on: the edits offset the keyframed placement, each moves the scene once more
//! (one more computation of the inducer's fields, with which live caustics are computed), and
//! the replay ends where the edits put the object and the light.

use std::path::Path;

use glam::{Quat, Vec3};
use vitreous::replay::{ReplayOptions, replay};
use vitreous_scene::effects::EffectSet;
use vitreous_scene::load_scene;
use vitreous_trace::format::{EditRecord, TraceSample, TraceWriter};
use vitreous_trace::{GazeSample, Pose};

/// Frame spacing of the recording, nanoseconds (4 Hz).
const STEP_NS: i64 = 250_000_000;

fn sample(time_ns: i64) -> TraceSample {
    TraceSample {
        time_ns,
        head: Pose::IDENTITY,
        gaze: GazeSample::none(time_ns),
    }
}

#[test]
fn recorded_edits_offset_the_keyframes_and_move_the_scene_once_each() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/moving-light.toml");
    let trace = dir.path().join("edited.trace");
    // 32 frames, 0 to 7.75 s: the light circles until 6 s and holds until 8 s. Edits at 6.5 s
    // (the object 1 cm along x; the light, in the object's frame, follows) and 7 s (the light
    // 1 cm up), while the keyframes hold.
    let object = Vec3::new(0.01, 0.0, 0.0);
    let light = Vec3::new(0.0, 0.01, 0.0);
    let mut w = TraceWriter::create_with_edits(&trace).unwrap();
    for k in 0..32 {
        let t = k * STEP_NS;
        w.write(&sample(t)).unwrap();
        let edit = |action: &str, light_offset_m| EditRecord {
            time_ns: t,
            action: action.into(),
            object_offset_m: object,
            object_turn: Quat::IDENTITY,
            light_offset_m,
            world_offset_m: Vec3::ZERO,
            light_share: None,
        };
        if k == 26 {
            w.write_edit(&edit("object+10mmx", Vec3::ZERO)).unwrap();
        }
        if k == 28 {
            w.write_edit(&edit("light+10mmy", light)).unwrap();
        }
    }
    w.finish().unwrap();

    let summary = replay(&ReplayOptions {
        scene: scene_path.clone(),
        trace: Some(trace),
        out: dir.path().join("out"),
        frames: None,
        save_every: 0,
        size: Some((64, 48)),
        validate: true,
        effects: Some(EffectSet::parse("inducer").unwrap()),
        device: None,
        frame_rate_hz: 4.0,
        at_samples: true,
        progress: false,
        reflection: vitreous_render::Reflection::Phong,
        sphere_check: false,
        compare_reference: false,
        compare_shifts_deg: Vec::new(),
        gaze: Default::default(),
        fields: Default::default(),
    })
    .expect("replay");
    assert_eq!(summary.frames, 32);
    assert_eq!(summary.scene_edits, 2);
    // Frames 1-24 move with the keyframes, 26 and 28 with the edits.
    assert_eq!(summary.moved_frames, 24 + 2);
    assert_eq!(summary.inducer_computations, 1 + 24 + 2);
    let scene = load_scene(&scene_path).unwrap();
    let keyed = scene.placement_at(7.75);
    let end = summary.final_placement.expect("the scene moved");
    let close = |a: [f32; 3], b: Vec3| Vec3::from(a).abs_diff_eq(b, 1e-6);
    assert!(
        close(end.object_position_m, keyed.object_position_m + object),
        "{end:?}"
    );
    assert!(
        close(
            end.light_position_m,
            keyed.light_position_m + object + light
        ),
        "{end:?}"
    );
}
