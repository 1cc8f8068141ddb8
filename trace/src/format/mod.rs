//! The vitreous trace format, version 1 (and its minor versions: 1.1 adds the per-eye pupil
//! diameters, 1.2 the scene-edit lines of live controls, 1.3 the tracker's own report of each
//! sample, 1.4 the event lines of what happened to a live session between its samples, 1.5 the
//! views lines of the eyes a headset drew from): head poses and eye-tracker samples as UTF-8
//! text.
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
//! The reader takes all four versions (before 1.3 a sample has no report); the writer writes
//! v1.1 (its pupil columns are empty where a sample has no measurement), or v1.2 when asked
//! for a trace that may hold edits ([`TraceWriter::create_with_edits`]); edit lines come out of
//! the reader beside the samples ([`TraceReader::take_edits`], [`read_trace_with_edits`]). It
//! writes v1.3, which may hold edits too, when asked ([`TraceWriter::with_version`]) or when
//! the first sample carries a tracker report: the header lines wait for the first sample,
//! which decides the version, so a trace without reports stays byte for byte what it was.
//!
//! The writer runs the same checks before writing, so it never produces a file the reader
//! refuses, and flushes after every sample so a crash loses at most the sample being written.
//! A trace file ([`TraceWriter::create`]) appears under its name only once finished.

mod edit;
mod error;
mod event;
mod read;
mod report;
#[cfg(test)]
mod test_traces;
mod validate;
mod views;
mod write;

use crate::frame::{GazeSample, Pose};

pub use crate::atomic_file::AtomicFile;
pub use edit::{
    EDIT_FIELDS, EDIT_SHARE_FIELD, EDIT_TAG, EditRecord, MAX_ACTION_BYTES, valid_action,
};
pub use error::TraceError;
pub use event::{EVENT_FIELDS, EVENT_KINDS, EVENT_TAG, EventRecord};
pub use read::{Recording, TraceReader, read_recording, read_trace, read_trace_with_edits};
pub use report::{behaviour_name, confidence_name};
pub(crate) use validate::check_span;
pub use validate::clean_ray;
pub use views::{HeadView, MAX_EYE_OFFSET_M, VIEWS_FIELDS, VIEWS_TAG, ViewsRecord};
pub use write::TraceWriter;

/// The first line of every version-1 trace.
pub const VERSION_LINE: &str = "# vitreous-trace v1";

/// The first line of a version-1.1 trace (version 1 plus the per-eye pupil diameters); the
/// writer writes this version.
pub const VERSION_LINE_V1_1: &str = "# vitreous-trace v1.1";

/// The first line of a version-1.2 trace (version 1.1 plus scene-edit lines).
pub const VERSION_LINE_V1_2: &str = "# vitreous-trace v1.2";

/// The first line of a version-1.3 trace (version 1.2 plus the tracker report columns).
pub const VERSION_LINE_V1_3: &str = "# vitreous-trace v1.3";

/// The first line of a version-1.4 trace (version 1.3 plus event lines).
pub const VERSION_LINE_V1_4: &str = "# vitreous-trace v1.4";

/// The first line of a version-1.5 trace (version 1.4 plus views lines).
pub const VERSION_LINE_V1_5: &str = "# vitreous-trace v1.5";

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

/// The column names of version 1.1, in file order: those of version 1, then the per-eye
/// pupil diameters (`left_pupil_m`, `right_pupil_m`).
pub const COLUMNS_V1_1: [&str; 35] = {
    let mut out = [""; 35];
    let mut i = 0;
    while i < COLUMNS.len() {
        out[i] = COLUMNS[i];
        i += 1;
    }
    out[PUPILS] = "left_pupil_m";
    out[PUPILS + 1] = "right_pupil_m";
    out
};

/// The column names of version 1.3, in file order: those of version 1.1, then the tracker's
/// report of the sample (`tracker_confidence`, `gaze_behaviour`).
pub const COLUMNS_V1_3: [&str; 37] = {
    let mut out = [""; 37];
    let mut i = 0;
    while i < COLUMNS_V1_1.len() {
        out[i] = COLUMNS_V1_1[i];
        i += 1;
    }
    out[REPORT] = "tracker_confidence";
    out[REPORT + 1] = "gaze_behaviour";
    out
};

/// The versions of the format this crate reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceVersion {
    /// `# vitreous-trace v1`: 33 columns.
    V1,
    /// `# vitreous-trace v1.1`: 35 columns, version 1's and the pupil diameters.
    V1_1,
    /// `# vitreous-trace v1.2`: version 1.1's columns, and scene-edit lines
    /// ([`EditRecord`]) between the samples.
    V1_2,
    /// `# vitreous-trace v1.3`: version 1.2 with 37 columns, the last two the tracker's
    /// report of the sample ([`crate::TrackerReport`]).
    V1_3,
    /// `# vitreous-trace v1.4`: version 1.3 (its columns, edit lines) and event lines
    /// ([`EventRecord`]): what happened to the live session between its samples.
    V1_4,
    /// `# vitreous-trace v1.5`: version 1.4 and views lines ([`ViewsRecord`]): the eyes the
    /// headset drew from.
    V1_5,
}

impl TraceVersion {
    /// The column names of this version, in file order.
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            TraceVersion::V1 => &COLUMNS,
            TraceVersion::V1_1 | TraceVersion::V1_2 => &COLUMNS_V1_1,
            TraceVersion::V1_3 | TraceVersion::V1_4 | TraceVersion::V1_5 => &COLUMNS_V1_3,
        }
    }

    /// The version line.
    pub fn version_line(self) -> &'static str {
        match self {
            TraceVersion::V1 => VERSION_LINE,
            TraceVersion::V1_1 => VERSION_LINE_V1_1,
            TraceVersion::V1_2 => VERSION_LINE_V1_2,
            TraceVersion::V1_3 => VERSION_LINE_V1_3,
            TraceVersion::V1_4 => VERSION_LINE_V1_4,
            TraceVersion::V1_5 => VERSION_LINE_V1_5,
        }
    }

    /// Whether lines of this version may be scene edits.
    pub fn has_edits(self) -> bool {
        matches!(
            self,
            TraceVersion::V1_2 | TraceVersion::V1_3 | TraceVersion::V1_4 | TraceVersion::V1_5
        )
    }

    /// Whether the samples of this version carry the tracker's report.
    pub fn has_reports(self) -> bool {
        matches!(
            self,
            TraceVersion::V1_3 | TraceVersion::V1_4 | TraceVersion::V1_5
        )
    }

    /// Whether lines of this version may be session events.
    pub fn has_events(self) -> bool {
        matches!(self, TraceVersion::V1_4 | TraceVersion::V1_5)
    }

    /// Whether lines of this version may be views lines.
    pub fn has_views(self) -> bool {
        self == TraceVersion::V1_5
    }
}

/// The range of pupil diameters a trace may hold, metres (1-10 mm): a value outside it is a
/// unit mistake or a tracker's placeholder, refused like any other bad field.
pub const PUPIL_RANGE_M: std::ops::RangeInclusive<f32> = 0.001..=0.010;

/// Index of the first column of each group in [`COLUMNS`] ([`COLUMNS_V1_1`] for the pupils,
/// [`COLUMNS_V1_3`] for the report).
const LEFT: usize = 9;
const RIGHT: usize = 16;
const COMBINED: usize = 23;
const FIXATION: usize = 30;
const PUPILS: usize = 33;
const REPORT: usize = 35;

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
