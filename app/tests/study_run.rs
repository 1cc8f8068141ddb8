//! `vitreous study plan` and `vitreous study run --dry-run`: plans reproducible and balanced,
//! answers recorded as they come on the protocol's clock (Vulkan validation on), resumed after
//! an interruption or a crash, and refused when they do not match the plan.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn protocol(name: &str) -> PathBuf {
    workspace().join("config/studies").join(name)
}

fn vitreous(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("vitreous runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

fn plan(protocol_file: &str, participants: usize, seed: u64, out: &Path) {
    ok(&vitreous(
        &[
            "study",
            "plan",
            protocol(protocol_file).to_str().unwrap(),
            "--participants",
            &participants.to_string(),
            "--seed",
            &seed.to_string(),
            "-o",
            out.to_str().unwrap(),
        ],
        "",
    ));
}

/// (participant, trial, stimulus, first, second) rows of a CSV with those columns.
fn rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

#[test]
fn study_plan_is_reproducible_and_balanced_across_participants() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a.csv"),
        dir.path().join("b.csv"),
        dir.path().join("c.csv"),
    );
    plan("visual-effects.toml", 20, 7, &a);
    plan("visual-effects.toml", 20, 7, &b);
    plan("visual-effects.toml", 20, 8, &c);
    let text = std::fs::read(&a).unwrap();
    assert_eq!(text, std::fs::read(&b).unwrap(), "same seed, same plan");
    assert_ne!(
        text,
        std::fs::read(&c).unwrap(),
        "another seed, another plan"
    );
    let trials = rows(&a);
    assert_eq!(trials.len(), 20 * 20);
    // Every participant rates every ordered pair once; over the 20 participants every pair
    // sits at every position once (a Williams design of 20 rows).
    let mut positions: BTreeMap<(String, String), BTreeSet<usize>> = BTreeMap::new();
    for participant in trials.chunks(20) {
        let pairs: BTreeSet<_> = participant.iter().map(|r| (&r[3], &r[4])).collect();
        assert_eq!(pairs.len(), 20, "{participant:?}");
        for (position, r) in participant.iter().enumerate() {
            assert_eq!(r[1], (position + 1).to_string());
            assert!(
                positions
                    .entry((r[3].clone(), r[4].clone()))
                    .or_default()
                    .insert(position)
            );
        }
    }
    assert!(positions.values().all(|p| p.len() == 20));
    // The forced-choice protocol: four scenes (two objects on two floors) in a balanced order,
    // six trials in each block.
    plan("shadows-caustics.toml", 4, 3, &a);
    let trials = rows(&a);
    assert_eq!(trials.len(), 4 * 24);
    let firsts: BTreeSet<&str> = trials.chunks(24).map(|p| p[0][2].as_str()).collect();
    assert_eq!(
        firsts.len(),
        4,
        "each scene comes first for one of four participants"
    );
    for block in trials.chunks(6) {
        let stimuli: BTreeSet<_> = block.iter().map(|r| &r[2]).collect();
        let pairs: BTreeSet<_> = block.iter().map(|r| (&r[3], &r[4])).collect();
        assert_eq!((stimuli.len(), pairs.len()), (1, 6), "{block:?}");
    }
}

#[test]
fn study_plan_refuses_bad_protocols_and_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan.csv");
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(protocol("visual-effects.toml"))
        .unwrap()
        .replace("first_s = 20.0", "first_s = \"twenty\"")
        .replace(
            "../scenes/",
            &format!("{}/", workspace().join("config/scenes").display()),
        );
    std::fs::write(&bad, &text).unwrap();
    let line = text.lines().position(|l| l.contains("twenty")).unwrap() + 1;
    let e = vitreous(
        &[
            "study",
            "plan",
            bad.to_str().unwrap(),
            "--participants",
            "3",
            "--seed",
            "1",
            "-o",
        ]
        .into_iter()
        .chain([out.to_str().unwrap()])
        .collect::<Vec<_>>(),
        "",
    );
    let stderr = String::from_utf8_lossy(&e.stderr);
    assert!(!e.status.success());
    assert!(stderr.contains(&format!("bad.toml:{line}")), "{stderr}");
    assert!(!out.exists(), "no plan written");
    let e = vitreous(
        &[
            "study",
            "plan",
            protocol("visual-effects.toml").to_str().unwrap(),
            "--participants",
            "0",
            "--seed",
            "1",
            "-o",
            out.to_str().unwrap(),
        ],
        "",
    );
    assert!(!e.status.success());
    assert!(String::from_utf8_lossy(&e.stderr).contains("--participants"));
}

