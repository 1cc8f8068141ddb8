//! The summary of an import, for a CLI to print.

use std::fmt;

use glam::Vec3;

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

/// The median of sorted values (mean of the middle two for an even count).
pub(super) fn median_sorted(v: &[f32]) -> Option<f32> {
    match v.len() {
        0 => None,
        n if n % 2 == 1 => Some(v[n / 2]),
        n => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
    }
}
