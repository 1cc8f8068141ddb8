//! `vitreous soak` replays a scene's motion as `replay` does: a moving scene's object and
//! light move in every pass, so a soak of a live scene recomputes its caustics, and a still
//! scene never moves.

use std::path::{Path, PathBuf};
use std::time::Duration;

use vitreous::effects::EffectSet;
use vitreous::soak::{SoakOptions, soak};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One short pass of `scene` in condition c, validation on.
fn one_pass(scene: &str) -> vitreous::soak::SoakReport {
    let options = SoakOptions {
        scene: workspace().join("config/scenes").join(scene),
        effects: Some(EffectSet::parse("c").expect("condition c")),
        duration: Duration::ZERO,
        size: (64, 48),
        frames_per_pass: 6,
        read_back_every: 3,
        validation: true,
        recreate: false,
        report: None,
    };
    let mut passes = 0;
    let report = soak(&options, |_| passes += 1).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(passes, 1, "a zero duration runs one pass");
    report
}

#[test]
fn a_soak_moves_a_moving_scene_and_keeps_a_still_one_still() {
    let moving = one_pass("moving-light.toml");
    let pass = &moving.passes[0];
    assert_eq!(pass.frames, 6);
    // The first frame places the scene; each later one moves the light along its circle.
    assert_eq!(pass.moved_frames, 5, "{pass}");
    assert_eq!(moving.validation_messages, 0, "{:?}", moving.first_messages);
    let still = one_pass("glass-sphere.toml");
    assert_eq!(still.passes[0].moved_frames, 0, "{}", still.passes[0]);
    assert_eq!(still.validation_messages, 0, "{:?}", still.first_messages);
}
