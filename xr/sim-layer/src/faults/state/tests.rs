//! The fault state machine driven the way an app drives a session.

use std::time::{Duration, Instant};

use openxr::sys::{self, SessionState as S};

use super::super::schedule::parse;
use super::*;

const SESSION: u64 = 11;
const INSTANCE: u64 = 7;
const PERIOD_NS: i64 = 50_000_000;

/// A session that is FOCUSED, as the runtime walked it.
fn focused(schedule: &str) -> Faults {
    let mut f = Faults::new(parse(schedule).unwrap());
    f.session_created(SESSION, INSTANCE);
    f.space_created(SESSION, sys::ReferenceSpaceType::STAGE);
    f.space_created(SESSION, sys::ReferenceSpaceType::VIEW);
    assert_eq!(f.begin_session(SESSION), None, "passed on to the runtime");
    for s in [S::READY, S::SYNCHRONIZED, S::VISIBLE, S::FOCUSED] {
        f.runtime_state(SESSION, s);
    }
    f
}

/// The app's frame: wait (after its plan), then whether it may render.
fn frame(f: &mut Faults, now: Instant) -> Option<bool> {
    match f.before_wait(SESSION) {
        WaitPlan::Refuse(_) => None,
        WaitPlan::Go { late } => {
            for _ in 0..late {
                f.skipped(0);
            }
            let display = f.frames as i64 * PERIOD_NS + 1;
            Some(f.after_wait(SESSION, display, true, now))
        }
    }
}

/// Every event pending now.
fn events(f: &mut Faults, now: Instant) -> Vec<Event> {
    std::iter::from_fn(|| f.next_event(INSTANCE, now)).collect()
}

fn states(events: &[Event]) -> Vec<sys::SessionState> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::State { state, .. } => Some(*state),
            _ => None,
        })
        .collect()
}

#[test]
fn the_headset_taken_off_walks_down_to_idle_and_back_up_after_its_time_off() {
    let now = Instant::now();
    let mut f = focused("frame 2 headset-off 3");
    let mut seen = Vec::new();
    for _ in 0..2 {
        assert_eq!(frame(&mut f, now), Some(true));
        seen.extend(states(&events(&mut f, now)));
    }
    assert!(seen.is_empty());
    // Frame 2 starts it: VISIBLE, then SYNCHRONIZED (no rendering), then STOPPING.
    assert_eq!(frame(&mut f, now), Some(true));
    assert_eq!(states(&events(&mut f, now)), [S::VISIBLE]);
    assert_eq!(frame(&mut f, now), Some(true));
    assert_eq!(states(&events(&mut f, now)), [S::SYNCHRONIZED]);
    assert_eq!(
        frame(&mut f, now),
        Some(false),
        "SYNCHRONIZED: not rendered"
    );
    assert_eq!(states(&events(&mut f, now)), [S::STOPPING]);
    // Beginning again or ending early is refused as the specification says.
    assert_eq!(
        f.begin_session(SESSION),
        Some(sys::Result::ERROR_SESSION_RUNNING)
    );
    assert_eq!(f.end_session(SESSION, now), Some(sys::Result::SUCCESS));
    assert_eq!(states(&events(&mut f, now)), [S::IDLE]);
    assert_eq!(frame(&mut f, now), None, "no frames while not running");
    assert_eq!(
        f.request_exit(SESSION),
        Some(sys::Result::ERROR_SESSION_NOT_RUNNING)
    );
    assert_eq!(
        f.begin_session(SESSION),
        Some(sys::Result::ERROR_SESSION_NOT_READY)
    );
    // Still off 2.9 s later; READY at 3 s.
    assert!(events(&mut f, now + Duration::from_millis(2900)).is_empty());
    let later = now + Duration::from_secs(3);
    assert_eq!(states(&events(&mut f, later)), [S::READY]);
    assert_eq!(f.begin_session(SESSION), Some(sys::Result::SUCCESS));
    assert_eq!(frame(&mut f, later), Some(false), "READY: not rendered yet");
    assert_eq!(states(&events(&mut f, later)), [S::SYNCHRONIZED]);
    assert_eq!(frame(&mut f, later), Some(false));
    assert_eq!(states(&events(&mut f, later)), [S::VISIBLE]);
    assert_eq!(frame(&mut f, later), Some(true));
    assert_eq!(states(&events(&mut f, later)), [S::FOCUSED]);
    // The runtime's session is FOCUSED underneath: calls pass on again.
    assert_eq!(f.end_session(SESSION, later), None);
    let log: Vec<&str> = f.take_log().iter().map(|(e, _)| *e).collect();
    assert!(log.contains(&"end-session") && log.contains(&"begin-session"));
}

#[test]
fn a_menu_takes_the_focus_for_its_frames_and_refuses_input_meanwhile() {
    let now = Instant::now();
    let mut f = focused("frame 1 menu 3");
    frame(&mut f, now);
    frame(&mut f, now);
    assert_eq!(states(&events(&mut f, now)), [S::VISIBLE]);
    assert_eq!(
        f.sync_actions(SESSION),
        Some(sys::Result::SESSION_NOT_FOCUSED)
    );
    for _ in 0..3 {
        assert_eq!(
            frame(&mut f, now),
            Some(true),
            "a menu keeps the app visible"
        );
    }
    assert_eq!(states(&events(&mut f, now)), [S::FOCUSED]);
    assert_eq!(f.sync_actions(SESSION), None);
}

