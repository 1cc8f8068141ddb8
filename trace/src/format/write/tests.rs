//! Tests of writing traces.

use glam::{Quat, Vec3};
use proptest::prelude::*;

use super::super::test_traces::*;
use super::super::validate::unit_quat;
use super::super::*;
use crate::frame::{GazeBehaviour, GazeRay, GazeSample, Pose, TrackerConfidence, TrackerReport};

fn report(confidence: TrackerConfidence, behaviour: GazeBehaviour) -> Option<TrackerReport> {
    Some(TrackerReport {
        confidence,
        behaviour,
    })
}

fn edit(time_ns: i64) -> EditRecord {
    EditRecord {
        time_ns,
        action: "object+1mmx".to_owned(),
        object_offset_m: Vec3::new(0.001, 0.0, 0.0),
        object_turn: Quat::IDENTITY,
        light_offset_m: Vec3::ZERO,
        world_offset_m: Vec3::ZERO,
        light_share: None,
    }
}

fn text_of(w: TraceWriter<Vec<u8>>) -> String {
    String::from_utf8(w.finish().unwrap()).unwrap()
}

#[test]
fn round_trip_keeps_samples_exactly() {
    let mut samples: Vec<_> = (1..=5).map(|i| sample(i * 1_000_000)).collect();
    samples[1].gaze.left = GazeRay::INVALID;
    samples[2].gaze.combined = Some(ray(Vec3::ZERO, Vec3::new(0.0, 0.1, -1.0)));
    samples[3].gaze.combined = Some(GazeRay::INVALID);
    samples[4].gaze.fixation = Some(Vec3::new(0.01, -0.02, -0.75));
    samples[0].gaze.pupil_diameter_m = [Some(0.0041), Some(0.003_95)];
    samples[2].gaze.pupil_diameter_m = [None, Some(0.0062)];
    let text = to_text(&samples);
    assert!(text.starts_with("# vitreous-trace v1.1\n"), "{text}");
    assert_eq!(read_str(&text).unwrap(), samples);
}

#[test]
fn reports_round_trip_in_version_1_3() {
    use GazeBehaviour::*;
    use TrackerConfidence::*;
    let mut samples: Vec<_> = (1..=8).map(|i| sample(i * 1_000_000)).collect();
    let reports = [
        report(High, Fixation),
        report(Medium, Pursuit),
        report(Low, Saccade),
        None,
        report(Low, Blink),
        report(Low, EyesClosed),
        report(High, Unknown),
        report(Medium, Fixation),
    ];
    for (s, r) in samples.iter_mut().zip(reports) {
        s.gaze.report = r;
    }
    samples[4].gaze.left = GazeRay::INVALID;
    samples[4].gaze.right = GazeRay::INVALID;
    samples[1].gaze.pupil_diameter_m = [Some(0.004), None];
    // Asked for nothing in particular: the first sample's report makes it version 1.3.
    let mut w = TraceWriter::new(Vec::new()).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    assert_eq!(w.version(), Some(TraceVersion::V1_3));
    let text = text_of(w);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(VERSION_LINE_V1_3));
    assert_eq!(lines.next(), Some(COLUMNS_V1_3.join(",").as_str()));
    assert!(
        lines.next().unwrap().ends_with(",,,high,fixation"),
        "{text}"
    );
    assert!(text.lines().nth(5).unwrap().ends_with(",,"), "{text}");
    let mut r = TraceReader::new(text.as_bytes(), "r.trace").unwrap();
    assert_eq!(r.version(), TraceVersion::V1_3);
    let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(read, samples);
}

