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

use std::fmt;
use std::fs::File;
use std::io::{self, BufRead, BufReader};
use std::path::Path;

use glam::{Quat, Vec3};
use thiserror::Error;

use crate::frame::{GazeRay, GazeSample, Pose};
use crate::trace::{TraceSample, clean_ray};

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

/// Everything that can go wrong importing an SRanipal CSV. Messages name the file, the line
/// (1-based, the header is line 1) and the column.
#[derive(Debug, Error)]
pub enum ImportError {
    /// The file could not be opened or read.
    #[error("{file}: {context}: {source}")]
    Io {
        /// File name.
        file: String,
        /// What was being done, with the line number when known.
        context: String,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The file has no header row.
    #[error(
        "{file}: empty file; expected a `;`-separated SRanipal header row starting with `{TIME}`"
    )]
    Empty {
        /// File name.
        file: String,
    },
    /// A column the importer needs is not in the header row.
    #[error("{file}:{line}: header row has no column `{column}`; is this an SRanipal recording?")]
    MissingColumn {
        /// File name.
        file: String,
        /// Line number of the header row.
        line: usize,
        /// The missing column name.
        column: &'static str,
    },
    /// A data row has a different number of fields from the header row.
    #[error(
        "{file}:{line}: {found} `;`-separated fields, expected {expected} as in the header row"
    )]
    FieldCount {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// Fields found.
        found: usize,
        /// Fields in the header row.
        expected: usize,
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
    /// A head pose value is NaN or infinite.
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
    /// A row's time is so far from the first row's that nanoseconds overflow an `i64`.
    #[error(
        "{file}:{line}: column `{TIME}`: {ticks} ticks is too far from the first row's {first_ticks} (nanoseconds overflow)"
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
    /// A row's helmet position is so far from the first row's that the re-anchored position
    /// is not a finite `f32`.
    #[error(
        "{file}:{line}: columns `helmet_pos_*`: {position_m} m is too far from the first row's {first_m} m (the difference overflows)"
    )]
    PositionRange {
        /// File name.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// This row's position, metres (OpenXR axes).
        position_m: Vec3,
        /// The first row's position, metres (OpenXR axes).
        first_m: Vec3,
    },
}

/// A summary of an import, for a CLI to print.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportReport {
    /// File name.
    pub file: String,
    /// Data rows read (blank lines not counted).
    pub rows: usize,
    /// Samples in the imported trace.
    pub samples: usize,
    /// Rows dropped because their time was not after the previous kept row.
    pub dropped_rows: usize,
    /// Fraction of samples whose left eye is valid (0 when there are no samples).
    pub left_valid_fraction: f64,
    /// Fraction of samples whose right eye is valid (0 when there are no samples).
    pub right_valid_fraction: f64,
    /// Median distance between the two eye origins over samples where both are valid,
    /// millimetres; `None` when no sample has both.
    pub median_ipd_mm: Option<f32>,
    /// Time from the first to the last sample, seconds.
    pub duration_s: f64,
    /// Heading removed by re-anchoring, radians about +y (OpenXR axes, positive = the
    /// recording started turned to the left).
    pub removed_yaw_rad: f32,
    /// Position subtracted by re-anchoring, metres (Unity world with z mirrored).
    pub removed_position_m: Vec3,
}

impl ImportReport {
    /// Sample rate implied by the sample count and duration, hertz (`None` below 2 samples).
    pub fn mean_rate_hz(&self) -> Option<f64> {
        (self.samples >= 2 && self.duration_s > 0.0)
            .then(|| (self.samples - 1) as f64 / self.duration_s)
    }
}

impl fmt::Display for ImportReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} rows -> {} samples",
            self.file, self.rows, self.samples
        )?;
        if self.dropped_rows > 0 {
            write!(f, " ({} dropped: time not increasing)", self.dropped_rows)?;
        }
        write!(f, ", {:.2} s", self.duration_s)?;
        if let Some(rate) = self.mean_rate_hz() {
            write!(f, " (~{rate:.0} Hz)")?;
        }
        write!(
            f,
            ", valid eyes L {:.1}% R {:.1}%",
            self.left_valid_fraction * 100.0,
            self.right_valid_fraction * 100.0
        )?;
        match self.median_ipd_mm {
            Some(ipd) => write!(f, ", median IPD {ipd:.1} mm"),
            None => write!(f, ", median IPD unknown (no sample with both eyes valid)"),
        }
    }
}

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

