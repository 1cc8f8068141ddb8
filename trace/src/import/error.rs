//! The error type of the Tobii Pro Glasses 3 and Pupil Labs Neon imports.

use std::io;

use thiserror::Error;

use crate::format::TraceError;

/// Everything that can go wrong importing a Tobii Pro Glasses 3 or Neon recording. Messages
/// name the file and, where there is one, the line (JSON lines, 1-based) or the record
/// (binary files, 0-based index as numpy would give it).
#[derive(Debug, Error)]
pub enum RecordingError {
    /// A file could not be opened or read (a gzip stream cut short lands here too).
    #[error("{file}: {context}: {source}")]
    Io {
        /// File name.
        file: String,
        /// What was being done, with the line or record when known.
        context: String,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// A file the import needs is not there.
    #[error("{file}: not found; {why}")]
    Missing {
        /// The path looked for.
        file: String,
        /// What the file holds and why it is needed.
        why: &'static str,
    },
    /// The file holds no records of the kind the import needs.
    #[error("{file}: no {what} records; nothing to import")]
    Empty {
        /// File name.
        file: String,
        /// What was looked for.
        what: &'static str,
    },
    /// A JSON line does not parse, or lacks a field the import needs.
    #[error("{file}:{line}: {message}")]
    Json {
        /// File name.
        file: String,
        /// Line number (1-based, of the decompressed text).
        line: usize,
        /// What is wrong, with the column the JSON parser reports.
        message: String,
    },
    /// A line is longer than [`crate::records::MAX_LINE_BYTES`].
    #[error("{file}:{line}: line is longer than {limit} bytes")]
    LineTooLong {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The limit, bytes.
        limit: usize,
    },
    /// A value is present but unusable (not finite, out of range).
    #[error("{file}:{at}: field `{field}`: expected {expected}, found {found}")]
    BadValue {
        /// File name.
        file: String,
        /// Where: the line number, `record N` or `bytes A..B`.
        at: String,
        /// Field name.
        field: String,
        /// The value found.
        found: String,
        /// What the field should hold.
        expected: &'static str,
    },
    /// A `.dtype` file does not describe the layout the import reads.
    #[error("{file}: {message}")]
    Dtype {
        /// The `.dtype` file.
        file: String,
        /// What does not match.
        message: String,
    },
    /// A binary file's length is not a whole number of records.
    #[error(
        "{file}: {bytes} bytes is not a whole number of {record_bytes}-byte records (truncated, or a different layout)"
    )]
    Truncated {
        /// File name.
        file: String,
        /// File length, bytes.
        bytes: u64,
        /// Record size, bytes.
        record_bytes: usize,
    },
    /// A `.raw` file and its `.time` file hold different numbers of records.
    #[error(
        "{raw}: {records} records, but {time} has {times} timestamps; they must pair one to one"
    )]
    CountMismatch {
        /// The data file.
        raw: String,
        /// Records in it.
        records: usize,
        /// The time file.
        time: String,
        /// Timestamps in it.
        times: usize,
    },
    /// The samples break a trace rule (a gap over 10 minutes, a span over 24 hours).
    #[error(transparent)]
    Trace(#[from] TraceError),
}
