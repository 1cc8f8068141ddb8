//! Why a responses file cannot be analysed: every error names the file, and the line where there
//! is one.

use std::path::PathBuf;

/// Why a responses file cannot be analysed.
#[derive(Debug, thiserror::Error)]
pub enum ResponsesError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The CSV itself is malformed (unequal field counts, bad UTF-8).
    #[error("{path}: line {line}: {message}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// The line, when known.
        line: u64,
        /// What the CSV reader said.
        message: String,
    },
    /// The header lacks a required column.
    #[error("{path}: line 1: the header has no `{column}` column (expected {expected})")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The missing column.
        column: &'static str,
        /// The columns a responses file must have, comma-separated.
        expected: String,
    },
    /// No answers after the header.
    #[error("{path}: no responses (the file has no lines after the header)")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A field is empty or not of its type.
    #[error("{path}: line {line}: `{field}` is {value:?}, expected {expected}")]
    BadField {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The column.
        field: &'static str,
        /// The text found.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A response that is neither `first`/`second` nor an integer.
    #[error(
        "{path}: line {line}: response {value:?} is neither `first`/`second` nor an integer rating from -3 to 3"
    )]
    UnknownResponse {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The text found.
        value: String,
    },
    /// A rating outside -3..3.
    #[error("{path}: line {line}: rating {value} is outside -3..3")]
    RatingOutOfRange {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The rating found.
        value: i64,
    },
    /// Forced choices and ratings in one file.
    #[error(
        "{path}: line {line}: {found} among answers of another kind (line {first_line} is {expected}); one file holds one kind"
    )]
    MixedKinds {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// This line's kind.
        found: &'static str,
        /// The kind of the first answer.
        expected: &'static str,
        /// The line of the first answer.
        first_line: u64,
    },
    /// A pair of one condition with itself.
    #[error("{path}: line {line}: first and second are both {condition:?}")]
    SameCondition {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The condition.
        condition: String,
    },
    /// The same (participant, trial) twice.
    #[error(
        "{path}: line {line}: participant {participant:?} trial {trial} already answered on line {first_line}"
    )]
    DuplicateTrial {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The participant.
        participant: String,
        /// The trial.
        trial: u64,
        /// The line of the earlier answer.
        first_line: u64,
    },
    /// Fewer than two conditions.
    #[error("{path}: only {count} condition(s); a paired comparison needs at least 2")]
    TooFewConditions {
        /// The file.
        path: PathBuf,
        /// How many conditions there are.
        count: usize,
    },
    /// A rating design where a participant rated an ordered pair twice.
    #[error(
        "{path}: line {line}: participant {participant:?} already rated {first:?} then {second:?} on line {first_line}; every ordered pair is rated once"
    )]
    RepeatedPair {
        /// The file.
        path: PathBuf,
        /// The line.
        line: u64,
        /// The participant.
        participant: String,
        /// Condition shown first.
        first: String,
        /// Condition shown second.
        second: String,
        /// The line of the earlier rating.
        first_line: u64,
    },
    /// A rating design where a participant lacks an ordered pair.
    #[error(
        "{path}: participant {participant:?} has no rating of {first:?} then {second:?}; every participant rates every ordered pair once"
    )]
    MissingPair {
        /// The file.
        path: PathBuf,
        /// The participant.
        participant: String,
        /// Condition shown first.
        first: String,
        /// Condition shown second.
        second: String,
    },
    /// A forced-choice design where a pair of conditions was never judged.
    #[error(
        "{path}: no participant compared {a:?} with {b:?}; every pair needs at least one answer"
    )]
    UnjudgedPair {
        /// The file.
        path: PathBuf,
        /// One condition.
        a: String,
        /// The other condition.
        b: String,
    },
}
