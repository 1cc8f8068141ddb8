//! The synthetic viewer's pupils: each eye's diameter drifts slowly and smoothly between 3.5
//! and 5 mm (a sine of period [`PUPIL_PERIOD_S`], the right eye a little behind the left),
//! deterministic for a seed, so traces exercise a measured pupil the way a real tracker's
//! slowly changing readings would.

/// Mean pupil diameter, metres.
const PUPIL_MEAN_M: f32 = 0.004_25;
/// Amplitude of the drift, metres: the diameter stays within 3.5-5 mm.
const PUPIL_AMPLITUDE_M: f32 = 0.000_75;
/// Period of the drift, seconds.
pub const PUPIL_PERIOD_S: f32 = 8.0;
/// How far the right eye's drift lags the left's, radians.
const RIGHT_EYE_LAG_RAD: f32 = 0.4;

/// The left and right pupil diameters at `t_s` seconds into a trace of seed `seed`, metres.
pub fn pupil_diameters_m(seed: u64, t_s: f32) -> [f32; 2] {
    // The start phase comes from the seed: traces of other seeds drift out of step.
    let start_rad = (seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40) as f32 / (1u64 << 24) as f32
        * std::f32::consts::TAU;
    let angle = start_rad + std::f32::consts::TAU * t_s / PUPIL_PERIOD_S;
    [angle, angle - RIGHT_EYE_LAG_RAD].map(|a| PUPIL_MEAN_M + PUPIL_AMPLITUDE_M * a.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pupils_stay_plausible_and_drift_slowly_per_eye() {
        let mut last = pupil_diameters_m(7, 0.0);
        let (mut min, mut max) = (f32::MAX, f32::MIN);
        for k in 1..=1000 {
            let d = pupil_diameters_m(7, k as f32 * 0.03);
            for eye in 0..2 {
                assert!((0.0035 - 1e-6..=0.005 + 1e-6).contains(&d[eye]), "{d:?}");
                // At 30 Hz a sample moves at most 2 pi * 0.75 mm / 8 s / 30 Hz = 0.02 mm.
                assert!((d[eye] - last[eye]).abs() < 2e-5, "{d:?} after {last:?}");
                min = min.min(d[eye]);
                max = max.max(d[eye]);
            }
            assert_ne!(d[0], d[1]);
            last = d;
        }
        assert!(max - min > 0.0014, "the drift covers the range over 30 s");
        assert_eq!(pupil_diameters_m(7, 1.5), pupil_diameters_m(7, 1.5));
        assert_ne!(pupil_diameters_m(7, 1.5), pupil_diameters_m(8, 1.5));
    }
}
