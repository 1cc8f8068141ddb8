//! Reading a trace: the version and column header lines, then one checked sample per line.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use glam::{Quat, Vec3};

use super::edit::{EDIT_TAG, EditRecord, check_edit, parse_edit};
use super::report::parse_report;
use super::validate::{Preceding, check_sample};
use super::{
    COLUMNS, COLUMNS_V1_1, COMBINED, FIXATION, LEFT, PUPILS, RIGHT, TraceError, TraceSample,
    TraceVersion, VERSION_PREFIX, clean_ray,
};
use crate::frame::{GazeRay, GazeSample, Pose};
use crate::records::{Record, RecordReader, printable};

/// Column names of the three columns starting at `col`.
fn names3(col: usize) -> [&'static str; 3] {
    [COLUMNS[col], COLUMNS[col + 1], COLUMNS[col + 2]]
}

/// Parses three consecutive float fields starting at column `col`.
fn parse_vec3(record: &Record<'_>, col: usize) -> Result<Vec3, TraceError> {
    record.vec3([col, col + 1, col + 2], names3(col))
}

/// Parses a required integer time field.
fn parse_time(record: &Record<'_>, col: usize) -> Result<i64, TraceError> {
    record.i64(col, COLUMNS[col], "an integer number of nanoseconds")
}

/// Parses a ray group: `valid, origin xyz, dir xyz` starting at `col`. The caller has checked
/// that the valid flag is present.
fn parse_ray(record: &Record<'_>, col: usize) -> Result<GazeRay, TraceError> {
    let valid = match record.field(col) {
        "1" => true,
        "0" => false,
        other => return Err(record.bad(COLUMNS[col], other, "0 or 1")),
    };
    if !valid {
        // An invalid ray's numbers are meaningless: they may be empty and are not read.
        return Ok(GazeRay::INVALID);
    }
    let origin = parse_vec3(record, col + 1)?;
    let direction = parse_vec3(record, col + 4)?;
    Ok(clean_ray(GazeRay {
        origin,
        direction,
        valid,
    }))
}

/// Parses an optional pupil diameter column (empty: unknown). Its range is checked with the
/// rest of the sample.
fn parse_pupil(record: &Record<'_>, col: usize) -> Result<Option<f32>, TraceError> {
    if record.field(col).is_empty() {
        return Ok(None);
    }
    record.f32(col, COLUMNS_V1_1[col]).map(Some)
}

/// Parses one sample line of a trace of `version` without the time-order checks.
fn parse_record(record: &Record<'_>, version: TraceVersion) -> Result<TraceSample, TraceError> {
    record.expect_len(version.columns().len())?;
    let time_ns = parse_time(record, 0)?;
    let position = parse_vec3(record, 1)?;
    let orientation = Quat::from_xyzw(
        record.f32(4, COLUMNS[4])?,
        record.f32(5, COLUMNS[5])?,
        record.f32(6, COLUMNS[6])?,
        record.f32(7, COLUMNS[7])?,
    );
    let gaze_time_ns = parse_time(record, 8)?;
    let left = parse_ray(record, LEFT)?;
    let right = parse_ray(record, RIGHT)?;

    let combined = match optional_group(record, COMBINED, 7, "combined")? {
        false => None,
        true => Some(parse_ray(record, COMBINED)?),
    };
    let fixation = match optional_group(record, FIXATION, 3, "fixation")? {
        false => None,
        true => Some(parse_vec3(record, FIXATION)?),
    };
    let pupil_diameter_m = match version {
        TraceVersion::V1 => [None, None],
        TraceVersion::V1_1 | TraceVersion::V1_2 | TraceVersion::V1_3 => [
            parse_pupil(record, PUPILS)?,
            parse_pupil(record, PUPILS + 1)?,
        ],
    };
    let report = if version.has_reports() {
        parse_report(record)?
    } else {
        None
    };
    Ok(TraceSample {
        time_ns,
        head: Pose {
            position,
            orientation,
        },
        gaze: GazeSample {
            sample_time_ns: gaze_time_ns,
            left,
            right,
            combined,
            fixation,
            pupil_diameter_m,
            report,
        },
    })
}

/// Whether an optional group is present. All empty: absent. For the combined ray, a `0` flag
/// with empty numbers is allowed (present but invalid); otherwise every field must be filled.
fn optional_group(
    record: &Record<'_>,
    col: usize,
    len: usize,
    group: &'static str,
) -> Result<bool, TraceError> {
    let empty = |i: usize| record.field(col + i).is_empty();
    if (0..len).all(empty) {
        return Ok(false);
    }
    let flag_only_invalid = group == "combined" && record.field(col) == "0";
    let needed = if flag_only_invalid { 1 } else { len };
    if let Some(i) = (0..needed).find(|&i| empty(i)) {
        return Err(TraceError::PartialGroup {
            file: record.file().to_owned(),
            line: record.line(),
            group,
            column: COLUMNS[col + i],
        });
    }
    Ok(true)
}

