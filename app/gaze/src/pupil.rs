//! The pupil diameter A_p of eq. 13-14: a fixed value (the paper's 6 mm unless the scene's
//! `[viewer] pupil_diameter_mm` or `--pupil` says otherwise), or the eye tracker's measurement,
//! smoothed (`[gaze] pupil = "measured"`).
//!
//! # The measured pupil's filter
//! Each tracker sample is taken once, however many frames see it (by its `sample_time_ns`,
//! like the depth filter). Of its two per-eye diameters, those inside 1-9 mm (the range
//! [`check_pupil_diameter_m`] accepts; anything else is a tracker error or a unit mistake) are
//! averaged; a sample with neither is skipped. The averages feed an exponential moving average
//! over sample time with time constant [`PUPIL_SMOOTHING_S`] (0.5 s): a new value `x` arriving
//! `dt` after the previous measurement moves the estimate by `(x - estimate) * (1 -
//! exp(-dt / 0.5 s))`, so a step change is 63 % through after 0.5 s and 95 % after 1.5 s at
//! any tracker rate. The first valid measurement is taken as it is. Until it arrives the fixed
//! value is used.

use std::fmt;
use std::str::FromStr;

use thiserror::Error;
use vitreous_trace::GazeSample;

use super::blur::check_pupil_diameter_m;

/// Time constant of the measured pupil's exponential moving average, seconds.
pub const PUPIL_SMOOTHING_S: f32 = 0.5;

/// Where A_p comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PupilSource {
    /// The fixed diameter: `[viewer] pupil_diameter_mm` (the paper's 6 mm by default) or
    /// `--pupil`.
    #[default]
    Paper,
    /// The tracker's per-eye diameters, smoothed; the fixed one until the first measurement.
    Measured,
}

impl fmt::Display for PupilSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PupilSource::Paper => "paper",
            PupilSource::Measured => "measured",
        })
    }
}

/// A pupil source name that could not be read.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("pupil source `{0}`: expected `paper` or `measured`")]
pub struct PupilSourceParseError(
    /// The text given.
    pub String,
);

impl FromStr for PupilSource {
    type Err = PupilSourceParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "paper" => Ok(PupilSource::Paper),
            "measured" => Ok(PupilSource::Measured),
            _ => Err(PupilSourceParseError(s.to_owned())),
        }
    }
}

/// The pupil diameter a frame uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PupilEstimate {
    /// A_p, metres.
    pub diameter_m: f32,
    /// Whether it comes from measurements (false: the fixed value).
    pub measured: bool,
}

/// A_p frame by frame: the fixed value, or the smoothed measurement (module docs).
#[derive(Clone, Copy, Debug)]
pub struct PupilFilter {
    /// Where A_p comes from.
    source: PupilSource,
    /// The fixed diameter, metres (also the measured source's value before a measurement).
    fixed_m: f32,
    /// The smoothed measurement, metres, once there is one.
    smoothed_m: Option<f32>,
    /// Sample time of the newest tracker sample taken (each is taken once).
    last_sample_ns: Option<i64>,
    /// Sample time of the newest sample with a valid measurement.
    last_measured_ns: Option<i64>,
    /// Tracker samples with at least one valid diameter taken so far.
    measured_samples: u64,
}

impl PupilFilter {
    /// A filter with no history; `fixed_m` is the fixed diameter, metres.
    pub fn new(source: PupilSource, fixed_m: f32) -> PupilFilter {
        PupilFilter {
            source,
            fixed_m,
            smoothed_m: None,
            last_sample_ns: None,
            last_measured_ns: None,
            measured_samples: 0,
        }
    }

    /// Where A_p comes from.
    pub fn source(&self) -> PupilSource {
        self.source
    }

    /// Tracker samples with at least one valid diameter taken so far (measured source only).
    pub fn measured_samples(&self) -> u64 {
        self.measured_samples
    }

