//! Version 1.3's report columns: the tracker's confidence and gaze behaviour as the words a
//! trace holds (`tracker_confidence`: `low`, `medium`, `high`; `gaze_behaviour`: `unknown`,
//! `eyes-closed`, `blink`, `fixation`, `pursuit`, `saccade`), both empty when the sample has
//! no report.

use super::{COLUMNS_V1_3, REPORT, TraceError};
use crate::frame::{GazeBehaviour, TrackerConfidence, TrackerReport};
use crate::records::Record;

/// Every confidence, lowest first.
const CONFIDENCES: [TrackerConfidence; 3] = [
    TrackerConfidence::Low,
    TrackerConfidence::Medium,
    TrackerConfidence::High,
];

/// Every gaze behaviour.
const BEHAVIOURS: [GazeBehaviour; 6] = [
    GazeBehaviour::Unknown,
    GazeBehaviour::EyesClosed,
    GazeBehaviour::Blink,
    GazeBehaviour::Fixation,
    GazeBehaviour::Pursuit,
    GazeBehaviour::Saccade,
];

/// What the confidence column holds, for error messages.
const CONFIDENCE_EXPECTED: &str = "`low`, `medium` or `high` (or empty with `gaze_behaviour`)";

/// What the behaviour column holds, for error messages.
const BEHAVIOUR_EXPECTED: &str = "`unknown`, `eyes-closed`, `blink`, `fixation`, `pursuit` or \
                                  `saccade` (or empty with `tracker_confidence`)";

/// The word a trace holds for `confidence`.
pub fn confidence_name(confidence: TrackerConfidence) -> &'static str {
    match confidence {
        TrackerConfidence::Low => "low",
        TrackerConfidence::Medium => "medium",
        TrackerConfidence::High => "high",
    }
}

/// The word a trace holds for `behaviour`.
pub fn behaviour_name(behaviour: GazeBehaviour) -> &'static str {
    match behaviour {
        GazeBehaviour::Unknown => "unknown",
        GazeBehaviour::EyesClosed => "eyes-closed",
        GazeBehaviour::Blink => "blink",
        GazeBehaviour::Fixation => "fixation",
        GazeBehaviour::Pursuit => "pursuit",
        GazeBehaviour::Saccade => "saccade",
    }
}

/// Parses the report columns of a version-1.3 sample line: both empty is no report, one empty
/// is a partial group, and a word that is not one of the column's is a bad field.
pub(super) fn parse_report(record: &Record<'_>) -> Result<Option<TrackerReport>, TraceError> {
    let (confidence, behaviour) = (record.field(REPORT), record.field(REPORT + 1));
    if confidence.is_empty() && behaviour.is_empty() {
        return Ok(None);
    }
    let empty = if confidence.is_empty() {
        Some(REPORT)
    } else if behaviour.is_empty() {
        Some(REPORT + 1)
    } else {
        None
    };
    if let Some(col) = empty {
        return Err(TraceError::PartialGroup {
            file: record.file().to_owned(),
            line: record.line(),
            group: "tracker report",
            column: COLUMNS_V1_3[col],
        });
    }
    let confidence = CONFIDENCES
        .into_iter()
        .find(|c| confidence_name(*c) == confidence)
        .ok_or_else(|| record.bad(COLUMNS_V1_3[REPORT], confidence, CONFIDENCE_EXPECTED))?;
    let behaviour = BEHAVIOURS
        .into_iter()
        .find(|b| behaviour_name(*b) == behaviour)
        .ok_or_else(|| record.bad(COLUMNS_V1_3[REPORT + 1], behaviour, BEHAVIOUR_EXPECTED))?;
    Ok(Some(TrackerReport {
        confidence,
        behaviour,
    }))
}

/// Appends the report columns (with their leading commas) of a version-1.3 line.
pub(super) fn write_report(b: &mut String, report: Option<TrackerReport>) {
    match report {
        None => b.push_str(",,"),
        Some(r) => {
            b.push(',');
            b.push_str(confidence_name(r.confidence));
            b.push(',');
            b.push_str(behaviour_name(r.behaviour));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_traces::*;
    use super::super::*;
    use super::*;

    #[test]
    fn every_confidence_and_behaviour_has_its_own_word() {
        let mut words: Vec<&str> = CONFIDENCES.into_iter().map(confidence_name).collect();
        words.extend(BEHAVIOURS.into_iter().map(behaviour_name));
        let mut unique = words.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), words.len());
        assert!(
            words
                .iter()
                .all(|w| CONFIDENCE_EXPECTED.contains(&format!("`{w}`"))
                    || BEHAVIOUR_EXPECTED.contains(&format!("`{w}`")))
        );
    }

    #[test]
    fn reports_read_from_their_columns() {
        let text = with_field(&good_text_v1_3(3), 4, REPORT, "low");
        let text = with_field(&text, 4, REPORT + 1, "eyes-closed");
        let text = with_field(&with_field(&text, 5, REPORT, ""), 5, REPORT + 1, "");
        let s = read_str(&text).unwrap();
        let report = |confidence, behaviour| {
            Some(TrackerReport {
                confidence,
                behaviour,
            })
        };
        assert_eq!(
            s[0].gaze.report,
            report(TrackerConfidence::High, GazeBehaviour::Fixation)
        );
        assert_eq!(
            s[1].gaze.report,
            report(TrackerConfidence::Low, GazeBehaviour::EyesClosed)
        );
        assert_eq!(s[2].gaze.report, None);
    }

    #[test]
    fn a_bad_report_word_names_file_line_and_column() {
        let cases = [
            (REPORT, "certain", "tracker_confidence"),
            (REPORT, "LOW", "tracker_confidence"),
            (REPORT + 1, "blinking", "gaze_behaviour"),
            (REPORT + 1, "eyes_closed", "gaze_behaviour"),
        ];
        for (col, value, column) in cases {
            let text = with_field(&good_text_v1_3(3), 4, col, value);
            let e = read_str(&text).unwrap_err();
            assert!(
                matches!(&e, TraceError::BadField { line: 4, column: c, .. } if *c == column),
                "{e}"
            );
            let message = e.to_string();
            assert!(message.contains("test.trace:4"), "{message}");
            assert!(
                message.contains(column) && message.contains(value),
                "{message}"
            );
        }
    }

    #[test]
    fn a_half_filled_report_is_refused() {
        for (col, empty_column) in [
            (REPORT, "tracker_confidence"),
            (REPORT + 1, "gaze_behaviour"),
        ] {
            let text = with_field(&good_text_v1_3(2), 3, col, "");
            let e = read_str(&text).unwrap_err();
            assert!(
                matches!(
                    &e,
                    TraceError::PartialGroup {
                        line: 3,
                        group: "tracker report",
                        column,
                        ..
                    } if *column == empty_column
                ),
                "{e}"
            );
            assert!(e.to_string().contains("test.trace:3"), "{e}");
        }
    }

    #[test]
    fn report_columns_belong_to_version_1_3_only() {
        // A version-1.2 line with the report columns has too many fields.
        let text = good_text_v1_3(1).replacen("v1.3", "v1.2", 1);
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::BadColumnHeader { column: 36, .. }),
            "{e}"
        );
        // A version-1.3 file whose header lacks them is refused at the header.
        let text = good_text(1).replacen("v1.1", "v1.3", 1);
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::BadColumnHeader {
                    column: 36,
                    expected: "tracker_confidence",
                    ..
                }
            ),
            "{e}"
        );
    }
}
