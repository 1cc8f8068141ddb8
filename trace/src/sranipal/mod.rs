//! Import of HTC Vive Pro Eye recordings made with SRanipal and Unity (`;`-separated CSV).
//!
//! Columns are found by name in the header row, so extra or reordered columns do not matter.
//! The columns read are:
//!
//! | column | meaning |
//! |---|---|
//! | `time(100ns)` | .NET ticks (100 ns) |
//! | `eye_valid_L`, `eye_valid_R` | SRanipal validity bit mask per eye |
//! | `gaze_origin_L.x(mm)` ... | eye origin, SRanipal gaze frame, millimetres |
//! | `gaze_direct_L.x` ... | gaze direction, SRanipal gaze frame |
//! | `helmet_pos_x` ... | head position, Unity world, metres |
//! | `helmet_rot_x` ... | head rotation, Unity Euler angles, degrees |
//!
//! Conversions, all into the OpenXR conventions of this crate:
//! - **Gaze** (SRanipal: right-handed, +x to the wearer's LEFT, +y up, +z forward): `x -> -x`,
//!   `z -> -z` (a half turn about y, so handedness is kept), millimetres to metres. An eye is
//!   valid when its mask has both the gaze-origin bit (0) and the gaze-direction bit (1) set
//!   (31, everything valid, is the usual value) and its ray is finite with a non-zero
//!   direction; otherwise it is [`GazeRay::INVALID`].
//! - **Head** (Unity: left-handed, +x right, +y up, +z forward; Euler angles applied Z, then
//!   X, then Y, i.e. `q = qY * qX * qZ`): the z axis is mirrored, position `(x, y, z) ->
//!   (x, y, -z)` and quaternion `(x, y, z, w) -> (-x, -y, z, w)`. A turn to the wearer's right
//!   stays a turn to the right.
//! - **Re-anchoring**: the first row's head position is subtracted and its heading (yaw about
//!   +y) removed, so the trace starts at the origin facing -z; its pitch and roll, and all
//!   motion relative to the first row, are kept.
//! - **Time**: nanoseconds since the first row; the gaze sample time is the row time. Rows
//!   whose time is not after the previous kept row are dropped and counted in the report.
//!   The trace limits apply: a gap over [`crate::format::MAX_SAMPLE_GAP_NS`] after the
//!   previous row, or a span over [`crate::format::MAX_TRACE_SPAN_NS`], fails the import.

mod convert;
mod report;
#[cfg(test)]
mod tests;

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use glam::{Quat, Vec3};

pub use convert::{heading_rad, sranipal_ray_to_openxr, unity_pose_to_openxr};
pub use report::ImportReport;
use report::median_sorted;

use crate::format::{TraceError, TraceSample, check_span};
use crate::frame::{GazeRay, GazeSample, Pose};
use crate::records::{Record, RecordReader};

/// SRanipal validity bits needed for a usable gaze ray: gaze origin (bit 0) and gaze
/// direction (bit 1).
pub const GAZE_VALID_MASK: u32 = 0b11;

/// The columns the importer needs, by name.
const TIME: &str = "time(100ns)";
const VALID_L: &str = "eye_valid_L";
const VALID_R: &str = "eye_valid_R";
const ORIGIN_L: [&str; 3] = [
    "gaze_origin_L.x(mm)",
    "gaze_origin_L.y(mm)",
    "gaze_origin_L.z(mm)",
];
const ORIGIN_R: [&str; 3] = [
    "gaze_origin_R.x(mm)",
    "gaze_origin_R.y(mm)",
    "gaze_origin_R.z(mm)",
];
const DIRECT_L: [&str; 3] = ["gaze_direct_L.x", "gaze_direct_L.y", "gaze_direct_L.z"];
const DIRECT_R: [&str; 3] = ["gaze_direct_R.x", "gaze_direct_R.y", "gaze_direct_R.z"];
const HELMET_POS: [&str; 3] = ["helmet_pos_x", "helmet_pos_y", "helmet_pos_z"];
const HELMET_ROT: [&str; 3] = ["helmet_rot_x", "helmet_rot_y", "helmet_rot_z"];

/// Nanoseconds per .NET tick.
const NS_PER_TICK: i64 = 100;