/// `study run --dry-run` of the visual-effects protocol at 1/200 of its durations.
fn dry_run(plan: &Path, responses: &Path, extra: &[&str], stdin: &str) -> Output {
    let protocol_path = protocol("visual-effects.toml");
    let mut args = vec![
        "study",
        "run",
        protocol_path.to_str().unwrap(),
        "--plan",
        plan.to_str().unwrap(),
        "--participant",
        "p01",
        "--responses",
        responses.to_str().unwrap(),
        "--dry-run",
        "--validate",
        "--size",
        "64x48",
        "--rate",
        "80",
        "--time-scale",
        "0.005",
    ]
    .into_iter()
    .map(|s| s.to_string())
    .collect::<Vec<_>>();
    args.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    vitreous(&refs, stdin)
}

const SCALE: &str = "O1=1.9,O2=0,O3=0.36,O4=0.9,O5=1.6";

#[test]
fn study_run_records_each_answer_on_the_protocol_clock_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let (plan_path, responses) = (dir.path().join("plan.csv"), dir.path().join("r.csv"));
    plan("visual-effects.toml", 2, 11, &plan_path);
    let planned: Vec<Vec<String>> = rows(&plan_path)
        .into_iter()
        .filter(|r| r[0] == "p01")
        .collect();
    ok(&dry_run(
        &plan_path,
        &responses,
        &["--simulate", SCALE, "--trials", "3"],
        "",
    ));
    let answered = rows(&responses);
    assert_eq!(answered.len(), 3, "{answered:?}");
    for (a, p) in answered.iter().zip(&planned) {
        assert_eq!((&a[1], &a[2], &a[3], &a[5]), (&p[1], &p[3], &p[4], &p[2]));
        let rating: i8 = a[4].parse().unwrap();
        assert!((-3..=3).contains(&rating));
    }
    // The timing log: each phase of trial 1 on the scaled clock (20 s x 0.005 = 0.1 s, within
    // a frame at 80 Hz), the gaze cue switching within each stimulus.
    let log = std::fs::read_to_string(dir.path().join("r-timing.csv")).unwrap();
    let time_of = |trial: &str, event: &str| -> f64 {
        log.lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|f| f[1] == trial && f[3] == event)
            .unwrap_or_else(|| panic!("no {event} of trial {trial} in\n{log}"))[7]
            .parse()
            .unwrap()
    };
    for (event, at_s) in [
        ("first", 0.0),
        ("blank", 0.1),
        ("second", 0.15),
        ("answer", 0.25),
    ] {
        let t = time_of("1", event);
        assert!(
            (t - at_s).abs() <= 0.013,
            "{event} at {t} s, expected {at_s} s\n{log}"
        );
    }
    let cues: Vec<&str> = log
        .lines()
        .filter(|l| l.starts_with("p01,1,") && l.contains(",cue,"))
        .map(|l| l.split(',').nth(4).unwrap())
        .collect();
    assert_eq!(
        cues,
        ["surface", "refracted", "surface", "refracted"].repeat(2),
        "{log}"
    );

    // Resumed: the other 17 trials, each once, in plan order.
    let stderr = ok(&dry_run(&plan_path, &responses, &["--simulate", SCALE], ""));
    assert!(stderr.contains("resuming at trial 4"), "{stderr}");
    let answered = rows(&responses);
    let trials: Vec<&str> = answered.iter().map(|r| r[1].as_str()).collect();
    let expected: Vec<String> = (1..=20).map(|t| t.to_string()).collect();
    assert_eq!(trials, expected);
    // Complete for p01: the analysis runs, and its plot is written.
    let png = dir.path().join("scale.png");
    let out = vitreous(
        &[
            "study",
            "analyze",
            responses.to_str().unwrap(),
            "--json",
            "--plot",
            png.to_str().unwrap(),
        ],
        "",
    );
    ok(&out);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["method"], "scheffe-nakaya");
    assert_eq!(json["stimulus"], "sphere");
    assert!(image::open(&png).is_ok());
    // Nothing left: a third run says so and changes nothing.
    let before = std::fs::read(&responses).unwrap();
    ok(&dry_run(&plan_path, &responses, &["--simulate", SCALE], ""));
    assert_eq!(before, std::fs::read(&responses).unwrap());
}