#[test]
fn traces_without_reports_are_written_as_before() {
    let samples: Vec<_> = (1..=2).map(|i| sample(i * 1000)).collect();
    // Byte for byte the text of the 1.1 and 1.2 writers before version 1.3 existed.
    let line = |t: i64| {
        format!(
            "{t},0.1,1.6,-0.2,0,0.14943814,0,0.9887711,{},1,-0.032,0,0.01,0.09950372,0,-0.99503714,1,0.032,0,0.01,-0.09950372,0,-0.99503714,,,,,,,,,,,,",
            t - 5
        )
    };
    let expected = |version: &str| {
        format!(
            "{version}\n{}\n{}\n{}\n",
            COLUMNS_V1_1.join(","),
            line(1000),
            line(2000)
        )
    };
    assert_eq!(to_text(&samples), expected(VERSION_LINE_V1_1));
    let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    assert_eq!(w.version(), Some(TraceVersion::V1_2));
    assert_eq!(text_of(w), expected(VERSION_LINE_V1_2));
    // With no samples the header lines come at the end, in the version asked for.
    let w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
    assert_eq!(
        text_of(w),
        format!("{VERSION_LINE_V1_2}\n{}\n", COLUMNS_V1_1.join(","))
    );
}

#[test]
fn version_1_3_when_asked_even_without_reports() {
    let samples: Vec<_> = (1..=2).map(|i| sample(i * 1000)).collect();
    let mut w = TraceWriter::with_version(Vec::new(), "a", TraceVersion::V1_3).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    let text = text_of(w);
    assert!(text.starts_with("# vitreous-trace v1.3\n"), "{text}");
    assert!(text.lines().nth(2).unwrap().ends_with(",,,,"), "{text}");
    assert_eq!(read_str(&text).unwrap(), samples);
}

#[test]
fn edits_before_the_first_sample_wait_for_its_version() {
    let mut first = sample(1000);
    first.gaze.report = report(TrackerConfidence::Medium, GazeBehaviour::Saccade);
    let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
    w.write_edit(&edit(0)).unwrap();
    assert_eq!(w.version(), None);
    w.write(&first).unwrap();
    w.write_edit(&edit(1500)).unwrap();
    w.write(&sample(2000)).unwrap();
    let text = text_of(w);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], VERSION_LINE_V1_3);
    assert!(lines[2].starts_with("edit,0,") && lines[4].starts_with("edit,1500,"));
    let mut r = TraceReader::new(text.as_bytes(), "e").unwrap();
    let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(read, vec![first, sample(2000)]);
    assert_eq!(r.take_edits(), vec![edit(0), edit(1500)]);
    // A trace of edits alone is the version asked for.
    let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
    w.write_edit(&edit(0)).unwrap();
    let text = text_of(w);
    assert!(text.starts_with("# vitreous-trace v1.2\n"), "{text}");
    assert!(text.ends_with("\nedit,0,object+1mmx,0.001,0,0,0,0,0,1,0,0,0,0,0,0\n"));
    // A writer asked for version 1.1 takes no edits, reports or not.
    let mut w = TraceWriter::new(Vec::new()).unwrap();
    assert!(matches!(
        w.write_edit(&edit(0)),
        Err(TraceError::EditsNotInVersion { .. })
    ));
}

#[test]
fn events_round_trip_in_version_1_4_among_samples_and_edits() {
    use crate::session_event::{NotRendered, SessionEvent};
    let ended = EventRecord {
        time_ns: 1000,
        event: SessionEvent::Ended,
    };
    let skipped = EventRecord {
        time_ns: 4000,
        event: SessionEvent::NotRendered {
            reason: NotRendered::Runtime,
            frames: 3,
        },
    };
    let mut w = TraceWriter::with_version(Vec::new(), "v", TraceVersion::V1_4).unwrap();
    w.write_event(&ended).unwrap();
    w.write(&sample(1000)).unwrap();
    w.write_edit(&edit(4000)).unwrap();
    w.write_event(&skipped).unwrap();
    w.write(&sample(4000)).unwrap();
    // Not before the line it follows.
    assert!(matches!(
        w.write_event(&EventRecord {
            time_ns: 3999,
            ..ended
        }),
        Err(TraceError::BadEvent { .. })
    ));
    let text = text_of(w);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], VERSION_LINE_V1_4);
    assert_eq!(lines[1].split(',').count(), 37, "version 1.3's columns");
    assert_eq!(lines[2], "event,1000,session-ended,,0");
    assert_eq!(lines[5], "event,4000,not-rendered,runtime,3");
    let mut r = TraceReader::new(text.as_bytes(), "v").unwrap();
    let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(read, vec![sample(1000), sample(4000)]);
    assert_eq!(r.take_events(), vec![ended, skipped]);
    assert_eq!(r.take_edits(), vec![edit(4000)]);
    // Earlier versions hold no events.
    let mut w = TraceWriter::with_version(Vec::new(), "v", TraceVersion::V1_3).unwrap();
    assert!(matches!(
        w.write_event(&ended),
        Err(TraceError::EventsNotInVersion { .. })
    ));
}

