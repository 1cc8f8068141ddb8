//! The vitreous trace format, version 1: head poses and eye-tracker samples as UTF-8 text.
//!
//! One sample per line, comma-separated, after a version line and a column header line. The
//! full description (every column, its unit and axes) is in `docs/trace-format.md`; the short
//! version:
//!
//! ```text
//! # vitreous-trace v1
//! time_ns,head_x_m,head_y_m,head_z_m,head_qx,head_qy,head_qz,head_qw,gaze_time_ns,left_valid,...
//! 0,0,0,0,0,0,0,1,0,1,-0.032,0,0,0,0,-1,1,0.032,0,0,0,0,-1,,,,,,,,,,
//! ```
//!
//! The reader is strict about what the replay depends on (times, head pose) and lenient about
//! what trackers really produce: a gaze ray with a NaN/infinite value or a zero direction is
//! read as an invalid ray of that eye instead of failing the whole trace.
//!
//! The writer runs the same checks before writing, so it never produces a file the reader
//! refuses, and flushes after every sample so a crash loses at most the sample being written.
//! A trace file ([`TraceWriter::create`]) appears under its name only once finished.

use std::fs::File;
use std::io::{self, BufReader, Read, Write};
use std::path::Path;

use glam::{Quat, Vec3};
use thiserror::Error;

pub use crate::atomic_file::AtomicFile;
use crate::frame::{GazeRay, GazeSample, Pose};
use crate::records::{Record, RecordReader, printable};

/// The first line of every version-1 trace.
pub const VERSION_LINE: &str = "# vitreous-trace v1";

/// What the version line starts with, whatever the version.
const VERSION_PREFIX: &str = "# vitreous-trace ";

/// The column names of version 1, in file order (the second non-comment line of a trace).
pub const COLUMNS: [&str; 33] = [
    "time_ns",
    "head_x_m",
    "head_y_m",
    "head_z_m",
    "head_qx",
    "head_qy",
    "head_qz",
    "head_qw",
    "gaze_time_ns",
    "left_valid",
    "left_origin_x_m",
    "left_origin_y_m",
    "left_origin_z_m",
    "left_dir_x",
    "left_dir_y",
    "left_dir_z",
    "right_valid",
    "right_origin_x_m",
    "right_origin_y_m",
    "right_origin_z_m",
    "right_dir_x",
    "right_dir_y",
    "right_dir_z",
    "combined_valid",
    "combined_origin_x_m",
    "combined_origin_y_m",
    "combined_origin_z_m",
    "combined_dir_x",
    "combined_dir_y",
    "combined_dir_z",
    "fixation_x_m",
    "fixation_y_m",
    "fixation_z_m",
];

/// Index of the first column of each group in [`COLUMNS`].
const LEFT: usize = 9;
const RIGHT: usize = 16;
const COMBINED: usize = 23;
const FIXATION: usize = 30;

/// How far the head quaternion's norm may be from 1 before the sample is refused; within it
/// the quaternion is normalised (text round-off, other tools' rounding).
pub const QUAT_NORM_TOLERANCE: f32 = 1e-3;

/// The longest trace accepted: 24 hours from the first sample's `time_ns` to the last's.
/// Replay at 90 Hz then takes under 8 million frames; anything longer is a clock error.
pub const MAX_TRACE_SPAN_NS: i64 = 24 * 3600 * 1_000_000_000;

/// The longest gap accepted between the `time_ns` of consecutive samples: 10 minutes. A
/// longer pause in a recording is a clock jump, and replaying it would show one frozen pose
/// for that long.
pub const MAX_SAMPLE_GAP_NS: i64 = 10 * 60 * 1_000_000_000;

/// Below this length a gaze direction counts as zero (the ray is then invalid).
const MIN_DIRECTION_LENGTH: f32 = 1e-6;

/// Vectors whose squared length is within this of 1 are kept bit-exact instead of being
/// normalised again, so that writing then reading a sample gives the same numbers.
const UNIT_EPSILON: f32 = 1e-6;