/// Everything that can go wrong importing an SRanipal CSV: the trace error type, which
/// names the file, the line (1-based, the header is line 1) and the column.
pub type ImportError = TraceError;

/// Imports an SRanipal CSV recording as a trace.
pub fn import_sranipal(path: impl AsRef<Path>) -> Result<Vec<TraceSample>, ImportError> {
    import_sranipal_with_report(path).map(|(samples, _)| samples)
}

/// Imports an SRanipal CSV recording as a trace, with a summary of what was imported.
pub fn import_sranipal_with_report(
    path: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, ImportReport), ImportError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let file = File::open(path).map_err(|source| ImportError::Io {
        file: name.clone(),
        context: "opening SRanipal recording".to_owned(),
        source,
    })?;
    parse_sranipal(BufReader::new(file), &name)
}

/// Imports SRanipal CSV text from any reader; `name` is used in error messages.
pub fn parse_sranipal(
    reader: impl Read,
    name: &str,
) -> Result<(Vec<TraceSample>, ImportReport), ImportError> {
    let mut records = RecordReader::new(reader, name, b';');
    let empty = || ImportError::Empty {
        file: name.to_owned(),
        expected: "a `;`-separated SRanipal header row starting with `time(100ns)`",
    };
    let Some(header) = records.next_record()? else {
        return Err(empty());
    };
    let names: Vec<&str> = header
        .fields()
        .map(|h| h.trim_start_matches('\u{feff}').trim())
        .collect();
    if names.iter().all(|h| h.is_empty()) {
        return Err(empty());
    }
    let cols = Columns::find(&names, name, header.line())?;
    let width = names.len();

    let mut importer = Importer::default();
    let mut rows = 0usize;
    while let Some(record) = records.next_record()? {
        if record.is_blank() {
            continue;
        }
        rows += 1;
        record.expect_len(width)?;
        importer.push(&cols, &record)?;
    }
    Ok(importer.finish(name, rows))
}

/// Indices of the needed columns in the header row.
struct Columns {
    time: usize,
    valid: [usize; 2],
    origin: [[usize; 3]; 2],
    direct: [[usize; 3]; 2],
    helmet_pos: [usize; 3],
    helmet_rot: [usize; 3],
}

impl Columns {
    fn find(header: &[&str], file: &str, line: usize) -> Result<Columns, ImportError> {
        let idx = |column: &'static str| {
            header
                .iter()
                .position(|h| *h == column)
                .ok_or_else(|| ImportError::MissingColumn {
                    file: file.to_owned(),
                    line,
                    column,
                })
        };
        let idx3 = |names: [&'static str; 3]| -> Result<[usize; 3], ImportError> {
            Ok([idx(names[0])?, idx(names[1])?, idx(names[2])?])
        };
        Ok(Columns {
            time: idx(TIME)?,
            valid: [idx(VALID_L)?, idx(VALID_R)?],
            origin: [idx3(ORIGIN_L)?, idx3(ORIGIN_R)?],
            direct: [idx3(DIRECT_L)?, idx3(DIRECT_R)?],
            helmet_pos: idx3(HELMET_POS)?,
            helmet_rot: idx3(HELMET_ROT)?,
        })
    }
}

/// One eye's ray in the OpenXR head frame, from a data row.
fn eye_ray(row: &Record<'_>, cols: &Columns, eye: usize) -> Result<GazeRay, ImportError> {
    let (valid_name, origin_names, direct_names) = if eye == 0 {
        (VALID_L, ORIGIN_L, DIRECT_L)
    } else {
        (VALID_R, ORIGIN_R, DIRECT_R)
    };
    let flags = row.i64(
        cols.valid[eye],
        valid_name,
        "an SRanipal validity bit mask (integer)",
    )?;
    if flags & i64::from(GAZE_VALID_MASK) != i64::from(GAZE_VALID_MASK) {
        // The tracker says it has no ray; its numbers are not read.
        return Ok(GazeRay::INVALID);
    }
    let origin_mm = row.vec3(cols.origin[eye], origin_names)?;
    let direction = row.vec3(cols.direct[eye], direct_names)?;
    Ok(sranipal_ray_to_openxr(origin_mm, direction))
}

/// Builds the trace row by row.
#[derive(Default)]
struct Importer {
    samples: Vec<TraceSample>,
    /// First row's ticks, and the re-anchoring transform taken from the first row.
    anchor: Option<Anchor>,
    dropped_rows: usize,
}