#[test]
fn a_lost_session_refuses_its_calls_and_the_headset_stays_away_for_the_outage() {
    let now = Instant::now();
    let mut f = focused("frame 0 session-loss 2");
    frame(&mut f, now);
    assert_eq!(states(&events(&mut f, now)), [S::LOSS_PENDING]);
    assert_eq!(
        f.refuse("xrLocateViews", SESSION),
        Some(sys::Result::ERROR_SESSION_LOST)
    );
    assert_eq!(frame(&mut f, now), None);
    assert_eq!(
        f.get_system(now + Duration::from_millis(1900)),
        Some(sys::Result::ERROR_FORM_FACTOR_UNAVAILABLE)
    );
    assert_eq!(f.create_instance(now), None, "the runtime itself is there");
    assert_eq!(f.get_system(now + Duration::from_secs(2)), None);
    f.session_destroyed(SESSION);
    assert_eq!(f.refuse("xrLocateViews", SESSION), None, "forgotten");
}

#[test]
fn an_instance_loss_is_announced_once_and_the_runtime_is_away_for_the_outage() {
    let now = Instant::now();
    let mut f = focused("frame 0 instance-loss 1");
    frame(&mut f, now);
    assert_eq!(
        events(&mut f, now),
        [Event::InstanceLoss { loss_time_ns: 1 }]
    );
    assert_eq!(
        f.refuse("xrEndFrame", SESSION),
        Some(sys::Result::ERROR_INSTANCE_LOST)
    );
    assert_eq!(
        f.create_instance(now),
        Some(sys::Result::ERROR_RUNTIME_UNAVAILABLE)
    );
    // Then starting again, not ready yet, until the outage ends.
    assert_eq!(
        f.create_instance(now + Duration::from_millis(500)),
        Some(sys::Result::ERROR_INITIALIZATION_FAILED)
    );
    assert_eq!(f.create_instance(now + Duration::from_secs(1)), None);
    // The runtime hands the destroyed instance's handle, and its session's, out again.
    f.instance_destroyed(INSTANCE);
    f.session_created(SESSION, INSTANCE);
    assert_eq!(
        f.refuse("xrEndFrame", SESSION),
        None,
        "a new instance is not lost"
    );
}

#[test]
fn frame_faults_apply_to_their_frames_only() {
    let now = Instant::now();
    let mut f = focused(
        "frame 0 no-render 2\nframe 3 late 2\nframe 4 image-timeout 1\n\
         frame 4 runtime-failure xrEndFrame\nframe 5 tracking-lost 1 2\nframe 5 recentre",
    );
    f.swapchain_created(99, SESSION);
    assert_eq!(frame(&mut f, now), Some(false));
    assert_eq!(frame(&mut f, now), Some(false));
    assert_eq!(frame(&mut f, now), Some(true));
    f.submitted(SESSION, 1);
    assert_eq!(frame(&mut f, now), Some(true));
    // Frame 3 asked for two late frames before the app's next.
    assert_eq!(f.before_wait(SESSION), WaitPlan::Go { late: 2 });
    assert!(f.after_wait(SESSION, 999, true, now));
    assert_eq!(
        f.wait_image(99, true),
        None,
        "an infinite wait cannot time out"
    );
    assert_eq!(f.wait_image(99, false), Some(sys::Result::TIMEOUT_EXPIRED));
    assert_eq!(f.wait_image(99, false), None);
    assert_eq!(
        f.refuse("xrEndFrame", SESSION),
        Some(sys::Result::ERROR_RUNTIME_FAILURE)
    );
    assert_eq!(f.refuse("xrEndFrame", SESSION), None, "once");
    frame(&mut f, now);
    assert_eq!(f.tracking(), Some(TrackingLoss::Position));
    let ev = events(&mut f, now);
    assert!(matches!(
        ev.as_slice(),
        [Event::SpaceChange {
            space: sys::ReferenceSpaceType::STAGE,
            ..
        }]
    ));
    frame(&mut f, now);
    assert_eq!(f.tracking(), Some(TrackingLoss::Orientation));
    frame(&mut f, now);
    assert_eq!(f.tracking(), Some(TrackingLoss::Orientation));
    frame(&mut f, now);
    assert_eq!(f.tracking(), None);
    let log: Vec<String> = f
        .take_log()
        .into_iter()
        .map(|(e, d)| format!("{e} {d}"))
        .collect();
    assert!(log.contains(&"infinite-wait ".to_owned()), "{log:?}");
    assert!(
        !log.iter().any(|l| l.starts_with("rendered-unasked")),
        "{log:?}"
    );
}

#[test]
fn layers_in_a_frame_told_not_to_render_are_logged() {
    let now = Instant::now();
    let mut f = focused("frame 0 no-render 1");
    assert_eq!(frame(&mut f, now), Some(false));
    f.submitted(SESSION, 1);
    assert!(f.take_log().iter().any(|(e, _)| *e == "rendered-unasked"));
}

