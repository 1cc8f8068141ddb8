//! A director driven frame by frame through interruptions: a trial interrupted during its
//! stimuli is shown again from its start and its answer asked once.

use std::path::Path;

use vitreous_trace::session_event::{Loss, SessionEvent, TrackingLoss};

use super::super::answers::SimulatedObserver;
use super::super::protocol::Protocol;
use super::*;

/// A director over the visual-effects protocol's first two trials of p01 at 1/100 of its
/// durations (first 0.2 s, blank 0.1 s, second 0.2 s, interval 0.3 s), a simulated participant
/// answering; its responses and timing log in `dir`.
fn director(dir: &Path) -> StudyDirector {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/studies/visual-effects.toml");
    let protocol = Protocol::read(&path).unwrap();
    let trial = |n: u64, first: &str, second: &str| PlannedTrial {
        participant: "p01".into(),
        trial: n,
        stimulus: "sphere".into(),
        first: first.into(),
        second: second.into(),
    };
    let names: Vec<String> = protocol.conditions.iter().map(|c| c.name.clone()).collect();
    let (responses, answered) = ResponsesFile::open(&dir.join("r.csv"), "p01").unwrap();
    assert!(answered.is_empty());
    StudyDirector::new(
        &protocol,
        0.01,
        vec![trial(1, "O2", "O5"), trial(2, "O4", "O3")],
        None,
        AnswerSources {
            keyboard: None,
            simulated: Some(
                SimulatedObserver::parse("O1=1.9,O2=0,O3=0.4,O4=0.9,O5=1.6", &names, 1).unwrap(),
            ),
            controller: false,
        },
        responses,
        TimingLog::open(&dir.join("r-timing.csv")).unwrap(),
    )
}

/// The timing log's (trial, event, detail) rows.
fn log(dir: &Path) -> Vec<(String, String, String)> {
    std::fs::read_to_string(dir.join("r-timing.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[1].to_owned(), f[3].to_owned(), f[4].to_owned())
        })
        .collect()
}

/// Runs frames at 20 Hz from `t0_s` until the director is done, calling `during` before each
/// frame; the frame count.
fn run(
    d: &mut StudyDirector,
    t0_s: f64,
    mut during: impl FnMut(&mut StudyDirector, f64) -> f64,
) -> u64 {
    let mut t = t0_s;
    let mut n = 0;
    while !d.done() && n < 10_000 {
        t = during(d, t);
        d.frame(n, t).unwrap();
        t += 0.05;
        n += 1;
    }
    n
}

#[test]
fn a_trial_interrupted_during_its_stimuli_is_shown_again_and_answered_once() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = director(dir.path());
    let mut menu = false;
    let mut off = false;
    run(&mut d, 10.0, |d, t| {
        // A menu during trial 1's first stimulus, the headset off for 3 s during trial 2's
        // second.
        if !menu && t > 10.1 {
            menu = true;
            d.session_events(&[SessionEvent::Unfocused]);
        }
        let on_trial_2 = d.current.as_ref().is_some_and(|c| c.trial.trial == 2);
        if !off && on_trial_2 && d.current.as_ref().unwrap().phase == Some(Phase::Second) {
            off = true;
            d.session_events(&[SessionEvent::Ended]);
            return t + 3.0;
        }
        t
    });
    assert!(menu && off);
    let rows = log(dir.path());
    let interrupted: Vec<_> = rows.iter().filter(|(_, e, _)| e == "interrupted").collect();
    assert_eq!(
        interrupted,
        [
            &("1".into(), "interrupted".into(), "unfocused".into()),
            &("2".into(), "interrupted".into(), "session-ended".into())
        ]
    );
    // Each trial shown again from its first stimulus, and answered once, in order.
    for trial in ["1", "2"] {
        let firsts = rows
            .iter()
            .filter(|(t, e, _)| t == trial && e == "first")
            .count();
        assert_eq!(firsts, 2, "trial {trial}: {rows:?}");
    }
    let answers = std::fs::read_to_string(dir.path().join("r.csv")).unwrap();
    let trials: Vec<&str> = answers
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(trials, ["1", "2"]);
}

#[test]
fn a_gap_in_the_frames_interrupts_and_a_glitch_or_a_rest_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = director(dir.path());
    let mut k = 0;
    run(&mut d, 0.0, |d, t| {
        k += 1;
        let phase = d.current.as_ref().and_then(|c| c.phase);
        match (k, phase) {
            // Two frames late (150 ms between frames) in the first stimulus: a glitch.
            (2, _) => t + 0.1,
            // Lost position tracking and a menu-free late frame change nothing either.
            (3, _) => {
                d.session_events(&[SessionEvent::TrackingLost(TrackingLoss::Position)]);
                t
            }
            // A lost session after the answer (in the rest): nothing to show again.
            (_, Some(Phase::Rest)) if k < 40 => {
                d.session_events(&[SessionEvent::Lost(Loss::Session)]);
                t + 1.0
            }
            _ => t,
        }
    });
    assert!(
        !log(dir.path()).iter().any(|(_, e, _)| e == "interrupted"),
        "{:?}",
        log(dir.path())
    );
    // A 0.5 s gap in a stimulus does.
    let dir = tempfile::tempdir().unwrap();
    let mut d = director(dir.path());
    let mut k = 0;
    run(&mut d, 0.0, |_, t| {
        k += 1;
        if k == 3 { t + 0.5 } else { t }
    });
    let rows = log(dir.path());
    assert!(
        rows.iter()
            .any(|(t, e, why)| t == "1" && e == "interrupted" && why.starts_with("gap 0.5")),
        "{rows:?}"
    );
}

#[test]
fn a_display_that_keeps_stalling_shows_a_trial_again_three_times_then_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = director(dir.path());
    // Every frame 0.45 s after the one before (0.05 s added to the loop's own step).
    let frames = run(&mut d, 0.0, |_, t| t + 0.4);
    assert!(d.done(), "the study ends ({frames} frames)");
    let rows = log(dir.path());
    for trial in ["1", "2"] {
        let again = rows
            .iter()
            .filter(|(t, e, _)| t == trial && e == "interrupted")
            .count();
        assert_eq!(again, MAX_GAP_RESTARTS as usize, "trial {trial}: {rows:?}");
    }
}