/// Streams [`TraceSample`]s out of a trace of any version this crate reads.
///
/// The version and column header lines are checked by the constructor; samples are parsed
/// and checked one line at a time as the iterator is advanced. After the first error the
/// iterator ends.
pub struct TraceReader<R: Read> {
    /// The lines being read.
    records: RecordReader<R>,
    /// What the ordering checks need of the samples before.
    previous: Option<Preceding>,
    /// Set after an error or the end of the input: the iterator is fused.
    done: bool,
    /// The version named by the first line.
    version: TraceVersion,
    /// The edit lines read so far (version 1.2 and later), in file order.
    edits: Vec<EditRecord>,
}

impl TraceReader<BufReader<File>> {
    /// Opens a trace file and checks its version and column header lines.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = File::open(path).map_err(|source| TraceError::Io {
            file: name.clone(),
            context: "opening trace".to_owned(),
            source,
        })?;
        TraceReader::new(BufReader::new(file), name)
    }
}

impl<R: Read> TraceReader<R> {
    /// Reads a trace from any reader; `name` is used in error messages. Checks the version
    /// and column header lines.
    pub fn new(reader: R, name: impl Into<String>) -> Result<Self, TraceError> {
        let mut this = TraceReader {
            records: RecordReader::new(reader, name, b','),
            previous: None,
            done: false,
            version: TraceVersion::V1,
            edits: Vec::new(),
        };
        this.read_headers()?;
        Ok(this)
    }

    /// The version of the trace, from its first line.
    pub fn version(&self) -> TraceVersion {
        self.version
    }

    /// The scene edits read so far (the lines among the samples already read; all of them once
    /// the iterator has ended), taken out of the reader.
    pub fn take_edits(&mut self) -> Vec<EditRecord> {
        std::mem::take(&mut self.edits)
    }

    /// The file name used in error messages.
    pub fn name(&self) -> &str {
        self.records.file()
    }

    /// Checks the version line and the column header line.
    fn read_headers(&mut self) -> Result<(), TraceError> {
        let name = self.records.file().to_owned();
        let Some(first) = self.records.next_record()? else {
            return Err(TraceError::Empty {
                file: name,
                expected: "first line `# vitreous-trace v1`",
            });
        };
        let text = first.text();
        let text = text.trim_start_matches('\u{feff}').trim();
        match text.strip_prefix(VERSION_PREFIX) {
            Some("v1") => self.version = TraceVersion::V1,
            Some("v1.1") => self.version = TraceVersion::V1_1,
            Some("v1.2") => self.version = TraceVersion::V1_2,
            Some("v1.3") => self.version = TraceVersion::V1_3,
            Some(version) => {
                return Err(TraceError::UnsupportedVersion {
                    file: name,
                    line: first.line(),
                    version: printable(version.trim()),
                });
            }
            None => {
                return Err(TraceError::BadVersionLine {
                    file: name,
                    line: first.line(),
                    found: printable(text),
                });
            }
        }
        let Some(header) = self.records.next_content_record()? else {
            return Err(TraceError::MissingColumnHeader { file: name });
        };
        let columns = self.version.columns();
        for i in 0..header.len().max(columns.len()) {
            let found = if i < header.len() {
                header.field(i)
            } else {
                ""
            };
            let expected = columns.get(i).copied().unwrap_or("");
            if found != expected {
                return Err(TraceError::BadColumnHeader {
                    file: name,
                    line: header.line(),
                    column: i + 1,
                    found: printable(found),
                    expected,
                });
            }
        }
        Ok(())
    }

    /// Reads, parses and checks the next sample (keeping the edit lines before it).
    fn next_sample(&mut self) -> Result<Option<TraceSample>, TraceError> {
        let record = loop {
            let Some(record) = self.records.next_content_record()? else {
                return Ok(None);
            };
            if !(self.version.has_edits() && record.field(0) == EDIT_TAG) {
                break record;
            }
            let raw = parse_edit(&record)?;
            let edit = check_edit(
                record.file(),
                record.line(),
                &raw,
                self.previous.map(|p| p.time_ns()),
                self.edits.last().map(|e| e.time_ns),
            )?;
            self.edits.push(edit);
        };
        let raw = parse_record(&record, self.version)?;
        let sample = check_sample(record.file(), record.line(), &raw, self.previous)?;
        self.previous = Some(Preceding::after(self.previous, &sample));
        Ok(Some(sample))
    }
}

impl<R: Read> Iterator for TraceReader<R> {
    type Item = Result<TraceSample, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.next_sample() {
            Ok(Some(sample)) => Some(Ok(sample)),
            Ok(None) => {
                self.done = true;
                None
            }
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

impl<R: Read> std::iter::FusedIterator for TraceReader<R> {}

/// Reads a whole trace file into memory, with its scene edits (none before version 1.2).
pub fn read_trace_with_edits(
    path: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, Vec<EditRecord>), TraceError> {
    let mut reader = TraceReader::open(path)?;
    let samples = reader.by_ref().collect::<Result<Vec<_>, _>>()?;
    Ok((samples, reader.take_edits()))
}

/// Reads a whole trace file into memory (the samples; scene edits are skipped).
pub fn read_trace(path: impl AsRef<Path>) -> Result<Vec<TraceSample>, TraceError> {
    TraceReader::open(path)?.collect()
}

#[cfg(test)]
mod tests {
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
        let doc = include_str!("../../../docs/trace-format.md");
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
        let doc = include_str!("../../../docs/trace-format.md");
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
        let doc = include_str!("../../../docs/trace-format.md");
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
}