/// One line of a trace: a head pose and the newest eye-tracker sample at that time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceSample {
    /// Time of the head pose, nanoseconds on the trace clock. Strictly increasing in a trace.
    pub time_ns: i64,
    /// Head pose in the world frame (OpenXR LOCAL-like axes, metres).
    pub head: Pose,
    /// The eye-tracker sample, rays in the head frame. `gaze.sample_time_ns <= time_ns`.
    pub gaze: GazeSample,
}

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
        "{file}:{line}: unsupported trace version `{version}`; this reader understands only v1"
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
    /// The column header line does not list the version-1 columns in order.
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
    /// A time or head-pose value is NaN or infinite.
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
    /// An optional group (combined ray, fixation) is only partly filled.
    #[error(
        "{file}:{line}: the {group} columns must be either all empty or all filled; column `{column}` is empty"
    )]
    PartialGroup {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// `combined` or `fixation`.
        group: &'static str,
        /// The first empty column of the group.
        column: &'static str,
    },
}

/// What the checks of a sample need to know of the samples before it.
#[derive(Clone, Copy, Debug)]
struct Preceding {
    /// The first sample's time.
    first_ns: i64,
    /// The previous sample's time.
    time_ns: i64,
    /// The previous sample's gaze time.
    gaze_time_ns: i64,
}

impl Preceding {
    /// What follows a sample accepted after `before`.
    fn after(before: Option<Preceding>, sample: &TraceSample) -> Preceding {
        Preceding {
            first_ns: before.map_or(sample.time_ns, |b| b.first_ns),
            time_ns: sample.time_ns,
            gaze_time_ns: sample.gaze.sample_time_ns,
        }
    }
}

/// Nanoseconds from `from` to `to`, seconds (no overflow: computed in 128 bits).
fn span_s(from: i64, to: i64) -> f64 {
    (i128::from(to) - i128::from(from)) as f64 * 1e-9
}

/// Checks the replay time limits: the gap to the previous sample and the span from the first
/// are at most [`MAX_SAMPLE_GAP_NS`] and [`MAX_TRACE_SPAN_NS`]. `time_ns` is after both.
pub(crate) fn check_span(
    file: &str,
    line: usize,
    time_ns: i64,
    previous_ns: i64,
    first_ns: i64,
) -> Result<(), TraceError> {
    if i128::from(time_ns) - i128::from(previous_ns) > i128::from(MAX_SAMPLE_GAP_NS) {
        return Err(TraceError::GapTooLong {
            file: file.to_owned(),
            line,
            time_ns,
            previous_ns,
            gap_s: span_s(previous_ns, time_ns),
        });
    }
    if i128::from(time_ns) - i128::from(first_ns) > i128::from(MAX_TRACE_SPAN_NS) {
        return Err(TraceError::SpanTooLong {
            file: file.to_owned(),
            line,
            time_ns,
            first_ns,
            span_s: span_s(first_ns, time_ns),
        });
    }
    Ok(())
}

/// Checks a head pose and its times; normalises small quaternion drift. Shared by the reader
/// and the writer so that what one accepts the other does too.
fn check_sample(
    file: &str,
    line: usize,
    sample: &TraceSample,
    previous: Option<Preceding>,
) -> Result<TraceSample, TraceError> {
    let p = sample.head.position;
    let q = sample.head.orientation;
    let values = [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
    for (i, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            return Err(TraceError::NonFinite {
                file: file.to_owned(),
                line,
                column: COLUMNS[1 + i],
                value,
            });
        }
    }
    let norm = q.length();
    if !norm.is_finite() || (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
        return Err(TraceError::NonUnitQuaternion {
            file: file.to_owned(),
            line,
            norm,
        });
    }
    let gaze_time_ns = sample.gaze.sample_time_ns;
    if let Some(before) = previous {
        if sample.time_ns <= before.time_ns {
            return Err(TraceError::TimeNotIncreasing {
                file: file.to_owned(),
                line,
                time_ns: sample.time_ns,
                previous_ns: before.time_ns,
            });
        }
        check_span(file, line, sample.time_ns, before.time_ns, before.first_ns)?;
        if gaze_time_ns < before.gaze_time_ns {
            return Err(TraceError::GazeTimeBackwards {
                file: file.to_owned(),
                line,
                gaze_time_ns,
                previous_ns: before.gaze_time_ns,
            });
        }
    }
    if gaze_time_ns > sample.time_ns {
        return Err(TraceError::GazeAfterPose {
            file: file.to_owned(),
            line,
            gaze_time_ns,
            time_ns: sample.time_ns,
        });
    }
    let mut out = *sample;
    out.head.orientation = unit_quat(q);
    out.gaze.left = clean_ray(sample.gaze.left);
    out.gaze.right = clean_ray(sample.gaze.right);
    out.gaze.combined = sample.gaze.combined.map(clean_ray);
    out.gaze.fixation = sample.gaze.fixation.filter(|f| f.is_finite());
    Ok(out)
}

