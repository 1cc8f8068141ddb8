//! `vitreous study analyze`: the JSON of a small forced-choice file and a small rating file
//! against hand-computed values, and the error of a bad file.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

const HEADER: &str = "participant,trial,first,second,response\n";

fn analyze(file: &Path, json: bool) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_vitreous"));
    command.args(["study", "analyze"]).arg(file);
    if json {
        command.arg("--json");
    }
    command.output().expect("vitreous runs")
}

fn write(dir: &Path, name: &str, body: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, format!("{HEADER}{body}")).expect("write responses");
    path
}

fn json_of(output: &Output) -> Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("valid JSON")
}

#[test]
fn study_analyze_forced_choice_gives_case_v_scale_and_mosteller_test() {
    let dir = tempfile::tempdir().unwrap();
    // 10 judgments per pair, shown in both orders: a over b 7 times, a over c 9, b over c 6.
    let mut body = String::new();
    let mut trial = 0;
    for (x, y, wins) in [("a", "b", 7), ("a", "c", 9), ("b", "c", 6)] {
        for k in 0..10 {
            trial += 1;
            let chosen_x = k < wins;
            // Alternate the presentation order; the answer names the chosen position.
            let (first, second, answer) = if k % 2 == 0 {
                (x, y, if chosen_x { "first" } else { "second" })
            } else {
                (y, x, if chosen_x { "second" } else { "first" })
            };
            body.push_str(&format!("p{},{trial},{first},{second},{answer}\n", k % 5));
        }
    }
    let file = write(dir.path(), "choices.csv", &body);
    let report = json_of(&analyze(&file, true));
    assert_eq!(report["method"], "thurstone-case-v");
    for (name, value) in [("a", 1.113_617), ("b", 0.421_282), ("c", 0.0)] {
        let got = report["scale"][name].as_f64().unwrap();
        assert!((got - value).abs() < 1e-5, "{name}: {got}");
    }
    assert_eq!(report["chi_square"]["df"], 1);
    let p = report["chi_square"]["p"].as_f64().unwrap();
    assert!(p > 0.0 && p <= 1.0);
    let text = analyze(&file, false);
    assert!(text.status.success());
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(
        text.contains("Case V") && text.contains("Mosteller"),
        "{text}"
    );
}

#[test]
fn study_analyze_ratings_give_scheffe_scale_anova_and_yardsticks() {
    let dir = tempfile::tempdir().unwrap();
    let body = "p1,1,none,defocus,2\np1,2,defocus,none,-1\n\
                p2,1,defocus,none,0\np2,2,none,defocus,1\n\
                p3,1,none,defocus,0\np3,2,defocus,none,0\n";
    let file = write(dir.path(), "ratings.csv", body);
    let report = json_of(&analyze(&file, true));
    assert_eq!(report["method"], "scheffe-nakaya");
    assert!((report["scale"]["none"].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-12);
    assert!((report["scale"]["defocus"].as_f64().unwrap() + 1.0 / 3.0).abs() < 1e-12);
    // MS_e = 1/6 on 2 df: Y(0.05) = q(0.05; 2, 2) · sqrt((1/6) / 12) = 6.0849 · 0.11785.
    let y05 = report["yardstick"]["0.05"].as_f64().unwrap();
    assert!((y05 - 0.717_113).abs() < 1e-3, "{y05}");
    assert!(report["yardstick"]["0.01"].as_f64().unwrap() > y05);
    let anova = report["anova"].as_array().unwrap();
    let sources: Vec<&str> = anova
        .iter()
        .map(|row| row["source"].as_str().unwrap())
        .collect();
    assert_eq!(
        sources,
        [
            "main effect",
            "main effect x participant",
            "combination effect",
            "order effect",
            "error",
            "total"
        ]
    );
    assert!((anova[0]["f"].as_f64().unwrap() - 16.0).abs() < 1e-9);
    assert_eq!(report["pairs"][0]["significant"]["0.05"], false);
}

#[test]
fn study_analyze_bad_file_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "bad.csv", "p1,1,a,b,2\np1,2,b,a,5\n");
    let output = analyze(&file, true);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("bad.csv: line 3: rating 5 is outside -3..3"),
        "{stderr}"
    );
}

#[test]
fn study_analyze_refuses_a_file_with_a_header_and_no_answers() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "empty.csv", "");
    let output = analyze(&file, true);
    assert!(!output.status.success());
    assert!(output.stdout.is_empty(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("empty.csv: no responses (the file has no lines after the header)"),
        "{stderr}"
    );
}