    /// A_p for a frame whose newest tracker sample is `gaze`.
    pub fn update(&mut self, gaze: Option<&GazeSample>) -> PupilEstimate {
        if self.source == PupilSource::Measured
            && let Some(sample) = gaze
            && self
                .last_sample_ns
                .is_none_or(|t| sample.sample_time_ns > t)
        {
            self.last_sample_ns = Some(sample.sample_time_ns);
            if let Some(x) = mean_valid_diameter_m(sample) {
                self.measured_samples += 1;
                let t = sample.sample_time_ns;
                self.smoothed_m = Some(match (self.smoothed_m, self.last_measured_ns) {
                    (Some(old), Some(before)) => {
                        let dt_s = (t.saturating_sub(before)) as f32 * 1e-9;
                        let weight = 1.0 - (-dt_s / PUPIL_SMOOTHING_S).exp();
                        old + (x - old) * weight
                    }
                    _ => x,
                });
                self.last_measured_ns = Some(t);
            }
        }
        match self.smoothed_m {
            Some(diameter_m) => PupilEstimate {
                diameter_m,
                measured: true,
            },
            None => PupilEstimate {
                diameter_m: self.fixed_m,
                measured: false,
            },
        }
    }
}

/// The mean of a sample's per-eye diameters that are inside 1-9 mm; `None` when neither is.
fn mean_valid_diameter_m(sample: &GazeSample) -> Option<f32> {
    let valid: Vec<f32> = sample
        .pupil_diameter_m
        .iter()
        .flatten()
        .copied()
        .filter(|&d| check_pupil_diameter_m(d).is_ok())
        .collect();
    (!valid.is_empty()).then(|| valid.iter().sum::<f32>() / valid.len() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t_ms: i64, pupils_mm: [Option<f32>; 2]) -> GazeSample {
        GazeSample {
            pupil_diameter_m: pupils_mm.map(|p| p.map(|mm| mm / 1000.0)),
            ..GazeSample::none(t_ms * 1_000_000)
        }
    }

    #[test]
    fn paper_source_ignores_measurements() {
        let mut f = PupilFilter::new(PupilSource::Paper, 0.006);
        let e = f.update(Some(&sample(0, [Some(3.0), Some(3.0)])));
        assert_eq!(
            e,
            PupilEstimate {
                diameter_m: 0.006,
                measured: false
            }
        );
        assert_eq!(f.measured_samples(), 0);
    }

    #[test]
    fn measured_source_falls_back_then_averages_eyes_and_smooths_over_sample_time() {
        let mut f = PupilFilter::new(PupilSource::Measured, 0.006);
        assert_eq!(f.update(None).diameter_m, 0.006);
        // Implausible values and missing eyes are no measurement.
        let e = f.update(Some(&sample(0, [Some(12.0), Some(0.5)])));
        assert!(!e.measured && e.diameter_m == 0.006);
        let e = f.update(Some(&sample(10, [Some(3.0), Some(5.0)])));
        assert!(e.measured && (e.diameter_m - 0.004).abs() < 1e-7, "{e:?}");
        // The same sample seen by another frame is not taken again.
        let e = f.update(Some(&sample(10, [Some(8.0), Some(8.0)])));
        assert!((e.diameter_m - 0.004).abs() < 1e-7);
        assert_eq!(f.measured_samples(), 1);
        // A step to 6 mm, one eye only, 0.5 s later: 63 % of the way.
        let e = f.update(Some(&sample(510, [None, Some(6.0)])));
        let expected = 0.004 + 0.002 * (1.0 - (-1.0f32).exp());
        assert!((e.diameter_m - expected).abs() < 1e-6, "{e:?}");
        // Held through samples without a measurement (a blink).
        let e = f.update(Some(&sample(520, [None, None])));
        assert!(e.measured && (e.diameter_m - expected).abs() < 1e-6);
        assert_eq!(f.measured_samples(), 2);
    }

    #[test]
    fn source_names_parse() {
        for s in [PupilSource::Paper, PupilSource::Measured] {
            assert_eq!(s.to_string().parse::<PupilSource>().unwrap(), s);
        }
        assert!("tracker".parse::<PupilSource>().is_err());
    }
}
