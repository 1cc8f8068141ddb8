//! Options that take a number: a negative value reaches the option's own check, which names
//! the option and what it takes.

use crate::cli::{assert_clean_failure, scene, vitreous, workspace};

/// Every option that takes a number lets `-1` through to its own check, which names the
/// option and says what it expects, instead of taking `-1` for an unknown option.
#[test]
fn a_negative_number_for_any_numeric_option_names_the_option_and_what_it_expects() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene("glass-sphere.toml");
    let protocol = workspace().join("config/studies/visual-effects.toml");
    let p = protocol.to_str().unwrap();
    let plan = dir.path().join("plan.csv");
    let made = vitreous(
        &[
            "study",
            "plan",
            p,
            "--participants",
            "1",
            "--seed",
            "1",
            "-o",
            plan.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(made.status.success(), "{made:?}");
    let plan = plan.to_str().unwrap();
    let run = [
        "study",
        "run",
        p,
        "--plan",
        plan,
        "--participant",
        "p01",
        "--dry-run",
    ];
    let compare = ["compare", "a.png", "b.png", "--seen", "a.png", "--display"];
    let cases: Vec<(Vec<&str>, &str, &str)> = [
        (
            vec!["run", &s],
            &["--size", "--frames", "--reconnect-s"][..],
        ),
        (
            vec!["view", &s],
            &["--window", "--render-scale", "--frames"],
        ),
        (
            vec!["replay", &s],
            &["--frames", "--save-every", "--size", "--rate", "--pupil-mm"],
        ),
        (vec!["bench", &s], &["--size", "--frames", "--pupil-mm"]),
        (vec!["soak", &s], &["--minutes", "--size", "--frames"]),
        (compare.to_vec(), &["--ppd", "--panel-blur-deg"]),
        (
            vec!["reference", &s, "--trace", "t.csv"],
            &[
                "--frames",
                "--save-every",
                "--rate",
                "--size",
                "--samples",
                "--texel-mm",
                "--photons-per-texel",
            ],
        ),
        (
            vec!["trace", "synth", "--scene", &s, "-o", "t.csv"],
            &["--duration", "--rate", "--seed"],
        ),
        (
            vec!["study", "plan", p, "-o", "p.csv", "--seed", "1"],
            &["--participants"],
        ),
        (
            vec!["study", "plan", p, "-o", "p.csv", "--participants", "1"],
            &["--seed"],
        ),
        (
            run.to_vec(),
            &[
                "--rate",
                "--time-scale",
                "--trials",
                "--seed",
                "--size",
                "--window",
            ],
        ),
    ]
    .into_iter()
    .flat_map(|(args, options)| {
        options.iter().map(move |&option| {
            let value = if ["--size", "--window"].contains(&option) {
                "-1x5"
            } else {
                "-1"
            };
            (args.clone(), option, value)
        })
    })
    .chain([(
        vec!["trace", "import", "--from", "neon", "rec", "-o", "t.csv"],
        "--kappa-deg",
        "-20",
    )])
    .collect();
    for (mut args, option, value) in cases {
        args.extend([option, value]);
        let out = vitreous(&args, dir.path());
        let message = assert_clean_failure(&out, &[option, value]);
        assert!(!message.contains("unexpected argument"), "{message}");
        assert!(
            ["expected", "must be", "is outside"]
                .iter()
                .any(|w| message.contains(w)),
            "{args:?}: {message}"
        );
    }
    assert!(!dir.path().join("out").exists());
    assert!(!dir.path().join("t.csv").exists());
}
