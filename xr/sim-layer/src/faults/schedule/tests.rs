//! The schedule's parsing, its error messages and the chaos schedule.

use super::*;

#[test]
fn every_fault_parses_and_prints_back() {
    let text = "\
        frame 40  headset-off 3   # off
        frame 120 menu 30
        at 9.5 session-loss 2
        frame 400 instance-loss 2.5
        frame 470 recentre
        frame 500 no-render 20
        frame 540 late 4
        frame 560 image-timeout 2
        frame 580 runtime-failure xrLocateViews
        frame 600 tracking-lost 20 10
        frame 650 unusable-pose 5
        frame 660 zero-fov 2
        frame 700 gaze-dropout 2 invalid
        frame 705 bad-time 3 negative
        frame 708 gaze-clock 1.5 20
        frame 709 gaze-clock 0.5 -300
        frame 710 eyes 58.5 2
        frame 720 eyes 70
    ";
    let parsed = parse(text).unwrap();
    assert_eq!(parsed.len(), 18);
    // Frame triggers first, in frame order; the time trigger after them.
    assert_eq!(parsed[0].to_string(), "frame 40 headset-off 3");
    assert_eq!(parsed[9].to_string(), "frame 650 unusable-pose 5");
    assert_eq!(parsed[10].fault, Fault::ZeroFov(2));
    assert_eq!(parsed[11].to_string(), "frame 700 gaze-dropout 2 invalid");
    assert_eq!(parsed[12].to_string(), "frame 705 bad-time 3 negative");
    assert_eq!(parsed[13].fault, Fault::GazeClock(1.5, 20));
    assert_eq!(parsed[13].to_string(), "frame 708 gaze-clock 1.5 20");
    assert_eq!(parsed[14].fault, Fault::GazeClock(0.5, -300));
    assert_eq!(parsed[15].fault, Fault::Eyes(58.5, 2.0));
    assert_eq!(parsed[16].to_string(), "frame 720 eyes 70 0");
    assert_eq!(parsed[17].to_string(), "at 9.5 session-loss 2");
    for s in &parsed {
        assert_eq!(parse(&s.to_string()).unwrap(), vec![s.clone()]);
    }
}

#[test]
fn bad_lines_are_named_with_what_was_expected() {
    for (text, says) in [
        ("frame x menu 3", "line 1: frame: `x` is not a whole number"),
        (
            "\nframe 3 menu 0",
            "line 2: menu: `0` is not a whole number from 1",
        ),
        (
            "frame 3 headset-off -1",
            "headset-off: `-1` is not a number of seconds",
        ),
        ("frame 3 headset-off nan", "headset-off: `nan`"),
        (
            "frame 3 runtime-failure xrFoo",
            "`xrFoo` is not one of xrLocateViews",
        ),
        (
            "frame 3 gaze-dropout 1 blink",
            "`blink` is not none, invalid or low",
        ),
        ("frame 3 tracking-lost 0 0", "no frame lost"),
        (
            "frame 3 gaze-clock 1 0",
            "gaze-clock: `0` is not a whole number of milliseconds ahead, -1000 to 1000",
        ),
        ("frame 3 gaze-clock 1 1001", "gaze-clock: `1001` is not"),
        ("frame 3 gaze-clock 1 2.5", "gaze-clock: `2.5` is not"),
        ("frame 3 gaze-clock 1", "`gaze-clock`: not a fault"),
        (
            "frame 3 eyes 30",
            "eyes: `30` is not a distance of 40 to 90",
        ),
        (
            "frame 3 bad-time 2 late",
            "`late` is not negative, repeat or ahead",
        ),
        (
            "frame 3 bad-time 0 repeat",
            "bad-time: `0` is not a whole number from 1",
        ),
        ("frame 3 eyes 60 12", "eyes: `60 12` is not"),
        ("frame 3 eyes 60 nan", "eyes: `60 nan` is not"),
        ("frame 3 eyes", "`eyes`: not a fault"),
        ("frame 3 eyes 60 1 2", "`eyes`: not a fault"),
        ("frame 3 explode", "`explode`: not a fault"),
        ("soon 3 menu 2", "`soon`: expected `frame N`"),
        ("frame 3", "a trigger with no fault after it"),
        ("menu", "expected `frame N FAULT"),
        ("chaos 1 0", "chaos: frames: `0`"),
    ] {
        let e = parse(text).unwrap_err().to_string();
        assert!(e.contains(says), "{text:?}: {e}");
    }
}

#[test]
fn chaos_is_reproducible_and_has_every_family_spaced_out() {
    let a = chaos(7, 2000);
    assert_eq!(a, chaos(7, 2000));
    assert_ne!(a, chaos(8, 2000));
    for family in [
        "headset-off",
        "menu",
        "session-loss",
        "instance-loss",
        "recentre",
        "no-render",
        "late",
        "image-timeout",
        "runtime-failure",
        "tracking-lost",
        "unusable-pose",
        "zero-fov",
        "gaze-dropout",
        "gaze-clock",
        "bad-time",
        "eyes",
    ] {
        assert!(
            a.iter().any(|s| s.fault.name() == family),
            "{family} missing from {a:?}"
        );
    }
    let frames: Vec<u64> = a
        .iter()
        .map(|s| match s.trigger {
            Trigger::Frame(n) => n,
            Trigger::At(_) => panic!("chaos uses frame triggers"),
        })
        .collect();
    assert!(frames.windows(2).all(|w| w[1] >= w[0] + 50), "{frames:?}");
    assert!(*frames.last().unwrap() < 2000);
    // The Monado cases' schedules (seeds 1, 2, 3 over 2000 frames) hold every family too.
    for seed in 1..=3 {
        let names: std::collections::HashSet<&str> =
            chaos(seed, 2000).iter().map(|s| s.fault.name()).collect();
        assert_eq!(names.len(), 16, "seed {seed}: {names:?}");
    }
    // Expanded in place: the chaos line stands for its faults.
    let parsed = parse("chaos 7 2000").unwrap();
    assert_eq!(parsed, a);
}
