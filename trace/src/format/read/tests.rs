//! Tests of reading traces.

use glam::Vec3;

use super::super::test_traces::*;
use super::super::*;
use crate::frame::GazeRay;

#[test]
fn missing_file_names_the_file() {
    let e = read_trace("/nonexistent/dir/x.trace").unwrap_err();
    assert!(e.to_string().contains("/nonexistent/dir/x.trace"), "{e}");
}

#[test]
fn a_huge_line_is_refused_without_reading_it_whole_or_printing_it_raw() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.trace");
    let mut text = good_text(1).into_bytes();
    let mut huge = b"1\0\x1b".repeat(1 << 20);
    huge.push(b'\n');
    text.extend_from_slice(&huge);
    std::fs::write(&path, &text).unwrap();
    let e = read_trace(&path).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::LineTooLong {
                line: 4,
                limit: crate::records::MAX_LINE_BYTES,
                ..
            }
        ),
        "{e}"
    );
    let message = e.to_string();
    assert!(message.contains("huge.trace:4:"), "{message}");
    assert!(message.contains("1\\0\\u{1b}1"), "{message}");
    assert!(!message.chars().any(char::is_control), "{message}");
    assert!(message.len() < 400, "{message}");
    // The same bytes as the first line: refused before the version check quotes them.
    std::fs::write(&path, &huge).unwrap();
    let e = read_trace(&path).unwrap_err();
    assert!(matches!(e, TraceError::LineTooLong { line: 1, .. }), "{e}");
}

#[test]
fn control_characters_in_a_field_are_escaped() {
    let text = with_field(&good_text(1), 3, 2, "1\u{7}\u{0}");
    let e = read_str(&text).unwrap_err();
    assert!(e.to_string().contains("1\\u{7}\\0"), "{e}");
}

#[test]
fn empty_file_is_refused() {
    let e = read_str("").unwrap_err();
    assert!(matches!(e, TraceError::Empty { .. }), "{e}");
    assert!(e.to_string().contains("test.trace"));
}

#[test]
fn header_only_file_is_an_empty_trace() {
    let text = format!("{VERSION_LINE}\n{}\n", COLUMNS.join(","));
    assert_eq!(read_str(&text).unwrap(), vec![]);
    let e = read_str(&format!("{VERSION_LINE}\n")).unwrap_err();
    assert!(matches!(e, TraceError::MissingColumnHeader { .. }), "{e}");
}

#[test]
fn comments_blank_lines_and_crlf_are_accepted() {
    let text = good_text(3).replace('\n', "\r\n");
    let mut lines: Vec<&str> = text.split("\r\n").collect();
    lines.insert(1, "# recorded by hand");
    lines.insert(4, "");
    lines.insert(5, "  # another comment");
    let text = lines.join("\r\n");
    assert_eq!(read_str(&text).unwrap().len(), 3);
}