#[test]
fn a_dropout_covers_its_display_time_span() {
    let now = Instant::now();
    let mut f = focused("frame 2 gaze-dropout 0.1 none");
    for _ in 0..3 {
        frame(&mut f, now);
    }
    let start = 2 * PERIOD_NS + 1;
    assert_eq!(f.dropout_at(start - 1), None);
    assert_eq!(f.dropout_at(start), Some((Dropout::None, start)));
    assert_eq!(
        f.dropout_at(start + 99_999_999),
        Some((Dropout::None, start))
    );
    assert_eq!(f.dropout_at(start + 100_000_000), None);
}

#[test]
fn zero_fields_of_view_last_their_frames_and_are_logged() {
    let now = Instant::now();
    let mut f = focused("frame 1 zero-fov 2");
    let seen: Vec<_> = (0..4)
        .map(|_| {
            frame(&mut f, now);
            f.tracking()
        })
        .collect();
    let zero = Some(TrackingLoss::ZeroFov);
    assert_eq!(seen, [None, zero, zero, None]);
    let logged = f.take_log();
    let zeros = logged
        .iter()
        .filter(|(e, d)| *e == "tracking" && d == "zerofov");
    assert_eq!(zeros.count(), 2);
}

#[test]
fn a_gaze_clock_runs_ahead_over_its_display_time_span() {
    let now = Instant::now();
    let mut f = focused("frame 1 gaze-clock 0.05 20");
    for _ in 0..2 {
        frame(&mut f, now);
    }
    let start = PERIOD_NS + 1;
    assert_eq!(f.gaze_lead_at(start - 1), 0);
    assert_eq!(f.gaze_lead_at(start), 20_000_000);
    assert_eq!(f.gaze_lead_at(start + 49_999_999), 20_000_000);
    assert_eq!(f.gaze_lead_at(start + 50_000_000), 0);
    // Started like every fault, the eye tracker's own timing untouched otherwise.
    assert!(
        f.take_log()
            .iter()
            .any(|(e, d)| *e == "fault" && d == "gaze-clock 0.05 20")
    );
    assert_eq!(f.dropout_at(start), None);
    // Behind: the stamps go back.
    let mut f = focused("frame 0 gaze-clock 0.05 -300");
    frame(&mut f, now);
    assert_eq!(f.gaze_lead_at(1), -300_000_000);
}

#[test]
fn new_eyes_hold_from_their_frame_and_the_newest_wins() {
    let now = Instant::now();
    let mut f = focused("frame 2 eyes 58 2\nframe 4 eyes 70");
    for want in [
        None,
        None,
        Some((0.058, 2.0)),
        Some((0.058, 2.0)),
        Some((0.070, 0.0)),
    ] {
        frame(&mut f, now);
        let got = f.eyes().map(|e| (e.ipd_m, e.toe_out_deg));
        assert_eq!(got, want, "frame {}", f.frames - 1);
    }
}

#[test]
fn a_bad_time_is_shown_to_the_app_and_the_true_one_ends_the_frame() {
    let now = Instant::now();
    let mut f =
        focused("frame 1 bad-time 2 negative\nframe 4 bad-time 1 repeat\nframe 6 bad-time 1 ahead");
    let mut shown = Vec::new();
    for k in 0..7i64 {
        frame(&mut f, now);
        let truth = k * PERIOD_NS + 1;
        let seen = f.shown_display();
        if let Some(bad) = seen {
            // The app ends the frame at the time it was shown: the runtime gets the true one.
            assert_eq!(
                f.end_time(bad),
                Some((
                    truth,
                    match k {
                        ..4 => BadTime::Negative,
                        4 => BadTime::Repeat,
                        _ => BadTime::Ahead,
                    }
                ))
            );
            assert_eq!(f.end_time(bad), None, "once");
        }
        shown.push(seen);
    }
    let t = |k: i64| k * PERIOD_NS + 1;
    assert_eq!(
        shown,
        [
            None,
            Some(-t(1)),
            Some(-t(2)),
            None,
            Some(t(3)),
            None,
            Some(t(6) + BadTime::AHEAD_NS)
        ],
        "negative twice from frame 1, frame 3's time again at frame 4, weeks ahead at frame 6"
    );
}

#[test]
fn a_fault_that_walks_the_session_waits_for_the_one_before() {
    let now = Instant::now();
    let mut f = focused("frame 0 menu 5\nframe 1 headset-off 1");
    frame(&mut f, now);
    events(&mut f, now);
    for _ in 0..5 {
        frame(&mut f, now);
        assert!(
            states(&events(&mut f, now))
                .iter()
                .all(|s| *s != S::STOPPING)
        );
    }
    // FOCUSED is handed out after frame 5; the headset comes off at the next frame.
    assert_eq!(states(&events(&mut f, now)), [] as [sys::SessionState; 0]);
    frame(&mut f, now);
    assert_eq!(states(&events(&mut f, now)), [S::VISIBLE]);
}