#[test]
fn study_run_takes_typed_answers_and_repairs_a_cut_off_last_line() {
    let dir = tempfile::tempdir().unwrap();
    let (plan_path, responses) = (dir.path().join("plan.csv"), dir.path().join("r.csv"));
    plan("visual-effects.toml", 1, 5, &plan_path);
    // Two bad lines are refused (and named), then -1 and +2 answer trials 1 and 2.
    let stderr = ok(&dry_run(
        &plan_path,
        &responses,
        &["--trials", "2"],
        "first\n4\n-1\n+2\n",
    ));
    assert!(stderr.contains("`first` is not a rating"), "{stderr}");
    assert!(stderr.contains("`4` is not a rating"), "{stderr}");
    let answered = rows(&responses);
    assert_eq!(
        answered.iter().map(|r| r[4].as_str()).collect::<Vec<_>>(),
        ["-1", "2"]
    );
    // A crash while writing trial 3's answer: the cut-off line goes, trial 3 is asked again.
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(&responses)
        .unwrap();
    f.write_all(b"p01,3,O").unwrap();
    drop(f);
    let stderr = ok(&dry_run(&plan_path, &responses, &["--trials", "1"], "3\n"));
    assert!(stderr.contains("cut off"), "{stderr}");
    let answered = rows(&responses);
    assert_eq!(answered.len(), 3);
    assert_eq!(
        (answered[2][1].as_str(), answered[2][4].as_str()),
        ("3", "3")
    );
    // Typing ends (standard input closed) with answers still due: a clear error, not a wait
    // until the trace runs out; the answer given is kept.
    let out = dry_run(&plan_path, &responses, &[], "0\n");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("trial 5: an answer is due but nothing can give it"),
        "{stderr}"
    );
    assert_eq!(rows(&responses).len(), 4);
}

#[test]
fn study_run_refuses_responses_that_do_not_match_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let (plan_path, responses) = (dir.path().join("plan.csv"), dir.path().join("r.csv"));
    plan("visual-effects.toml", 1, 5, &plan_path);
    let first = &rows(&plan_path)[0];
    // Trial 1 with its conditions swapped: another plan's answer.
    std::fs::write(
        &responses,
        format!(
            "participant,trial,first,second,response,stimulus\np01,1,{},{},2,sphere\n",
            first[4], first[3]
        ),
    )
    .unwrap();
    let out = dry_run(&plan_path, &responses, &["--simulate", SCALE], "");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("r.csv:2") && stderr.contains("wrong plan"),
        "{stderr}"
    );
    // An unknown participant.
    let out = vitreous(
        &[
            "study",
            "run",
            protocol("visual-effects.toml").to_str().unwrap(),
            "--plan",
            plan_path.to_str().unwrap(),
            "--participant",
            "p99",
            "--responses",
            dir.path().join("other.csv").to_str().unwrap(),
            "--dry-run",
        ],
        "",
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no trials for participant `p99`"));
}

/// `study run --view`: the trials in the desktop window (a virtual X server, validation on),
/// answered by a simulated participant; each answer recorded in plan order. Skipped outside CI
/// when xvfb-run is missing (in CI a missing one fails).
#[test]
fn study_run_shows_the_trials_in_the_desktop_viewer() {
    let xvfb = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join("xvfb-run"))
            .find(|p| p.is_file())
    });
    let Some(xvfb) = xvfb else {
        assert!(
            std::env::var_os("CI").is_none(),
            "xvfb-run is missing: tools/ensure-vulkan --window installs it"
        );
        eprintln!("skipped: no xvfb-run here");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (plan_path, responses) = (dir.path().join("plan.csv"), dir.path().join("r.csv"));
    plan("visual-effects.toml", 1, 9, &plan_path);
    let out = Command::new(xvfb)
        .args(["-a", "-n", "300", "-s", "-screen 0 640x480x24"])
        .arg(env!("CARGO_BIN_EXE_vitreous"))
        .args(["study", "run"])
        .arg(protocol("visual-effects.toml"))
        .arg("--plan")
        .arg(&plan_path)
        .args(["--participant", "p01", "--responses"])
        .arg(&responses)
        .args([
            "--view",
            "--window",
            "320x240",
            "--validate",
            // The shortest phase (the 10 s blank) lasts 250 ms: longer than a frame of the
            // window on a loaded machine, so that every phase is shown and logged.
            "--time-scale",
            "0.025",
        ])
        .args(["--trials", "2", "--simulate", SCALE])
        .stdin(Stdio::null())
        .output()
        .expect("running xvfb-run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let planned = rows(&plan_path);
    let answered = rows(&responses);
    assert_eq!(answered.len(), 2, "{stderr}");
    for (a, p) in answered.iter().zip(&planned) {
        assert_eq!((&a[1], &a[2], &a[3]), (&p[1], &p[3], &p[4]));
    }
    let log = std::fs::read_to_string(dir.path().join("r-timing.csv")).unwrap();
    for event in ["first", "blank", "second", "answer", "answered"] {
        assert!(
            log.lines()
                .any(|l| l.starts_with("p01,2,") && l.contains(&format!(",{event},"))),
            "no {event} in\n{log}"
        );
    }
}
