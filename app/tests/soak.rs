//! `vitreous soak` replays a scene's motion as `replay` does: a moving scene's object and
//! light move in every pass, so a soak of a live scene recomputes its caustics, and a still
//! scene never moves.

use std::path::{Path, PathBuf};
use std::time::Duration;

use vitreous_frames::soak::{SoakEffects, SoakLength, SoakOptions, soak};
use vitreous_scene::effects::EffectSet;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One short pass of `scene` in condition c, validation on.
fn one_pass(scene: &str) -> vitreous_frames::soak::SoakReport {
    let options = SoakOptions {
        scene: workspace().join("config/scenes").join(scene),
        effects: SoakEffects::Set(EffectSet::parse("c").expect("condition c")),
        length: SoakLength::Duration(Duration::ZERO),
        size: (64, 48),
        frames_per_pass: 6,
        read_back_every: 3,
        validation: true,
        recreate: false,
        report: None,
        max_growth_percent: vitreous_frames::soak::MAX_GROWTH_PERCENT,
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

#[test]
fn soak_values_out_of_range_name_the_option() {
    let cwd = workspace();
    let cases: [(&[&str], &[&str]); 4] = [
        (&["--passes", "3"], &["--passes", "at least 4"]),
        (
            &["--max-growth", "-1"],
            &["--max-growth", "0 percent or more"],
        ),
        (
            &["--passes", "6", "--minutes", "1"],
            &["--passes", "--minutes"],
        ),
        (
            &["--all-effects", "--effects", "all"],
            &["--all-effects", "--effects"],
        ),
    ];
    for (args, needles) in cases {
        let mut all = vec!["soak", "config/scenes/glass-sphere.toml"];
        all.extend_from_slice(args);
        let out = crate::cli::vitreous(&all, &cwd);
        crate::cli::assert_clean_failure(&out, needles);
    }
}

#[test]
fn a_soak_of_several_scenes_reports_each_with_the_effects_its_assets_allow() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("soak.json");
    let out = crate::cli::vitreous(
        &[
            "soak",
            "config/scenes/glass-sphere.toml",
            "config/scenes/torus.toml",
            "--passes",
            "4",
            "--frames",
            "1",
            "--size",
            "32x24",
            "--all-effects",
            "--max-growth",
            "100",
            "--json",
            json.to_str().unwrap(),
        ],
        &workspace(),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // One summary line per scene; the torus has no caustics to render (no bake, not live).
    assert_eq!(stdout.lines().count(), 2, "{stdout}");
    let reports: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let reports = reports.as_array().expect("an array for several scenes");
    let got: Vec<(&str, &str, usize, u64)> = reports
        .iter()
        .map(|r| {
            (
                r["scene"].as_str().unwrap(),
                r["effects"].as_str().unwrap(),
                r["passes"].as_array().unwrap().len(),
                r["validation_messages"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        got,
        [
            ("config/scenes/glass-sphere.toml", "all", 4, 0),
            (
                "config/scenes/torus.toml",
                "disparity,defocus,inducer",
                4,
                0
            ),
        ]
    );
}