/// Imports SRanipal CSV text from any buffered reader; `name` is used in error messages.
pub fn parse_sranipal(
    mut reader: impl BufRead,
    name: &str,
) -> Result<(Vec<TraceSample>, ImportReport), ImportError> {
    let mut buf = String::new();
    let mut line = 0usize;
    let mut next_line = |buf: &mut String| -> Result<Option<usize>, ImportError> {
        buf.clear();
        let n = reader.read_line(buf).map_err(|source| ImportError::Io {
            file: name.to_owned(),
            context: format!("reading line {}", line + 1),
            source,
        })?;
        if n == 0 {
            return Ok(None);
        }
        line += 1;
        let len = buf.trim_end_matches(['\n', '\r']).len();
        buf.truncate(len);
        Ok(Some(line))
    };

    let Some(header_line) = next_line(&mut buf)? else {
        return Err(ImportError::Empty {
            file: name.to_owned(),
        });
    };
    let header: Vec<String> = buf
        .trim_start_matches('\u{feff}')
        .split(';')
        .map(|s| s.trim().to_owned())
        .collect();
    if header.iter().all(|h| h.is_empty()) {
        return Err(ImportError::Empty {
            file: name.to_owned(),
        });
    }
    let cols = Columns::find(&header, name, header_line)?;

    let mut importer = Importer::default();
    let mut rows = 0usize;
    while let Some(line) = next_line(&mut buf)? {
        if buf.trim().is_empty() {
            continue;
        }
        rows += 1;
        let fields: Vec<&str> = buf.split(';').map(str::trim).collect();
        if fields.len() != header.len() {
            return Err(ImportError::FieldCount {
                file: name.to_owned(),
                line,
                found: fields.len(),
                expected: header.len(),
            });
        }
        let row = Row {
            name,
            line,
            fields: &fields,
        };
        importer.push(&cols, &row)?;
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
    fn find(header: &[String], file: &str, line: usize) -> Result<Columns, ImportError> {
        let idx = |column: &'static str| {
            header
                .iter()
                .position(|h| h == column)
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

/// One data row, with what error messages need.
struct Row<'a> {
    name: &'a str,
    line: usize,
    fields: &'a [&'a str],
}

impl Row<'_> {
    fn bad(&self, column: &'static str, found: &str, expected: &'static str) -> ImportError {
        ImportError::BadField {
            file: self.name.to_owned(),
            line: self.line,
            column,
            found: found.chars().take(60).collect(),
            expected,
        }
    }

    fn i64(
        &self,
        index: usize,
        column: &'static str,
        expected: &'static str,
    ) -> Result<i64, ImportError> {
        let text = self.fields[index];
        text.parse().map_err(|_| self.bad(column, text, expected))
    }

    fn f32(&self, index: usize, column: &'static str) -> Result<f32, ImportError> {
        let text = self.fields[index];
        text.parse()
            .map_err(|_| self.bad(column, text, "a decimal number"))
    }

    fn vec3(&self, index: [usize; 3], names: [&'static str; 3]) -> Result<Vec3, ImportError> {
        Ok(Vec3::new(
            self.f32(index[0], names[0])?,
            self.f32(index[1], names[1])?,
            self.f32(index[2], names[2])?,
        ))
    }

    /// A head pose vector: must be finite.
    fn finite_vec3(
        &self,
        index: [usize; 3],
        names: [&'static str; 3],
    ) -> Result<Vec3, ImportError> {
        let v = self.vec3(index, names)?;
        for (value, column) in v.to_array().into_iter().zip(names) {
            if !value.is_finite() {
                return Err(ImportError::NonFinite {
                    file: self.name.to_owned(),
                    line: self.line,
                    column,
                    value,
                });
            }
        }
        Ok(v)
    }

    /// One eye's ray in the OpenXR head frame.
    fn eye(&self, cols: &Columns, eye: usize) -> Result<GazeRay, ImportError> {
        let (valid_name, origin_names, direct_names) = if eye == 0 {
            (VALID_L, ORIGIN_L, DIRECT_L)
        } else {
            (VALID_R, ORIGIN_R, DIRECT_R)
        };
        let flags = self.i64(
            cols.valid[eye],
            valid_name,
            "an SRanipal validity bit mask (integer)",
        )?;
        if flags & i64::from(GAZE_VALID_MASK) != i64::from(GAZE_VALID_MASK) {
            // The tracker says it has no ray; its numbers are not read.
            return Ok(GazeRay::INVALID);
        }
        let origin_mm = self.vec3(cols.origin[eye], origin_names)?;
        let direction = self.vec3(cols.direct[eye], direct_names)?;
        Ok(sranipal_ray_to_openxr(origin_mm, direction))
    }
}

/// Converts an SRanipal gaze ray (origin in millimetres, +x to the wearer's left, +z forward)
/// into the OpenXR head frame (metres, +x right, -z forward). Non-finite values or a zero
/// direction give [`GazeRay::INVALID`].
pub fn sranipal_ray_to_openxr(origin_mm: Vec3, direction: Vec3) -> GazeRay {
    let flip = Vec3::new(-1.0, 1.0, -1.0);
    clean_ray(GazeRay {
        origin: origin_mm * flip / 1000.0,
        direction: direction * flip,
        valid: true,
    })
}

/// Converts a Unity head pose (left-handed world, +z forward; Euler angles in degrees applied
/// Z, then X, then Y) into the right-handed OpenXR frame by mirroring z.
pub fn unity_pose_to_openxr(position_m: Vec3, euler_deg: Vec3) -> Pose {
    let q = Quat::from_rotation_y(euler_deg.y.to_radians())
        * Quat::from_rotation_x(euler_deg.x.to_radians())
        * Quat::from_rotation_z(euler_deg.z.to_radians());
    Pose {
        position: Vec3::new(position_m.x, position_m.y, -position_m.z),
        orientation: Quat::from_xyzw(-q.x, -q.y, q.z, q.w).normalize(),
    }
}

/// The heading of an orientation: the angle about +y that turns -z toward the horizontal
/// direction the head faces. Looking straight up or down, the top of the head gives it.
pub fn heading_rad(orientation: Quat) -> f32 {
    let forward = orientation * Vec3::NEG_Z;
    let h = if forward.x * forward.x + forward.z * forward.z > 1e-6 {
        forward
    } else {
        let up = orientation * Vec3::Y;
        if forward.y < 0.0 { up } else { -up }
    };
    // Rotating -z by a about +y gives (-sin a, 0, -cos a).
    (-h.x).atan2(-h.z)
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
    fn push(&mut self, cols: &Columns, row: &Row<'_>) -> Result<(), ImportError> {
        let ticks = row.i64(cols.time, TIME, "an integer count of 100 ns ticks")?;
        let position = row.finite_vec3(cols.helmet_pos, HELMET_POS)?;
        let euler_deg = row.finite_vec3(cols.helmet_rot, HELMET_ROT)?;
        let left = row.eye(cols, 0)?;
        let right = row.eye(cols, 1)?;
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
                file: row.name.to_owned(),
                line: row.line,
                ticks,
                first_ticks: anchor.first_ticks,
            })?;
        if self.samples.last().is_some_and(|s| time_ns <= s.time_ns) {
            tracing::warn!(
                "{}:{}: time {} ticks is not after the previous row; row dropped",
                row.name,
                row.line,
                ticks
            );
            self.dropped_rows += 1;
            return Ok(());
        }
        let head_position = anchor.unyaw * (pose.position - anchor.position);
        if !head_position.is_finite() {
            return Err(ImportError::PositionRange {
                file: row.name.to_owned(),
                line: row.line,
                position_m: pose.position,
                first_m: anchor.position,
            });
        }
        self.samples.push(TraceSample {
            time_ns,
            head: Pose {
                position: head_position,
                orientation: (anchor.unyaw * pose.orientation).normalize(),
            },
            gaze: GazeSample {
                sample_time_ns: time_ns,
                left,
                right,
                combined: None,
                fixation: None,
            },
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

/// The median of sorted values (mean of the middle two for an even count).
fn median_sorted(v: &[f32]) -> Option<f32> {
    match v.len() {
        0 => None,
        n if n % 2 == 1 => Some(v[n / 2]),
        n => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn data(file: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/sranipal")
            .join(file)
    }

    const RECORDINGS: [&str; 3] = [
        "TESTNA01_2D_Fist3.csv",
        "TESTNA05_360VR_Spread7.csv",
        "TESTNA10_360VR_Fist3.csv",
    ];

    /// The minimal header the importer needs, in a different order from the real files.
    const MINI_HEADER: &str = "helmet_rot_x;helmet_rot_y;helmet_rot_z;helmet_pos_x;helmet_pos_y;helmet_pos_z;time(100ns);eye_valid_L;eye_valid_R;gaze_origin_L.x(mm);gaze_origin_L.y(mm);gaze_origin_L.z(mm);gaze_origin_R.x(mm);gaze_origin_R.y(mm);gaze_origin_R.z(mm);gaze_direct_L.x;gaze_direct_L.y;gaze_direct_L.z;gaze_direct_R.x;gaze_direct_R.y;gaze_direct_R.z";

    /// One row of the minimal CSV: head pose (Unity), ticks, both eyes valid looking ahead.
    fn mini_row(rot_deg: Vec3, pos_m: Vec3, ticks: i64) -> String {
        format!(
            "{};{};{};{};{};{};{ticks};31;31;32;0;-35;-32;0;-35;0;0;1;0;0;1",
            rot_deg.x, rot_deg.y, rot_deg.z, pos_m.x, pos_m.y, pos_m.z
        )
    }

    fn parse(text: &str) -> Result<(Vec<TraceSample>, ImportReport), ImportError> {
        parse_sranipal(text.as_bytes(), "mini.csv")
    }

    fn median(mut v: Vec<f32>) -> f32 {
        v.sort_by(f32::total_cmp);
        median_sorted(&v).unwrap()
    }

    #[test]
    fn real_recordings_have_plausible_ipd_and_forward_gaze() {
        for file in RECORDINGS {
            let (samples, report) = import_sranipal_with_report(data(file)).unwrap();
            eprintln!("{report}");
            assert!(samples.len() > 1000, "{report}");
            let ipd = report.median_ipd_mm.unwrap();
            // TESTNA10 has both eyes valid in only ~1% of rows: its median is not meaningful.
            let ipd_range = if report.right_valid_fraction > 0.5 {
                60.0..=72.0
            } else {
                50.0..=80.0
            };
            assert!(ipd_range.contains(&ipd), "{report}");
            let rate = report.mean_rate_hz().unwrap();
            assert!((100.0..150.0).contains(&rate), "{report}");
            // Forward in the head frame is -z.
            let valid: Vec<Vec3> = samples
                .iter()
                .flat_map(|s| [s.gaze.left, s.gaze.right])
                .filter(|r| r.valid)
                .map(|r| r.direction)
                .collect();
            let dz = median(valid.iter().map(|d| d.z).collect());
            assert!(dz < -0.9, "{file}: median gaze z {dz}");
            // The left eye sits at negative x.
            let lx = median(
                samples
                    .iter()
                    .filter(|s| s.gaze.left.valid)
                    .map(|s| s.gaze.left.origin.x)
                    .collect(),
            );
            assert!(lx < -0.02, "{file}: left eye x {lx}");
            // Re-anchored: starts at the origin, facing -z; times start at 0 and increase.
            assert_eq!(samples[0].time_ns, 0);
            assert!(samples[0].head.position.length() < 1e-6);
            assert!(heading_rad(samples[0].head.orientation).abs() < 1e-4);
            assert!(samples.windows(2).all(|w| w[0].time_ns < w[1].time_ns));
            assert!(samples.iter().all(|s| s.gaze.sample_time_ns == s.time_ns));
        }
    }

    #[test]
    fn mostly_invalid_recording_with_zero_head_pose_imports() {
        let (samples, report) =
            import_sranipal_with_report(data("TESTNA10_360VR_Fist3.csv")).unwrap();
        assert!(report.right_valid_fraction < 0.1, "{report}");
        assert!(report.left_valid_fraction > 0.5, "{report}");
        assert!(samples.iter().all(|s| s.head == Pose::IDENTITY));
    }

    #[test]
    fn header_only_recording_is_an_empty_trace() {
        let (samples, report) =
            import_sranipal_with_report(data("TESTVA03_2D_Spread9.csv")).unwrap();
        assert!(samples.is_empty());
        assert_eq!(report.rows, 0);
        assert_eq!(report.median_ipd_mm, None);
        assert!(report.to_string().contains("0 samples"));
    }

    #[test]
    fn gaze_is_converted_to_openxr_head_frame() {
        let text = format!("{MINI_HEADER}\n{}\n", mini_row(Vec3::ZERO, Vec3::ZERO, 5));
        let (s, _) = parse(&text).unwrap();
        let g = s[0].gaze;
        assert!(
            g.left
                .origin
                .abs_diff_eq(Vec3::new(-0.032, 0.0, 0.035), 1e-6)
        );
        assert!(
            g.right
                .origin
                .abs_diff_eq(Vec3::new(0.032, 0.0, 0.035), 1e-6)
        );
        assert_eq!(g.left.direction, Vec3::NEG_Z);
    }

    #[test]
    fn unity_yaw_right_stays_a_turn_right() {
        let text = format!(
            "{MINI_HEADER}\n{}\n{}\n{}\n",
            mini_row(Vec3::ZERO, Vec3::ZERO, 1000),
            mini_row(Vec3::new(0.0, 30.0, 0.0), Vec3::new(0.1, 0.0, 0.0), 2000),
            mini_row(Vec3::new(20.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.2), 3000),
        );
        let (s, _) = parse(&text).unwrap();
        assert_eq!(s[1].time_ns, 100_000);
        let forward = s[1].head.transform_vector(Vec3::NEG_Z);
        assert!(
            forward.abs_diff_eq(Vec3::new(0.5, 0.0, -(3f32.sqrt()) / 2.0), 1e-5),
            "{forward}"
        );
        assert!(
            s[1].head
                .position
                .abs_diff_eq(Vec3::new(0.1, 0.0, 0.0), 1e-6)
        );
        // Unity +x pitch tilts forward down; Unity +z forward is OpenXR -z.
        let forward = s[2].head.transform_vector(Vec3::NEG_Z);
        assert!(forward.y < -0.3 && forward.z < 0.0, "{forward}");
        assert!(
            s[2].head
                .position
                .abs_diff_eq(Vec3::new(0.0, 0.0, -0.2), 1e-6)
        );
    }

    #[test]
    fn initial_heading_is_removed_and_relative_motion_kept() {
        // Starts facing Unity +x (yaw 90), then turns 30 degrees further right and moves
        // 0.1 m along Unity +x, which is forward for this wearer.
        let text = format!(
            "{MINI_HEADER}\n{}\n{}\n",
            mini_row(Vec3::new(10.0, 90.0, 0.0), Vec3::new(1.0, 1.5, 2.0), 1000),
            mini_row(Vec3::new(10.0, 120.0, 0.0), Vec3::new(1.1, 1.5, 2.0), 2000),
        );
        let (s, report) = parse(&text).unwrap();
        assert!((report.removed_yaw_rad + std::f32::consts::FRAC_PI_2).abs() < 1e-5);
        assert!(s[0].head.position.length() < 1e-6);
        // Pitch (10 degrees down) is kept, heading removed.
        let f0 = s[0].head.transform_vector(Vec3::NEG_Z);
        assert!(
            f0.abs_diff_eq(
                Vec3::new(
                    0.0,
                    -(10f32.to_radians().sin()),
                    -(10f32.to_radians().cos())
                ),
                1e-5
            ),
            "{f0}"
        );
        assert!(
            s[1].head
                .position
                .abs_diff_eq(Vec3::new(0.0, 0.0, -0.1), 1e-5),
            "{}",
            s[1].head.position
        );
        assert!((heading_rad(s[1].head.orientation) + 30f32.to_radians()).abs() < 1e-4);
    }

    #[test]
    fn invalid_eye_flags_and_bad_rays_give_invalid_rays() {
        let row = mini_row(Vec3::ZERO, Vec3::ZERO, 1);
        let partly = row.replacen(";31;31;", ";25;24;", 1);
        let nan = mini_row(Vec3::ZERO, Vec3::ZERO, 2).replacen(";0;0;1;0;0;1", ";NaN;0;1;0;0;0", 1);
        let (s, report) = parse(&format!("{MINI_HEADER}\n{partly}\n{nan}\n")).unwrap();
        assert_eq!(s[0].gaze.left, GazeRay::INVALID);
        assert_eq!(s[0].gaze.right, GazeRay::INVALID);
        assert_eq!(s[1].gaze.left, GazeRay::INVALID);
        assert_eq!(s[1].gaze.right, GazeRay::INVALID);
        assert_eq!(report.median_ipd_mm, None);
    }

    #[test]
    fn malformed_rows_name_file_line_and_column() {
        let good = mini_row(Vec3::ZERO, Vec3::ZERO, 1);
        let bad_time = mini_row(Vec3::ZERO, Vec3::ZERO, 2).replacen(";2;", ";2x;", 1);
        let e = parse(&format!("{MINI_HEADER}\n{good}\n{bad_time}\n")).unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::BadField {
                    line: 3,
                    column: TIME,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().starts_with("mini.csv:3:"), "{e}");

        let short = format!("{MINI_HEADER}\n{good}\n\n1;2;3\n");
        let e = parse(&short).unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::FieldCount {
                    line: 4,
                    found: 3,
                    expected: 21,
                    ..
                }
            ),
            "{e}"
        );

        let nan_head = format!("{MINI_HEADER}\nNaN{}\n", &good[1..]);
        let e = parse(&nan_head).unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::NonFinite {
                    line: 2,
                    column: "helmet_rot_x",
                    ..
                }
            ),
            "{e}"
        );

        let e = parse("time(100ns);eye_valid_L\n").unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::MissingColumn {
                    line: 1,
                    column: "eye_valid_R",
                    ..
                }
            ),
            "{e}"
        );
        assert!(matches!(parse(""), Err(ImportError::Empty { .. })));
    }

    #[test]
    fn positions_too_far_apart_are_an_error_not_a_non_finite_pose() {
        let a = mini_row(Vec3::ZERO, Vec3::new(-3e38, 0.0, 0.0), 1);
        let b = mini_row(Vec3::ZERO, Vec3::new(3e38, 0.0, 0.0), 2);
        let e = parse(&format!("{MINI_HEADER}\n{a}\n{b}\n")).unwrap_err();
        assert!(
            matches!(e, ImportError::PositionRange { line: 3, .. }),
            "{e}"
        );
        assert!(
            e.to_string()
                .starts_with("mini.csv:3: columns `helmet_pos_*`"),
            "{e}"
        );
    }

    #[test]
    fn repeated_times_are_dropped_and_counted() {
        let a = mini_row(Vec3::ZERO, Vec3::ZERO, 10);
        let b = mini_row(Vec3::ZERO, Vec3::ZERO, 10);
        let c = mini_row(Vec3::ZERO, Vec3::ZERO, 5);
        let (s, report) = parse(&format!("{MINI_HEADER}\n{a}\n{b}\n{c}\n")).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!((report.rows, report.dropped_rows), (3, 2));
    }

    #[test]
    fn imported_trace_survives_the_trace_format() {
        let samples = import_sranipal(data("TESTNA01_2D_Fist3.csv")).unwrap();
        let mut w = crate::trace::TraceWriter::new(Vec::new()).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        let text = w.finish().unwrap();
        let back: Vec<TraceSample> = crate::trace::TraceReader::new(&text[..], "t")
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        assert_eq!(back, samples);
    }
}