#[test]
fn wrong_or_missing_version_line_is_refused() {
    let text = good_text(1);
    let e = read_str(&text.replacen("v1", "v2", 1)).unwrap_err();
    assert!(
        matches!(e, TraceError::UnsupportedVersion { line: 1, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("v2"));
    let no_version: String = text.lines().skip(1).collect::<Vec<_>>().join("\n");
    let e = read_str(&no_version).unwrap_err();
    assert!(
        matches!(e, TraceError::BadVersionLine { line: 1, .. }),
        "{e}"
    );
}

#[test]
fn wrong_column_header_names_the_column() {
    let text = good_text(1).replacen("head_qw", "head_w", 1);
    let e = read_str(&text).unwrap_err();
    match &e {
        TraceError::BadColumnHeader {
            line: 2,
            column: 8,
            expected: "head_qw",
            ..
        } => {}
        _ => panic!("unexpected {e}"),
    }
    let short = good_text(1).replacen(",fixation_z_m", "", 1);
    let e = read_str(&short).unwrap_err();
    assert!(
        matches!(e, TraceError::BadColumnHeader { column: 33, .. }),
        "{e}"
    );
}

#[test]
fn wrong_field_count_gives_line() {
    let mut text = good_text(3);
    text = text.replacen("\n3000,", "\n3000,1,", 1);
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::FieldCount {
                line: 5,
                found: 36,
                expected: 35,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn unparseable_numbers_give_line_and_column() {
    let text = with_field(&good_text(3), 4, 2, "1.6m");
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::BadField {
                line: 4,
                column: "head_y_m",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("test.trace:4"), "{e}");
    let text = with_field(&good_text(3), 3, 0, "1.5");
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::BadField {
                line: 3,
                column: "time_ns",
                ..
            }
        ),
        "{e}"
    );
    let text = with_field(&good_text(3), 5, LEFT, "yes");
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::BadField {
                line: 5,
                column: "left_valid",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn example_in_the_format_doc_reads() {
    let doc = include_str!("../../../../docs/trace-format.md");
    let start = doc.find("```text\n").unwrap() + "```text\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let samples = read_str(&doc[start..end]).unwrap();
    assert_eq!(samples.len(), 3);
    assert_eq!(samples[1].gaze.left, GazeRay::INVALID);
    assert_eq!(
        samples[2].gaze.sample_time_ns,
        samples[1].gaze.sample_time_ns
    );
    assert_eq!(samples[2].gaze.fixation, Some(Vec3::new(0.0, 0.0, -0.6)));
}

#[test]
fn version_1_1_example_in_the_format_doc_reads_with_pupils() {
    let doc = include_str!("../../../../docs/trace-format.md");
    let at = doc.find("```text\n# vitreous-trace v1.1").unwrap() + "```text\n".len();
    let end = at + doc[at..].find("```").unwrap();
    let mut reader = TraceReader::new(&doc.as_bytes()[at..end], "doc").unwrap();
    assert_eq!(reader.version(), TraceVersion::V1_1);
    let samples: Vec<_> = reader.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(samples.len(), 2);
    assert_eq!(
        samples[0].gaze.pupil_diameter_m,
        [Some(0.0042), Some(0.0041)]
    );
    assert_eq!(samples[1].gaze.pupil_diameter_m, [None, Some(0.0041)]);
}

#[test]
fn version_1_3_example_in_the_format_doc_reads_with_reports() {
    use crate::frame::{GazeBehaviour, TrackerConfidence, TrackerReport};
    let doc = include_str!("../../../../docs/trace-format.md");
    let at = doc.find("```text\n# vitreous-trace v1.3").unwrap() + "```text\n".len();
    let end = at + doc[at..].find("```").unwrap();
    let mut reader = TraceReader::new(&doc.as_bytes()[at..end], "doc").unwrap();
    assert_eq!(reader.version(), TraceVersion::V1_3);
    let samples: Vec<_> = reader.by_ref().collect::<Result<_, _>>().unwrap();
    let reports: Vec<_> = samples.iter().map(|s| s.gaze.report).collect();
    assert_eq!(
        reports,
        [
            Some(TrackerReport {
                confidence: TrackerConfidence::High,
                behaviour: GazeBehaviour::Fixation,
            }),
            Some(TrackerReport {
                confidence: TrackerConfidence::Low,
                behaviour: GazeBehaviour::Blink,
            }),
            None,
        ]
    );
    assert_eq!(samples[1].gaze.combined, Some(GazeRay::INVALID));
}

#[test]
fn older_versions_read_without_reports() {
    for version in ["v1.1", "v1.2"] {
        let text = good_text(2).replacen("v1.1", version, 1);
        let samples = read_str(&text).unwrap();
        assert!(samples.iter().all(|s| s.gaze.report.is_none()), "{version}");
    }
}

#[test]
fn partial_optional_group_is_refused() {
    let text = with_field(&good_text(2), 4, FIXATION, "0.5");
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::PartialGroup {
                line: 4,
                group: "fixation",
                column: "fixation_y_m",
                ..
            }
        ),
        "{e}"
    );
    let text = with_field(&good_text(2), 4, COMBINED + 1, "0.5");
    let e = read_str(&text).unwrap_err();
    assert!(
        matches!(
            e,
            TraceError::PartialGroup {
                line: 4,
                group: "combined",
                column: "combined_valid",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn reader_stops_after_first_error() {
    let text = with_field(&good_text(3), 4, 1, "x");
    let mut r = TraceReader::new(text.as_bytes(), "t").unwrap();
    assert!(r.next().unwrap().is_ok());
    assert!(r.next().unwrap().is_err());
    assert!(r.next().is_none());
}