#[test]
fn bad_event_lines_name_the_line_and_what_is_wrong() {
    let head = format!("{VERSION_LINE_V1_4}\n{}\n", COLUMNS_V1_3.join(","));
    for (line, says) in [
        (
            "event,10,crashed,,0",
            "`crashed` is not one of not-rendered",
        ),
        ("event,10,lost,headset,0", "session or instance"),
        ("event,10,late,,-1", "count"),
        ("event,x,late,,1", "time_ns"),
        ("event,10,late,,1,2", "fields"),
    ] {
        let text = format!("{head}{line}\n");
        let mut r = TraceReader::new(text.as_bytes(), "bad.trace").unwrap();
        let e = r.next().unwrap().unwrap_err().to_string();
        assert!(e.contains("bad.trace:3") && e.contains(says), "{line}: {e}");
    }
    // In version 1.3 an event line is a sample line that does not parse.
    let text = format!(
        "{VERSION_LINE_V1_3}\n{}\nevent,10,late,,1\n",
        COLUMNS_V1_3.join(",")
    );
    let mut r = TraceReader::new(text.as_bytes(), "old.trace").unwrap();
    assert!(r.next().unwrap().is_err());
}

#[test]
fn reports_after_a_first_sample_without_one_are_left_out_and_counted() {
    let mut samples: Vec<_> = (1..=3).map(|i| sample(i * 1000)).collect();
    samples[1].gaze.report = report(TrackerConfidence::High, GazeBehaviour::Fixation);
    samples[2].gaze.report = report(TrackerConfidence::Low, GazeBehaviour::Blink);
    let mut w = TraceWriter::with_version(Vec::new(), "late", TraceVersion::V1_2).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    assert_eq!(w.reports_left_out(), 2);
    let text = text_of(w);
    assert!(text.starts_with("# vitreous-trace v1.2\n"), "{text}");
    let read = read_str(&text).unwrap();
    assert!(read.iter().all(|s| s.gaze.report.is_none()));
    assert_eq!(read[1].gaze.left, samples[1].gaze.left);
}

#[test]
fn version_1_files_read_as_before_without_pupils() {
    let mut samples: Vec<_> = (1..=3).map(|i| sample(i * 1000)).collect();
    samples[1].gaze.left = GazeRay::INVALID;
    // The same samples as a version-1 file: the pupil columns cut off.
    let v1: Vec<String> = to_text(&samples)
        .lines()
        .enumerate()
        .map(|(i, line)| match i {
            0 => VERSION_LINE.to_owned(),
            _ => line.rsplitn(3, ',').nth(2).unwrap().to_owned(),
        })
        .collect();
    assert_eq!(v1[1], COLUMNS.join(","));
    assert_eq!(v1[2].split(',').count(), COLUMNS.len());
    let v1 = v1.join("\n");
    let mut r = TraceReader::new(v1.as_bytes(), "v1.trace").unwrap();
    assert_eq!(r.version(), TraceVersion::V1);
    let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(read, samples);
    // A v1 file with the pupil columns is refused at its header.
    let e = read_str(&to_text(&samples).replacen("v1.1", "v1", 1)).unwrap_err();
    assert!(
        matches!(e, TraceError::BadColumnHeader { column: 34, .. }),
        "{e}"
    );
}