/// Normalises a quaternion unless it already is unit to f32 precision (keeps round trips exact).
fn unit_quat(q: Quat) -> Quat {
    if (q.length_squared() - 1.0).abs() <= UNIT_EPSILON {
        q
    } else {
        q.normalize()
    }
}

/// The canonical form of a gaze ray: invalid rays (flagged, non-finite, zero direction) become
/// [`GazeRay::INVALID`]; valid directions are unit length.
pub fn clean_ray(ray: GazeRay) -> GazeRay {
    if !ray.valid || !ray.origin.is_finite() || !ray.direction.is_finite() {
        return GazeRay::INVALID;
    }
    // Scaled by the largest component first so huge finite values do not overflow.
    let largest = ray.direction.abs().max_element();
    if largest < MIN_DIRECTION_LENGTH {
        return GazeRay::INVALID;
    }
    let direction = if (ray.direction.length_squared() - 1.0).abs() <= UNIT_EPSILON {
        ray.direction
    } else {
        (ray.direction / largest).normalize()
    };
    GazeRay {
        origin: ray.origin,
        direction,
        valid: true,
    }
}

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

/// Parses one sample line without the time-order checks.
fn parse_record(record: &Record<'_>) -> Result<TraceSample, TraceError> {
    record.expect_len(COLUMNS.len())?;
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

/// Streams [`TraceSample`]s out of a version-1 trace.
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
        };
        this.read_headers()?;
        Ok(this)
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
            Some("v1") => {}
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
        for i in 0..header.len().max(COLUMNS.len()) {
            let found = if i < header.len() {
                header.field(i)
            } else {
                ""
            };
            let expected = COLUMNS.get(i).copied().unwrap_or("");
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

    /// Reads, parses and checks the next sample.
    fn next_sample(&mut self) -> Result<Option<TraceSample>, TraceError> {
        let Some(record) = self.records.next_content_record()? else {
            return Ok(None);
        };
        let raw = parse_record(&record)?;
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

/// Reads a whole trace file into memory.
pub fn read_trace(path: impl AsRef<Path>) -> Result<Vec<TraceSample>, TraceError> {
    TraceReader::open(path)?.collect()
}

/// Writes [`TraceSample`]s as a version-1 trace.
///
/// Every sample is checked like the reader checks it (finite head pose, unit quaternion,
/// increasing times, gaze time not after the pose time) and flushed once written.
pub struct TraceWriter<W: Write> {
    /// Where the text goes.
    writer: W,
    /// File name used in error messages.
    name: String,
    /// Line number the next sample will have (1-based).
    line: usize,
    /// What the ordering checks need of the samples before.
    previous: Option<Preceding>,
    /// Reused line buffer.
    buf: String,
    /// What [`TraceWriter::finish`] does after flushing: nothing, or commit a file.
    complete: fn(&mut W) -> io::Result<()>,
}

impl TraceWriter<AtomicFile> {
    /// Starts a trace file and writes its header lines. The trace is written to a temporary
    /// file in the same folder (flushed after every sample) and appears under `path`,
    /// replacing any earlier file, only when [`TraceWriter::finish`] succeeds; see
    /// [`AtomicFile`].
    pub fn create(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = AtomicFile::create(path).map_err(|source| TraceError::Io {
            file: name.clone(),
            context: "creating trace".to_owned(),
            source,
        })?;
        let mut this = TraceWriter::with_name(file, name)?;
        this.complete = AtomicFile::commit;
        Ok(this)
    }
}

impl<W: Write> TraceWriter<W> {
    /// Writes a trace into any writer (named `<output>` in error messages) and writes its
    /// header lines.
    pub fn new(writer: W) -> Result<Self, TraceError> {
        TraceWriter::with_name(writer, "<output>")
    }

    /// Like [`TraceWriter::new`], with the name to use in error messages.
    pub fn with_name(writer: W, name: impl Into<String>) -> Result<Self, TraceError> {
        let mut this = TraceWriter {
            writer,
            name: name.into(),
            line: 3,
            previous: None,
            buf: String::new(),
            complete: |_| Ok(()),
        };
        this.buf = format!("{VERSION_LINE}\n{}\n", COLUMNS.join(","));
        this.flush_buf("writing header")?;
        Ok(this)
    }

    /// Checks and writes one sample, then flushes. Invalid gaze rays (flagged, non-finite,
    /// zero direction) are written as `0` with empty numbers; a non-finite fixation point is
    /// written as absent.
    pub fn write(&mut self, sample: &TraceSample) -> Result<(), TraceError> {
        use std::fmt::Write as _;

        let s = check_sample(&self.name, self.line, sample, self.previous)?;
        let p = s.head.position;
        let q = s.head.orientation;
        let b = &mut self.buf;
        b.clear();
        // Writing into a String cannot fail.
        let _ = write!(
            b,
            "{},{},{},{},{},{},{},{},{}",
            s.time_ns, p.x, p.y, p.z, q.x, q.y, q.z, q.w, s.gaze.sample_time_ns
        );
        write_ray(b, Some(s.gaze.left));
        write_ray(b, Some(s.gaze.right));
        write_ray(b, s.gaze.combined);
        match s.gaze.fixation {
            Some(f) => {
                let _ = write!(b, ",{},{},{}", f.x, f.y, f.z);
            }
            None => b.push_str(",,,"),
        }
        b.push('\n');
        self.flush_buf("writing sample")?;
        self.previous = Some(Preceding::after(self.previous, &s));
        self.line += 1;
        Ok(())
    }

    /// Flushes and returns the underlying writer; for a file from [`TraceWriter::create`],
    /// first moves it to its final name.
    pub fn finish(mut self) -> Result<W, TraceError> {
        let result = self
            .writer
            .flush()
            .and_then(|()| (self.complete)(&mut self.writer));
        result.map_err(|source| TraceError::Io {
            file: self.name.clone(),
            context: "finishing trace".to_owned(),
            source,
        })?;
        Ok(self.writer)
    }

    /// Writes `self.buf` and flushes, so a crash loses at most the line being written.
    fn flush_buf(&mut self, what: &str) -> Result<(), TraceError> {
        let result = self
            .writer
            .write_all(self.buf.as_bytes())
            .and_then(|()| self.writer.flush());
        result.map_err(|source| TraceError::Io {
            file: self.name.clone(),
            context: format!("{what} (line {})", self.line),
            source,
        })
    }
}

/// Appends one ray group (with its leading comma); `None` writes all-empty fields.
fn write_ray(b: &mut String, ray: Option<GazeRay>) {
    use std::fmt::Write as _;
    match ray {
        None => b.push_str(",,,,,,,"),
        Some(r) if !r.valid => b.push_str(",0,,,,,,"),
        Some(r) => {
            let (o, d) = (r.origin, r.direction);
            let _ = write!(b, ",1,{},{},{},{},{},{}", o.x, o.y, o.z, d.x, d.y, d.z);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ray(origin: Vec3, direction: Vec3) -> GazeRay {
        GazeRay {
            origin,
            direction: direction.normalize(),
            valid: true,
        }
    }

    fn sample(time_ns: i64) -> TraceSample {
        TraceSample {
            time_ns,
            head: Pose {
                position: Vec3::new(0.1, 1.6, -0.2),
                orientation: Quat::from_rotation_y(0.3),
            },
            gaze: GazeSample {
                sample_time_ns: time_ns - 5,
                left: ray(Vec3::new(-0.032, 0.0, 0.01), Vec3::new(0.1, 0.0, -1.0)),
                right: ray(Vec3::new(0.032, 0.0, 0.01), Vec3::new(-0.1, 0.0, -1.0)),
                combined: None,
                fixation: None,
            },
        }
    }

    fn to_text(samples: &[TraceSample]) -> String {
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        for s in samples {
            w.write(s).unwrap();
        }
        String::from_utf8(w.finish().unwrap()).unwrap()
    }

    fn read_str(text: &str) -> Result<Vec<TraceSample>, TraceError> {
        TraceReader::new(text.as_bytes(), "test.trace")?.collect()
    }

    /// A valid trace text with `n` samples, for corrupting one line in the tests.
    fn good_text(n: i64) -> String {
        to_text(&(1..=n).map(|i| sample(i * 1000)).collect::<Vec<_>>())
    }

    /// Replaces field `col` of physical line `line` (1-based).
    fn with_field(text: &str, line: usize, col: usize, value: &str) -> String {
        text.lines()
            .enumerate()
            .map(|(i, l)| {
                if i + 1 == line {
                    let mut f: Vec<&str> = l.split(',').collect();
                    f[col] = value;
                    f.join(",")
                } else {
                    l.to_owned()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn line_of(e: &TraceError) -> Option<usize> {
        use TraceError::*;
        match e {
            BadVersionLine { line, .. }
            | UnsupportedVersion { line, .. }
            | BadColumnHeader { line, .. }
            | FieldCount { line, .. }
            | BadField { line, .. }
            | NonFinite { line, .. }
            | NonUnitQuaternion { line, .. }
            | TimeNotIncreasing { line, .. }
            | GazeAfterPose { line, .. }
            | GazeTimeBackwards { line, .. }
            | PartialGroup { line, .. } => Some(*line),
            _ => None,
        }
    }

    #[test]
    fn round_trip_keeps_samples_exactly() {
        let mut samples: Vec<_> = (1..=5).map(|i| sample(i * 1_000_000)).collect();
        samples[1].gaze.left = GazeRay::INVALID;
        samples[2].gaze.combined = Some(ray(Vec3::ZERO, Vec3::new(0.0, 0.1, -1.0)));
        samples[3].gaze.combined = Some(GazeRay::INVALID);
        samples[4].gaze.fixation = Some(Vec3::new(0.01, -0.02, -0.75));
        let text = to_text(&samples);
        assert_eq!(read_str(&text).unwrap(), samples);
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
                    found: 34,
                    expected: 33,
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
    fn non_finite_head_pose_is_refused() {
        for (col, v) in [(1, "NaN"), (3, "inf"), (7, "-inf")] {
            let text = with_field(&good_text(3), 4, col, v);
            let e = read_str(&text).unwrap_err();
            assert!(matches!(e, TraceError::NonFinite { line: 4, .. }), "{e}");
            assert_eq!(line_of(&e), Some(4));
        }
    }

    #[test]
    fn non_unit_quaternion_is_refused_and_drift_normalised() {
        let text = with_field(&good_text(2), 3, 7, "2");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::NonUnitQuaternion { line: 3, .. }),
            "{e}"
        );
        // (0,0,0,1.0004): small drift, normalised.
        let text = with_field(&with_field(&good_text(2), 3, 5, "0"), 3, 7, "1.0004");
        let samples = read_str(&text).unwrap();
        assert!(
            samples[0]
                .head
                .orientation
                .abs_diff_eq(Quat::IDENTITY, 1e-6)
        );
    }

    #[test]
    fn times_must_increase() {
        let text = with_field(&good_text(3), 5, 0, "2000");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::TimeNotIncreasing {
                    line: 5,
                    time_ns: 2000,
                    ..
                }
            ),
            "{e}"
        );
        let text = with_field(&good_text(3), 4, 8, "2001");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::GazeAfterPose { line: 4, .. }),
            "{e}"
        );
        let text = with_field(&good_text(3), 4, 8, "900");
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::GazeTimeBackwards { line: 4, .. }),
            "{e}"
        );
        // Equal gaze times are fine: a faster head tracker repeats the gaze sample.
        let text = with_field(&good_text(3), 4, 8, "995");
        assert!(read_str(&text).is_ok());
    }

    #[test]
    fn traces_that_would_replay_for_ages_are_refused() {
        // A gap of years before the last sample.
        let years_ns = 3 * 365 * 86_400 * 1_000_000_000i64;
        let text = with_field(&good_text(3), 5, 0, &years_ns.to_string());
        let e = read_str(&text).unwrap_err();
        assert!(matches!(e, TraceError::GapTooLong { line: 5, .. }), "{e}");
        assert!(e.to_string().contains("test.trace:5"), "{e}");
        // A span overflowing 64-bit nanoseconds.
        let text = with_field(
            &with_field(&good_text(2), 3, 0, &i64::MIN.to_string()),
            3,
            8,
            &i64::MIN.to_string(),
        );
        let text = with_field(&text, 4, 0, &i64::MAX.to_string());
        let e = read_str(&text).unwrap_err();
        assert!(matches!(e, TraceError::GapTooLong { line: 4, .. }), "{e}");
        // Many gaps under the limit adding up to more than the longest trace.
        let step = MAX_SAMPLE_GAP_NS;
        let count = MAX_TRACE_SPAN_NS / step + 2;
        let samples: Vec<_> = (0..count).map(|i| sample(i * step + 10)).collect();
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        for s in &samples[..samples.len() - 1] {
            w.write(s).unwrap();
        }
        let e = w.write(&samples[samples.len() - 1]).unwrap_err();
        assert!(matches!(e, TraceError::SpanTooLong { .. }), "{e}");
        let mut text = String::from_utf8(w.finish().unwrap()).unwrap();
        let last = samples[samples.len() - 1];
        let last_line = to_text(&[last]).lines().nth(2).unwrap().to_owned();
        text.push_str(&last_line);
        let e = read_str(&text).unwrap_err();
        assert!(
            matches!(e, TraceError::SpanTooLong { line, .. } if line == samples.len() + 2),
            "{e}"
        );
        assert!(
            e.to_string().contains("the longest trace is 86400 s"),
            "{e}"
        );
        // Exactly at the limits is fine.
        let at_limit = [sample(0), sample(MAX_SAMPLE_GAP_NS)];
        assert_eq!(read_str(&to_text(&at_limit)).unwrap().len(), 2);
    }

    #[test]
    fn bad_gaze_values_make_the_eye_invalid() {
        let text = with_field(&good_text(2), 3, LEFT + 4, "NaN");
        let s = read_str(&text).unwrap();
        assert_eq!(s[0].gaze.left, GazeRay::INVALID);
        assert!(s[0].gaze.right.valid);
        let zero = with_field(
            &with_field(
                &with_field(&good_text(2), 3, RIGHT + 4, "0"),
                3,
                RIGHT + 5,
                "0",
            ),
            3,
            RIGHT + 6,
            "0",
        );
        let s = read_str(&zero).unwrap();
        assert_eq!(s[0].gaze.right, GazeRay::INVALID);
        assert!(s[0].gaze.left.valid);
    }

    #[test]
    fn example_in_the_format_doc_reads() {
        let doc = include_str!("../../docs/trace-format.md");
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
    fn huge_finite_directions_are_normalised_not_invalid() {
        let text = with_field(&good_text(1), 3, LEFT + 6, "-3e38");
        let s = read_str(&text).unwrap();
        assert!(s[0].gaze.left.valid);
        assert!(s[0].gaze.left.direction.abs_diff_eq(Vec3::NEG_Z, 1e-6));
    }

    #[test]
    fn directions_are_normalised_on_read() {
        let text = with_field(&good_text(1), 3, LEFT + 6, "-10");
        let s = read_str(&text).unwrap();
        assert!((s[0].gaze.left.direction.length() - 1.0).abs() < 1e-6);
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

    fn arb_sample() -> impl Strategy<Value = (i64, i64, TraceSample)> {
        (
            1i64..1_000_000_000,
            0i64..1_000_000,
            arb_vec3(100.0),
            arb_vec3(1.0),
            -3.0f32..3.0,
            (arb_ray(), arb_ray(), proptest::option::of(arb_ray())),
            proptest::option::of(arb_vec3(10.0)),
        )
            .prop_map(
                |(dt, lag, position, axis, angle, (left, right, combined), fixation)| {
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
}
