//! The summary of a Tobii Pro Glasses 3 or Neon import, for a CLI to print.

use std::fmt;

use glam::Vec3;

use crate::format::TraceSample;

/// Where the head orientation of an imported trace comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeadSource {
    /// No IMU data: the head stays at the identity pose.
    None,
    /// Integrated from gyroscope rates (Tobii Pro Glasses 3); drifts.
    Gyroscope {
        /// Gyroscope records used.
        records: usize,
    },
    /// The IMU's own fused orientation quaternions (Neon).
    ImuOrientation {
        /// IMU records used.
        records: usize,
    },
}

/// A summary of an import: what was read, what was written, and what was approximated.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordingReport {
    /// The recording format, in words.
    pub format: &'static str,
    /// The gaze file (Tobii) or recording folder (Neon).
    pub file: String,
    /// Gaze records read (JSON lines of type `gaze`, or `.raw` records).
    pub records: usize,
    /// Samples in the imported trace.
    pub samples: usize,
    /// Records dropped because their time was not after the previous kept record's.
    pub dropped_records: usize,
    /// Lines skipped because they hold something other than gaze (Tobii `type` not `gaze`).
    pub skipped_lines: usize,
    /// Samples with neither eye valid (tracking loss, blinks).
    pub lost_samples: usize,
    /// Samples with exactly one eye valid.
    pub one_eye_samples: usize,
    /// Samples inside a blink the recording marks (Neon's blink detector); 0 for Tobii.
    pub blink_samples: usize,
    /// Pupil diameters outside 1-10 mm, left out of the trace (written as unknown).
    pub pupils_out_of_range: usize,
    /// Fraction of samples whose left eye is valid (0 when there are no samples).
    pub left_valid_fraction: f64,
    /// Fraction of samples whose right eye is valid (0 when there are no samples).
    pub right_valid_fraction: f64,
    /// Median distance between the two eye origins where both are valid, millimetres.
    pub median_ipd_mm: Option<f32>,
    /// Time from the first to the last sample, seconds.
    pub duration_s: f64,
    /// Where the head frame's origin, the middle of the eyes, lies from the scene camera
    /// (OpenXR axes, metres); `None` when no sample has both eyes valid and the origin stays
    /// at the scene camera.
    pub head_origin_m: Option<Vec3>,
    /// Where the head orientation comes from.
    pub head: HeadSource,
    /// What the import had to assume or approximate, one sentence each.
    pub approximations: Vec<String>,
}

impl RecordingReport {
    /// A report with the sample statistics of `samples` filled in and the counts at zero.
    pub(crate) fn from_samples(
        format: &'static str,
        file: String,
        samples: &[TraceSample],
    ) -> RecordingReport {
        let n = samples.len();
        let fraction = |count: usize| if n == 0 { 0.0 } else { count as f64 / n as f64 };
        let valid =
            |s: &TraceSample| usize::from(s.gaze.left.valid) + usize::from(s.gaze.right.valid);
        let left = samples.iter().filter(|s| s.gaze.left.valid).count();
        let right = samples.iter().filter(|s| s.gaze.right.valid).count();
        let mut ipds_mm: Vec<f32> = samples
            .iter()
            .filter(|s| valid(s) == 2)
            .map(|s| s.gaze.left.origin.distance(s.gaze.right.origin) * 1000.0)
            .collect();
        ipds_mm.sort_by(f32::total_cmp);
        let median_ipd_mm = match ipds_mm.len() {
            0 => None,
            k if k % 2 == 1 => Some(ipds_mm[k / 2]),
            k => Some((ipds_mm[k / 2 - 1] + ipds_mm[k / 2]) / 2.0),
        };
        let duration_s = match (samples.first(), samples.last()) {
            (Some(a), Some(b)) => (b.time_ns - a.time_ns) as f64 * 1e-9,
            _ => 0.0,
        };
        RecordingReport {
            format,
            file,
            records: 0,
            samples: n,
            dropped_records: 0,
            skipped_lines: 0,
            lost_samples: samples.iter().filter(|s| valid(s) == 0).count(),
            one_eye_samples: samples.iter().filter(|s| valid(s) == 1).count(),
            blink_samples: 0,
            pupils_out_of_range: 0,
            left_valid_fraction: fraction(left),
            right_valid_fraction: fraction(right),
            median_ipd_mm,
            duration_s,
            head_origin_m: None,
            head: HeadSource::None,
            approximations: Vec::new(),
        }
    }

    /// Sample rate implied by the sample count and duration, hertz (`None` below 2 samples).
    pub fn mean_rate_hz(&self) -> Option<f64> {
        (self.samples >= 2 && self.duration_s > 0.0)
            .then(|| (self.samples - 1) as f64 / self.duration_s)
    }
}

impl fmt::Display for RecordingReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}): {} gaze records -> {} samples",
            self.file, self.format, self.records, self.samples
        )?;
        if self.dropped_records > 0 {
            write!(
                f,
                " ({} dropped: time not increasing)",
                self.dropped_records
            )?;
        }
        if self.skipped_lines > 0 {
            write!(f, ", {} non-gaze lines skipped", self.skipped_lines)?;
        }
        write!(f, ", {:.2} s", self.duration_s)?;
        if let Some(rate) = self.mean_rate_hz() {
            write!(f, " (~{rate:.0} Hz)")?;
        }
        write!(
            f,
            ", valid eyes L {:.1}% R {:.1}%, {} samples without a valid eye, {} with one",
            self.left_valid_fraction * 100.0,
            self.right_valid_fraction * 100.0,
            self.lost_samples,
            self.one_eye_samples
        )?;
        if self.blink_samples > 0 {
            write!(f, " ({} inside marked blinks)", self.blink_samples)?;
        }
        if self.pupils_out_of_range > 0 {
            write!(
                f,
                ", {} pupil diameters outside 1-10 mm left out",
                self.pupils_out_of_range
            )?;
        }
        match self.median_ipd_mm {
            Some(ipd) => write!(f, ", median eye distance {ipd:.1} mm")?,
            None => write!(f, ", eye distance unknown (no sample with both eyes valid)")?,
        }
        match self.head_origin_m {
            Some(o) => write!(
                f,
                "; head origin: middle of the eyes, ({:.1}, {:.1}, {:.1}) mm from the scene camera",
                o.x * 1000.0,
                o.y * 1000.0,
                o.z * 1000.0
            )?,
            None => write!(f, "; head origin: the scene camera")?,
        }
        match self.head {
            HeadSource::None => write!(f, "; head: no IMU data, identity pose")?,
            HeadSource::Gyroscope { records } => write!(
                f,
                "; head: rotation integrated from {records} gyroscope records"
            )?,
            HeadSource::ImuOrientation { records } => {
                write!(f, "; head: rotation from {records} IMU orientation records")?
            }
        }
        for note in &self.approximations {
            write!(f, "\n  approximated: {note}")?;
        }
        Ok(())
    }
}