#[test]
fn file_round_trip_and_read_trace() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.trace");
    let samples: Vec<_> = (1..=3).map(|i| sample(i * 10)).collect();
    let mut w = TraceWriter::create(&path).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    // Nothing under the final name before finish().
    assert!(!path.exists());
    w.finish().unwrap();
    assert_eq!(read_trace(&path).unwrap(), samples);
    // Writing it again replaces it only on finish; an abandoned writer leaves it as it was
    // and no temporary file behind.
    let mut w = TraceWriter::create(&path).unwrap();
    w.write(&samples[0]).unwrap();
    drop(w);
    assert_eq!(read_trace(&path).unwrap(), samples);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn writer_refuses_what_reader_would() {
    let mut w = TraceWriter::new(Vec::new()).unwrap();
    w.write(&sample(100)).unwrap();
    let e = w.write(&sample(100)).unwrap_err();
    assert!(
        matches!(e, TraceError::TimeNotIncreasing { line: 4, .. }),
        "{e}"
    );
    let mut bad = sample(200);
    bad.head.position.x = f32::NAN;
    assert!(matches!(w.write(&bad), Err(TraceError::NonFinite { .. })));
    w.write(&sample(200)).unwrap();
}

fn arb_vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn arb_ray() -> impl Strategy<Value = GazeRay> {
    (any::<bool>(), arb_vec3(0.1), arb_vec3(1.0)).prop_map(|(valid, o, d)| {
        clean_ray(GazeRay {
            origin: o,
            direction: d,
            valid,
        })
    })
}

fn arb_report() -> impl Strategy<Value = TrackerReport> {
    use GazeBehaviour::*;
    use TrackerConfidence::*;
    (
        prop::sample::select(vec![Low, Medium, High]),
        prop::sample::select(vec![Unknown, EyesClosed, Blink, Fixation, Pursuit, Saccade]),
    )
        .prop_map(|(confidence, behaviour)| TrackerReport {
            confidence,
            behaviour,
        })
}

fn arb_sample() -> impl Strategy<Value = (i64, i64, TraceSample)> {
    (
        1i64..1_000_000_000,
        0i64..1_000_000,
        arb_vec3(100.0),
        arb_vec3(1.0),
        -3.0f32..3.0,
        (arb_ray(), arb_ray(), proptest::option::of(arb_ray())),
        (
            proptest::option::of(arb_vec3(10.0)),
            proptest::option::of(0.001f32..=0.010),
            proptest::option::of(0.001f32..=0.010),
            proptest::option::of(arb_report()),
        ),
    )
        .prop_map(
            |(
                dt,
                lag,
                position,
                axis,
                angle,
                (left, right, combined),
                (fixation, lp, rp, report),
            )| {
                let axis = axis.try_normalize().unwrap_or(Vec3::Y);
                let sample = TraceSample {
                    time_ns: 0,
                    head: Pose {
                        position,
                        orientation: Quat::from_axis_angle(axis, angle),
                    },
                    gaze: GazeSample {
                        sample_time_ns: 0,
                        left,
                        right,
                        combined,
                        fixation,
                        pupil_diameter_m: [lp, rp],
                        report,
                    },
                };
                (dt, lag, sample)
            },
        )
}

proptest! {
    #[test]
    fn random_traces_round_trip(raw in proptest::collection::vec(arb_sample(), 0..20)) {
        let mut time_ns = -5_000_000_000i64;
        let mut gaze_ns = i64::MIN;
        let mut samples = Vec::new();
        for (dt, lag, mut s) in raw {
            time_ns += dt;
            gaze_ns = gaze_ns.max(time_ns - lag);
            s.time_ns = time_ns;
            s.gaze.sample_time_ns = gaze_ns;
            s.head.orientation = unit_quat(s.head.orientation);
            samples.push(s);
        }
        let text = to_text(&samples);
        prop_assert_eq!(read_str(&text).unwrap(), samples);
    }
}
