//! Replays of small traces: frame times, gaze repetition, eye positions, interpolation,
//! streaming, and the errors.

use glam::Quat;
use vitreous_trace::format::{MAX_SAMPLE_GAP_NS, MAX_TRACE_SPAN_NS, TraceWriter};
use vitreous_trace::synth::{SynthParams, synthesize};
use vitreous_trace::{GazeRay, GazeSample, Pose};

use super::*;

fn sample(time_ns: i64, position: Vec3, yaw_rad: f32) -> TraceSample {
    TraceSample {
        time_ns,
        head: Pose {
            position,
            orientation: Quat::from_rotation_y(yaw_rad),
        },
        gaze: GazeSample::none(time_ns),
    }
}

fn run(backend: &mut NullBackend) -> Vec<FrameInput> {
    let mut frames = Vec::new();
    while let Some(f) = backend.wait_frame().unwrap() {
        backend.end_frame(&f).unwrap();
        frames.push(f);
    }
    frames
}

fn ten_ms_trace() -> Vec<TraceSample> {
    (0..=10)
        .map(|i| sample(5_000_000_000 + i * 10_000_000, Vec3::ZERO, 0.0))
        .collect()
}

#[test]
fn at_samples_gives_one_frame_per_sample_at_its_time() {
    // Irregular times, as a live session's frames are: 100 ms, then 50 ms, then 30 ms apart.
    let times = [
        1_000_000_000i64,
        1_100_000_000,
        1_150_000_000,
        1_180_000_000,
    ];
    let samples: Vec<TraceSample> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| sample(t, Vec3::new(i as f32 * 0.1, 0.0, 0.0), 0.0))
        .collect();
    let config = NullConfig {
        at_samples: true,
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(samples.clone(), config).unwrap();
    let frames = run(&mut b);
    assert_eq!(frames.iter().map(|f| f.time_ns).collect::<Vec<_>>(), times);
    // Each frame shows its own sample, not an interpolation between neighbours.
    for (f, s) in frames.iter().zip(&samples) {
        assert_eq!(f.head.position, s.head.position);
        assert_eq!(f.gaze.map(|g| g.sample_time_ns), Some(s.time_ns));
    }
    let limited = NullConfig {
        at_samples: true,
        max_frames: Some(2),
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(samples, limited).unwrap();
    assert_eq!(run(&mut b).len(), 2);
}

#[test]
fn frame_count_and_times_follow_the_frame_rate() {
    let mut b = NullBackend::new(ten_ms_trace(), NullConfig::default()).unwrap();
    let frames = run(&mut b);
    let times: Vec<i64> = frames.iter().map(|f| f.time_ns - 5_000_000_000).collect();
    assert_eq!(
        times,
        [
            0,
            16_666_667,
            33_333_333,
            50_000_000,
            66_666_667,
            83_333_333,
            100_000_000
        ]
    );
    assert!(frames.iter().enumerate().all(|(i, f)| f.index == i as u64));
    assert!(b.wait_frame().unwrap().is_none());

    let config = NullConfig {
        max_frames: Some(3),
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(ten_ms_trace(), config).unwrap();
    assert_eq!(run(&mut b).len(), 3);
}

#[test]
fn fast_loop_repeats_tracker_samples_without_inventing_any() {
    let samples = synthesize(&SynthParams {
        duration_s: 1.0,
        rate_hz: 30.0,
        blink_every_s: 0.0,
        ..SynthParams::default()
    });
    assert_eq!(samples.len(), 31);
    let config = NullConfig {
        frame_rate_hz: 90.0,
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(samples.clone(), config).unwrap();
    let frames = run(&mut b);
    assert_eq!(frames.len(), 91);
    for (k, f) in frames.iter().enumerate() {
        let gaze = f.gaze.unwrap();
        // Each 30 Hz sample serves three 90 Hz frames, unchanged.
        assert_eq!(gaze, samples[k / 3].gaze, "frame {k}");
        assert!(gaze.sample_time_ns <= f.time_ns);
    }
}

#[test]
fn a_gaze_sample_written_later_is_not_known_before_its_line() {
    // An eye tracker 25 ms late: the line at 40 ms holds the sample of 15 ms, and so on.
    let mut samples: Vec<TraceSample> = (0..6i64)
        .map(|i| sample(1_000_000_000 + i * 20_000_000, Vec3::ZERO, 0.0))
        .collect();
    for (i, s) in samples.iter_mut().enumerate() {
        let stamp = s.time_ns - 25_000_000;
        let mut g = GazeSample::none(stamp.max(1_000_000_000));
        g.left = GazeRay {
            origin: Vec3::new(-0.03, 0.0, 0.0),
            direction: Vec3::new(i as f32 * 0.1, 0.0, -1.0).normalize(),
            valid: true,
        };
        s.gaze = g;
    }
    for at_samples in [true, false] {
        let config = NullConfig {
            at_samples,
            frame_rate_hz: 100.0,
            ..NullConfig::default()
        };
        let frames = run(&mut NullBackend::new(samples.clone(), config).unwrap());
        for f in &frames {
            // The newest line at or before the frame, not the newest stamp at or before it
            // (the line at 60 ms holds a sample stamped at 35 ms, which a frame at 40 ms did
            // not have yet).
            let line = samples
                .iter()
                .rposition(|s| s.time_ns <= f.time_ns)
                .unwrap();
            assert_eq!(
                f.gaze,
                Some(samples[line].gaze),
                "frame at {} ns",
                f.time_ns
            );
        }
    }
}

#[test]
fn views_are_an_ipd_apart_along_head_x() {
    let samples = vec![
        sample(0, Vec3::new(1.0, 1.6, 0.0), 0.7),
        sample(1_000_000_000, Vec3::new(1.0, 1.6, 0.0), 0.7),
    ];
    let mut b = NullBackend::new(samples, NullConfig::default()).unwrap();
    let f = b.wait_frame().unwrap().unwrap();
    let head_x = f.head.transform_vector(Vec3::X);
    let d = f.views[1].pose.position - f.views[0].pose.position;
    assert!(d.abs_diff_eq(head_x * 0.063, 1e-6), "{d}");
    assert_eq!(f.views[0].pose.orientation, f.head.orientation);
    assert_eq!(f.views[1].fov, NullConfig::default().fov);
    let mid = (f.views[0].pose.position + f.views[1].pose.position) / 2.0;
    assert!(mid.abs_diff_eq(f.head.position, 1e-6));
}

#[test]
fn eye_positions_are_the_mean_of_valid_gaze_origins() {
    let mut samples = ten_ms_trace();
    let ray = |x: f32| GazeRay {
        origin: Vec3::new(x, 0.0, 0.03),
        direction: Vec3::NEG_Z,
        valid: true,
    };
    samples[0].gaze.left = ray(-0.030);
    samples[1].gaze.left = ray(-0.034);
    samples[1].gaze.right = ray(0.031);
    let config = NullConfig {
        frame_rate_hz: 100.0,
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(samples, config).unwrap();
    let f0 = b.wait_frame().unwrap().unwrap();
    b.end_frame(&f0).unwrap();
    assert!(
        f0.views[0]
            .pose
            .position
            .abs_diff_eq(Vec3::new(-0.030, 0.0, 0.03), 1e-6)
    );
    assert!(
        f0.views[1]
            .pose
            .position
            .abs_diff_eq(Vec3::new(0.0315, 0.0, 0.0), 1e-6)
    );
    let f1 = b.wait_frame().unwrap().unwrap();
    assert!(
        f1.views[0]
            .pose
            .position
            .abs_diff_eq(Vec3::new(-0.032, 0.0, 0.03), 1e-6)
    );
    assert!(
        f1.views[1]
            .pose
            .position
            .abs_diff_eq(Vec3::new(0.031, 0.0, 0.03), 1e-6)
    );
}

#[test]
fn head_pose_is_interpolated_midway() {
    let samples = vec![
        sample(0, Vec3::ZERO, 0.0),
        sample(
            1_000_000_000,
            Vec3::new(1.0, 0.0, 0.0),
            std::f32::consts::FRAC_PI_2,
        ),
    ];
    let config = NullConfig {
        frame_rate_hz: 2.0,
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(samples.clone(), config).unwrap();
    let frames = run(&mut b);
    assert_eq!(frames.len(), 3);
    let mid = frames[1].head;
    assert!(mid.position.abs_diff_eq(Vec3::new(0.5, 0.0, 0.0), 1e-6));
    let expected = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
    assert!(
        mid.orientation.abs_diff_eq(expected, 1e-6),
        "{}",
        mid.orientation
    );
    // Gaze is the newest sample at or before the frame, not an interpolation.
    assert_eq!(frames[1].gaze.unwrap().sample_time_ns, 0);
    assert_eq!(frames[2].head, samples[1].head);
}

#[test]
fn streams_from_a_trace_reader() {
    let samples = synthesize(&SynthParams {
        duration_s: 2.0,
        ..SynthParams::default()
    });
    let mut w = TraceWriter::new(Vec::new()).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    let text = w.finish().unwrap();
    let reader = TraceReader::new(std::io::Cursor::new(text), "synth.trace").unwrap();
    let mut streamed = NullBackend::from_reader(reader, NullConfig::default()).unwrap();
    let mut in_memory = NullBackend::new(samples, NullConfig::default()).unwrap();
    assert_eq!(run(&mut streamed), run(&mut in_memory));
}

#[test]
fn empty_or_broken_traces_are_errors_not_panics() {
    let e = NullBackend::new(Vec::new(), NullConfig::default())
        .err()
        .unwrap();
    assert!(matches!(e, NullError::EmptyTrace { .. }), "{e}");
    let header_only = format!(
        "{}\n{}\n",
        vitreous_trace::format::VERSION_LINE,
        vitreous_trace::format::COLUMNS.join(",")
    );
    let reader = TraceReader::new(std::io::Cursor::new(header_only), "empty.trace").unwrap();
    let e = NullBackend::from_reader(reader, NullConfig::default())
        .err()
        .unwrap();
    assert!(e.to_string().contains("empty.trace"), "{e}");

    let backwards = vec![sample(10, Vec3::ZERO, 0.0), sample(5, Vec3::ZERO, 0.0)];
    let mut b = NullBackend::new(backwards, NullConfig::default()).unwrap();
    assert!(matches!(
        b.wait_frame(),
        Err(NullError::OutOfOrder { index: 1, .. })
    ));
    assert!(b.wait_frame().unwrap().is_none());

    let bad_rate = NullConfig {
        frame_rate_hz: 0.0,
        ..NullConfig::default()
    };
    assert!(NullBackend::new(ten_ms_trace(), bad_rate).is_err());
}

#[test]
fn samples_spanning_too_long_are_refused() {
    let gap = vec![
        sample(0, Vec3::ZERO, 0.0),
        sample(MAX_SAMPLE_GAP_NS + 1, Vec3::ZERO, 0.0),
    ];
    let mut b = NullBackend::new(gap, NullConfig::default()).unwrap();
    let e = b.wait_frame().unwrap_err();
    assert!(matches!(e, NullError::TooLong { index: 1, .. }), "{e}");
    let overflow = vec![
        sample(i64::MIN, Vec3::ZERO, 0.0),
        sample(i64::MAX, Vec3::ZERO, 0.0),
    ];
    let mut b = NullBackend::new(overflow, NullConfig::default()).unwrap();
    assert!(matches!(b.wait_frame(), Err(NullError::TooLong { .. })));
    let step = MAX_SAMPLE_GAP_NS;
    let long: Vec<_> = (0..=MAX_TRACE_SPAN_NS / step + 1)
        .map(|i| sample(i * step, Vec3::ZERO, 0.0))
        .collect();
    let config = NullConfig {
        frame_rate_hz: 1e-3,
        ..NullConfig::default()
    };
    let mut b = NullBackend::new(long, config).unwrap();
    let e = loop {
        match b.wait_frame() {
            Ok(Some(f)) => b.end_frame(&f).unwrap(),
            Ok(None) => panic!("replay ended without refusing the trace"),
            Err(e) => break e,
        }
    };
    assert!(e.to_string().contains("the first sample's"), "{e}");
}

#[test]
fn a_trace_ending_near_the_end_of_time_ends_the_replay() {
    let near_end = vec![
        sample(i64::MAX - 20_000_000, Vec3::ZERO, 0.0),
        sample(i64::MAX, Vec3::ZERO, 0.0),
    ];
    let mut b = NullBackend::new(near_end, NullConfig::default()).unwrap();
    let mut frames = 0;
    while let Some(f) = b.wait_frame().unwrap() {
        b.end_frame(&f).unwrap();
        frames += 1;
        assert!(frames < 10, "replay does not end");
    }
    assert_eq!(frames, 2);
}

#[test]
fn frame_calls_must_alternate() {
    let mut b = NullBackend::new(ten_ms_trace(), NullConfig::default()).unwrap();
    let f = b.wait_frame().unwrap().unwrap();
    assert!(matches!(b.wait_frame(), Err(NullError::FrameOrder(_))));
    b.end_frame(&f).unwrap();
    assert!(matches!(b.end_frame(&f), Err(NullError::FrameOrder(_))));
}

#[test]
fn backend_is_send() {
    fn is_send<T: Send>() {}
    is_send::<NullBackend>();
}

#[test]
fn a_recordings_events_come_with_the_frames_they_came_with() {
    use vitreous_trace::format::{EventRecord, TraceVersion};
    use vitreous_trace::session_event::{NotRendered, SessionEvent};
    let mut text = Vec::new();
    let mut w = TraceWriter::with_version(&mut text, "r", TraceVersion::V1_4).unwrap();
    let at = |time_ns, event| EventRecord { time_ns, event };
    let skipped = SessionEvent::NotRendered {
        reason: NotRendered::Runtime,
        frames: 3,
    };
    w.write(&sample(1_000, Vec3::ZERO, 0.0)).unwrap();
    w.write_event(&at(5_000, SessionEvent::Ended)).unwrap();
    w.write_event(&at(5_000, SessionEvent::Resumed)).unwrap();
    w.write(&sample(5_000, Vec3::ZERO, 0.0)).unwrap();
    w.write_event(&at(6_000, skipped)).unwrap();
    w.write(&sample(6_000, Vec3::ZERO, 0.0)).unwrap();
    w.write_event(&at(
        7_000,
        SessionEvent::Lost(vitreous_trace::session_event::Loss::Session),
    ))
    .unwrap();
    w.finish().unwrap();
    let reader = TraceReader::new(std::io::Cursor::new(text), "r").unwrap();
    let mut backend = NullBackend::from_reader(
        reader,
        NullConfig {
            at_samples: true,
            ..NullConfig::default()
        },
    )
    .unwrap();
    let mut seen = Vec::new();
    while let Some(f) = backend.wait_frame().unwrap() {
        seen.push((f.time_ns, backend.take_events()));
        backend.end_frame(&f).unwrap();
    }
    assert_eq!(
        seen,
        vec![
            (1_000, vec![]),
            (5_000, vec![SessionEvent::Ended, SessionEvent::Resumed]),
            (6_000, vec![skipped]),
        ]
    );
    // The one after the last frame comes once the replay is over.
    assert_eq!(
        backend.take_events(),
        vec![SessionEvent::Lost(
            vitreous_trace::session_event::Loss::Session
        )]
    );
    // Samples in memory take the events beside them.
    let mut backend = NullBackend::new(ten_ms_trace(), NullConfig::default())
        .unwrap()
        .with_events(vec![at(5_015_000_000, SessionEvent::Recentred)]);
    let mut with = Vec::new();
    while let Some(f) = backend.wait_frame().unwrap() {
        if !backend.take_events().is_empty() {
            with.push(f.time_ns);
        }
        backend.end_frame(&f).unwrap();
    }
    // 60 Hz frames: the first at or after 15 ms is at 16.67 ms.
    assert_eq!(with, vec![5_016_666_667]);
}

#[test]
fn recorded_views_are_drawn_from_their_time_on_in_memory_and_streamed() {
    use vitreous_trace::format::{HeadView, TraceVersion, ViewsRecord};
    // Eyes 58 mm apart, each turned 2 degrees outwards, from 30 ms on (before: the default
    // eyes, 63 mm apart and parallel).
    let eye = |side: f32| HeadView {
        pose: Pose {
            position: Vec3::new(side * 0.029, 0.0, 0.0),
            orientation: Quat::from_rotation_y(-side * 2f32.to_radians()),
        },
        fov: vitreous_trace::Fov::symmetric(1.5, 1.5),
    };
    let views = ViewsRecord {
        time_ns: 5_030_000_000,
        eyes: [eye(-1.0), eye(1.0)],
    };
    // A head turned 30 degrees: the eyes are placed and turned in its frame.
    let trace: Vec<_> = (0..=10)
        .map(|i| sample(5_000_000_000 + i * 10_000_000, Vec3::Y, 0.5))
        .collect();
    let config = NullConfig {
        at_samples: true,
        ..NullConfig::default()
    };
    let check = |frames: &[FrameInput]| {
        assert_eq!(frames.len(), 11);
        for f in frames {
            let apart = f.views[0].pose.position.distance(f.views[1].pose.position);
            let turn = f.views[0]
                .pose
                .orientation
                .angle_between(f.views[1].pose.orientation)
                .to_degrees();
            let (want_apart, want_turn) = if f.time_ns < 5_030_000_000 {
                (0.063, 0.0)
            } else {
                (0.058, 4.0)
            };
            assert!((apart - want_apart).abs() < 1e-6, "{}: {apart}", f.time_ns);
            assert!((turn - want_turn).abs() < 1e-3, "{}: {turn}", f.time_ns);
            // The left eye turned to the head's left; the field is the replay's own.
            let left_forward = f.views[0].pose.orientation * Vec3::NEG_Z;
            let head_left = f.head.orientation * Vec3::NEG_X;
            if want_turn > 0.0 {
                assert!(left_forward.dot(head_left) > 0.0);
            }
            assert_eq!(f.views[0].fov, NullConfig::default().fov);
        }
    };
    let mut backend = NullBackend::new(trace.clone(), config)
        .unwrap()
        .with_views(vec![views]);
    check(&run(&mut backend));
    // The same from a version 1.5 file read as it is replayed.
    let mut w = TraceWriter::with_version(Vec::new(), "v", TraceVersion::V1_5).unwrap();
    for s in &trace {
        if s.time_ns == views.time_ns {
            w.write_views(&views).unwrap();
        }
        w.write(s).unwrap();
    }
    let text = w.finish().unwrap();
    let reader = TraceReader::new(std::io::Cursor::new(text), "v").unwrap();
    let mut backend = NullBackend::from_reader(reader, config).unwrap();
    check(&run(&mut backend));
}

#[test]
fn recorded_fields_are_drawn_when_asked_from_the_lines_time_on() {
    use vitreous_trace::Fov;
    use vitreous_trace::format::{HeadView, ViewsRecord};
    // A headset whose fields are asymmetric, each wider towards its own side.
    let field = |side: f32| Fov {
        angle_left_rad: if side < 0.0 { -0.45 } else { -0.35 },
        angle_right_rad: if side < 0.0 { 0.35 } else { 0.45 },
        angle_up_rad: 0.3,
        angle_down_rad: -0.32,
    };
    let eye = |side: f32| HeadView {
        pose: Pose {
            position: Vec3::new(side * 0.0315, 0.0, 0.0),
            orientation: Quat::IDENTITY,
        },
        fov: field(side),
    };
    let views = ViewsRecord {
        time_ns: 5_030_000_000,
        eyes: [eye(-1.0), eye(1.0)],
    };
    let trace: Vec<_> = (0..=10)
        .map(|i| sample(5_000_000_000 + i * 10_000_000, Vec3::Y, 0.0))
        .collect();
    let config = NullConfig {
        at_samples: true,
        ..NullConfig::default()
    };
    let mut backend = NullBackend::new(trace, config)
        .unwrap()
        .with_views(vec![views])
        .with_recorded_fields();
    let frames = run(&mut backend);
    assert_eq!(frames.len(), 11);
    for f in &frames {
        let want = if f.time_ns < views.time_ns {
            [config.fov; 2]
        } else {
            [field(-1.0), field(1.0)]
        };
        assert_eq!([f.views[0].fov, f.views[1].fov], want, "{}", f.time_ns);
    }
}