/// What re-anchoring removes: the first pose's position and heading.
#[derive(Clone, Copy)]
struct Anchor {
    first_ticks: i64,
    position: Vec3,
    yaw_rad: f32,
    /// Rotation by `-yaw_rad` about +y.
    unyaw: Quat,
}

impl Importer {
    fn push(&mut self, cols: &Columns, row: &Record<'_>) -> Result<(), ImportError> {
        let ticks = row.i64(cols.time, TIME, "an integer count of 100 ns ticks")?;
        let position = row.finite_vec3(cols.helmet_pos, HELMET_POS)?;
        let euler_deg = row.finite_vec3(cols.helmet_rot, HELMET_ROT)?;
        let left = eye_ray(row, cols, 0)?;
        let right = eye_ray(row, cols, 1)?;
        let pose = unity_pose_to_openxr(position, euler_deg);

        let anchor = *self.anchor.get_or_insert_with(|| {
            let yaw_rad = heading_rad(pose.orientation);
            Anchor {
                first_ticks: ticks,
                position: pose.position,
                yaw_rad,
                unyaw: Quat::from_rotation_y(-yaw_rad),
            }
        });
        let time_ns = ticks
            .checked_sub(anchor.first_ticks)
            .and_then(|d| d.checked_mul(NS_PER_TICK))
            .ok_or(ImportError::TimeRange {
                file: row.file().to_owned(),
                line: row.line(),
                ticks,
                first_ticks: anchor.first_ticks,
            })?;
        if self.samples.last().is_some_and(|s| time_ns <= s.time_ns) {
            tracing::warn!(
                "{}:{}: time {} ticks is not after the previous row; row dropped",
                row.file(),
                row.line(),
                ticks
            );
            self.dropped_rows += 1;
            return Ok(());
        }
        if let Some(last) = self.samples.last() {
            check_span(row.file(), row.line(), time_ns, last.time_ns, 0)?;
        }
        // Positions near the f32 limits can make the re-anchored one overflow: a NaN head
        // pose no trace reader accepts.
        let head_position = anchor.unyaw * (pose.position - anchor.position);
        if let Some(axis) = (0..3).find(|&i| !head_position[i].is_finite()) {
            return Err(ImportError::BadField {
                file: row.file().to_owned(),
                line: row.line(),
                column: HELMET_POS[axis],
                found: position[axis].to_string(),
                expected: "a position whose distance from the first row's fits in an f32",
            });
        }
        self.samples.push(TraceSample {
            time_ns,
            head: Pose {
                position: head_position,
                orientation: (anchor.unyaw * pose.orientation).normalize(),
            },
            gaze: GazeSample::binocular(time_ns, left, right),
        });
        Ok(())
    }

    fn finish(self, name: &str, rows: usize) -> (Vec<TraceSample>, ImportReport) {
        let samples = self.samples;
        let n = samples.len();
        let fraction = |count: usize| if n == 0 { 0.0 } else { count as f64 / n as f64 };
        let left_valid = samples.iter().filter(|s| s.gaze.left.valid).count();
        let right_valid = samples.iter().filter(|s| s.gaze.right.valid).count();
        let mut ipds_mm: Vec<f32> = samples
            .iter()
            .filter(|s| s.gaze.left.valid && s.gaze.right.valid)
            .map(|s| s.gaze.left.origin.distance(s.gaze.right.origin) * 1000.0)
            .collect();
        ipds_mm.sort_by(f32::total_cmp);
        let median_ipd_mm = median_sorted(&ipds_mm);
        let duration_s = match (samples.first(), samples.last()) {
            (Some(a), Some(b)) => (b.time_ns - a.time_ns) as f64 * 1e-9,
            _ => 0.0,
        };
        let report = ImportReport {
            file: name.to_owned(),
            rows,
            samples: n,
            dropped_rows: self.dropped_rows,
            left_valid_fraction: fraction(left_valid),
            right_valid_fraction: fraction(right_valid),
            median_ipd_mm,
            duration_s,
            removed_yaw_rad: self.anchor.map_or(0.0, |a| a.yaw_rad),
            removed_position_m: self.anchor.map_or(Vec3::ZERO, |a| a.position),
        };
        (samples, report)
    }
}
