//! The one error type of trace reading and writing, and of the SRanipal import.

use std::io;

use thiserror::Error;

#[cfg(doc)]
use super::PUPIL_RANGE_M;
use super::{MAX_SAMPLE_GAP_NS, MAX_TRACE_SPAN_NS, QUAT_NORM_TOLERANCE, VERSION_LINE};

/// Everything that can go wrong reading or writing a trace, or importing one from another
/// format ([`crate::sranipal`] uses this type too). Messages name the file, the line
/// (1-based) and the column where they can; quoted file content is escaped and shortened
/// ([`crate::records::printable`]).
#[derive(Debug, Error)]
pub enum TraceError {
    /// The file could not be opened, read or written.
    #[error("{file}: {context}: {source}")]
    Io {
        /// File name (or a description of the stream).
        file: String,
        /// What was being done, with the line number when known.
        context: String,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The file has no lines, or only empty ones.
    #[error("{file}: empty file; expected {expected}")]
    Empty {
        /// File name.
        file: String,
        /// What the first line should hold.
        expected: &'static str,
    },
    /// A line is longer than the readers accept ([`crate::records::MAX_LINE_BYTES`]).
    #[error("{file}:{line}: line is longer than {limit} bytes; it starts `{start}`")]
    LineTooLong {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The limit, bytes.
        limit: usize,
        /// The start of the line, escaped and shortened.
        start: String,
    },
    /// A line is not valid UTF-8 text.
    #[error("{file}:{line}: field {field} is not valid UTF-8 text")]
    NotUtf8 {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Field number (1-based).
        field: usize,
    },
    /// The first line is not a vitreous trace version line.
    #[error("{file}:{line}: not a vitreous trace: expected `{VERSION_LINE}`, found `{found}`")]
    BadVersionLine {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The line as found (shortened).
        found: String,
    },
    /// The version line names a version this reader does not know.
    #[error(
        "{file}:{line}: unsupported trace version `{version}`; this reader understands v1, v1.1, v1.2 and v1.3"
    )]
    UnsupportedVersion {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The version text after `# vitreous-trace `.
        version: String,
    },
    /// The file ends after the version line, without the column header line.
    #[error("{file}: missing column header line after `{VERSION_LINE}`")]
    MissingColumnHeader {
        /// File name.
        file: String,
    },
    /// The column header line does not list the columns of the file's version in order.
    #[error("{file}:{line}: column {column} of the header is `{found}`, expected `{expected}`")]
    BadColumnHeader {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Column number (1-based).
        column: usize,
        /// The name found (empty when the header is too short).
        found: String,
        /// The name expected (empty when the header is too long).
        expected: &'static str,
    },
    /// A data line has a different number of fields from the column header.
    #[error(
        "{file}:{line}: {found} `{separator}`-separated fields, expected {expected} (one per column of the header)"
    )]
    FieldCount {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Number of fields found.
        found: usize,
        /// Number of columns of the header.
        expected: usize,
        /// The field separator of the format.
        separator: char,
    },
    /// A column the SRanipal importer needs is not in the header row.
    #[error("{file}:{line}: header row has no column `{column}`; is this an SRanipal recording?")]
    MissingColumn {
        /// File name.
        file: String,
        /// Line number of the header row.
        line: usize,
        /// The missing column name.
        column: &'static str,
    },
    /// An SRanipal row's time is so far from the first row's that nanoseconds overflow an
    /// `i64`.
    #[error(
        "{file}:{line}: column `time(100ns)`: {ticks} ticks is too far from the first row's {first_ticks} (nanoseconds overflow)"
    )]
    TimeRange {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This row's ticks.
        ticks: i64,
        /// The first row's ticks.
        first_ticks: i64,
    },
    /// A field could not be parsed.
    #[error("{file}:{line}: column `{column}`: expected {expected}, found `{found}`")]
    BadField {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Column name.
        column: &'static str,
        /// The text found.
        found: String,
        /// What the column holds.
        expected: &'static str,
    },
    /// A time, head-pose or pupil value is NaN or infinite.
    #[error("{file}:{line}: column `{column}`: expected a finite number, found {value}")]
    NonFinite {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Column name.
        column: &'static str,
        /// The value found.
        value: f32,
    },
    /// A pupil diameter is outside [`PUPIL_RANGE_M`] (1-10 mm).
    #[error(
        "{file}:{line}: column `{column}`: pupil diameter {value} m is outside 1-10 mm (metres expected; empty when unknown)"
    )]
    PupilOutOfRange {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Column name.
        column: &'static str,
        /// The value found, metres.
        value: f32,
    },
    /// The head orientation quaternion is too far from unit length.
    #[error(
        "{file}:{line}: head quaternion (head_qx..head_qw) has norm {norm}, expected a unit quaternion (within {QUAT_NORM_TOLERANCE})"
    )]
    NonUnitQuaternion {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The norm found.
        norm: f32,
    },
    /// `time_ns` does not increase.
    #[error(
        "{file}:{line}: column `time_ns`: {time_ns} is not after the previous sample's {previous_ns}; times must strictly increase"
    )]
    TimeNotIncreasing {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This sample's time.
        time_ns: i64,
        /// The previous sample's time.
        previous_ns: i64,
    },
    /// `time_ns` is further after the previous sample's than [`MAX_SAMPLE_GAP_NS`].
    #[error(
        "{file}:{line}: column `time_ns`: {time_ns} is {gap_s:.1} s after the previous sample's {previous_ns}; the longest gap between samples is {} s",
        MAX_SAMPLE_GAP_NS / 1_000_000_000
    )]
    GapTooLong {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This sample's time.
        time_ns: i64,
        /// The previous sample's time.
        previous_ns: i64,
        /// The gap, seconds.
        gap_s: f64,
    },
    /// `time_ns` is further after the first sample's than [`MAX_TRACE_SPAN_NS`].
    #[error(
        "{file}:{line}: column `time_ns`: {time_ns} is {span_s:.1} s after the first sample's {first_ns}; the longest trace is {} s ({} hours)",
        MAX_TRACE_SPAN_NS / 1_000_000_000,
        MAX_TRACE_SPAN_NS / 3_600_000_000_000
    )]
    SpanTooLong {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This sample's time.
        time_ns: i64,
        /// The first sample's time.
        first_ns: i64,
        /// The span, seconds.
        span_s: f64,
    },
    /// `gaze_time_ns` is later than the head pose time of the same line.
    #[error(
        "{file}:{line}: column `gaze_time_ns`: {gaze_time_ns} is after time_ns {time_ns}; a line pairs a head pose with the newest gaze sample at or before it"
    )]
    GazeAfterPose {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The gaze sample time.
        gaze_time_ns: i64,
        /// The head pose time.
        time_ns: i64,
    },
    /// `gaze_time_ns` goes backwards.
    #[error(
        "{file}:{line}: column `gaze_time_ns`: {gaze_time_ns} is before the previous sample's {previous_ns}; gaze times must not decrease"
    )]
    GazeTimeBackwards {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This sample's gaze time.
        gaze_time_ns: i64,
        /// The previous sample's gaze time.
        previous_ns: i64,
    },
    /// An optional group (combined ray, fixation, tracker report) is only partly filled.
    #[error(
        "{file}:{line}: the {group} columns must be either all empty or all filled; column `{column}` is empty"
    )]
    PartialGroup {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// `combined`, `fixation` or `tracker report`.
        group: &'static str,
        /// The first empty column of the group.
        column: &'static str,
    },
    /// A scene-edit line (version 1.2) that cannot be replayed.
    #[error("{file}:{line}: edit line: {reason}")]
    BadEdit {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A session-event line (version 1.4) that cannot be read.
    #[error("{file}:{line}: event line: {reason}")]
    BadEvent {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A views line (version 1.5) that cannot be read.
    #[error("{file}:{line}: views line: {reason}")]
    BadViews {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Views written into a trace whose version has no views lines.
    #[error("{file}: a version {version} trace holds no views lines")]
    ViewsNotInVersion {
        /// File name.
        file: String,
        /// The version being written.
        version: &'static str,
    },
    /// An event written into a trace whose version has no event lines.
    #[error("{file}: a version {version} trace holds no session events")]
    EventsNotInVersion {
        /// File name.
        file: String,
        /// The version being written.
        version: &'static str,
    },
    /// An edit written into a trace whose version has no edit lines.
    #[error("{file}: a version {version} trace holds no scene edits")]
    EditsNotInVersion {
        /// File name.
        file: String,
        /// The version being written.
        version: &'static str,
    },
}
