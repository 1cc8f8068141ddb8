//! Protocol files: a good one read with its pairs, bad fields named with their line.

use super::*;

const GOOD: &str = r#"
[study]
name = "t"
question = "Which looked real?"
response = "rating"
orders = "both"
gaze = "cued"
cue_period_s = 5.0

[timing]
first_s = 20.0
blank_s = 10.0
second_s = 20.0
interval_s = 30.0

[[condition]]
name = "O1"
effects = "nothing"

[[condition]]
name = "O2"
effects = "O2"

[[condition]]
name = "O5"
effects = "O5"

[[stimulus]]
name = "sphere"
scene = "scene.toml"
"#;

fn parse(text: &str) -> Result<Protocol, ProtocolError> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), "").unwrap();
    Protocol::parse(&dir.path().join("p.toml"), text)
}

#[test]
fn a_good_protocol_reads_with_its_pairs() {
    let p = parse(GOOD).unwrap();
    assert_eq!(p.conditions.len(), 3);
    assert_eq!(p.conditions[0].show, Show::Nothing);
    assert_eq!(p.gaze, GazeCue::Cued { period_s: 5.0 });
    assert_eq!(p.pairs().len(), 6);
    assert_eq!(p.trials_per_participant(), 6);
}

#[test]
fn bad_fields_are_named_with_their_line() {
    let cases = [
        (
            "effects = \"O5\"",
            "effects = \"sparkle\"",
            "condition[2].effects",
        ),
        ("first_s = 20.0", "first_s = -1.0", "timing.first_s"),
        ("first_s = 20.0", "first_s = nan", "timing.first_s"),
        (
            "response = \"rating\"",
            "response = \"stars\"",
            "study.response",
        ),
        ("name = \"O2\"", "name = \"O1\"", "condition[1].name"),
        (
            "scene = \"scene.toml\"",
            "scene = \"missing.toml\"",
            "stimulus[0].scene",
        ),
        ("gaze = \"cued\"", "gaze = \"psychic\"", "study.gaze"),
    ];
    for (from, to, field) in cases {
        let text = GOOD.replace(from, to);
        let line = text
            .lines()
            .collect::<Vec<_>>()
            .iter()
            .rposition(|l| l.contains(to))
            .unwrap()
            + 1;
        let e = parse(&text).unwrap_err().to_string();
        assert!(e.contains(field), "{to}: {e}");
        assert!(e.contains(&format!("p.toml:{line}:")), "{to}: {e}");
    }
}

#[test]
fn unknown_keys_and_too_few_conditions_are_refused() {
    let e = parse(&GOOD.replace("orders = \"both\"", "orders = \"both\"\ncolour = 1"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("colour"), "{e}");
    let one = GOOD.split("[[condition]]").next().unwrap().to_owned()
        + "[[condition]]\nname = \"a\"\neffects = \"a\"\n[[stimulus]]\nname = \"s\"\nscene = \"scene.toml\"\n";
    let e = parse(&one).unwrap_err().to_string();
    assert!(e.contains("1 [[condition]]"), "{e}");
}
