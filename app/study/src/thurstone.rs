//! Thurstone's law of comparative judgment, Case V (equal, uncorrelated discriminal
//! dispersions), with Mosteller's (1951) chi-square test of the fit.
//!
//! From the choice counts `C[i][j]` (how often `i` was preferred to `j`), the proportion
//! `p_ij = C[i][j] / (C[i][j] + C[j][i])` is clipped to [0.02, 0.98] so that unanimous pairs get a
//! finite normal deviate (z(0.98) ≈ 2.054); `z_ij = Φ⁻¹(p_ij)` with `z_ii = 0`, and the scale value
//! of `i` is the row mean of `z`, shifted so that the lowest condition sits at 0.
//!
//! Mosteller's test compares the observed proportions (unclipped) with those the scale predicts,
//! `p'_ij = Φ(S_i − S_j)`, after the arcsine transform θ = asin(√p) in degrees, whose variance is
//! about 821 / n for n judgments: χ² = Σ_{i<j} n_ij (θ_ij − θ'_ij)² / 821 on (k − 1)(k − 2) / 2
//! degrees of freedom.

use super::distributions::{chi_square_upper_tail, normal_cdf, normal_quantile};
use super::responses::{Answer, Choice, Responses};

/// Lower clip of the choice proportions (the upper clip is 1 − this).
pub const PROPORTION_CLIP: f64 = 0.02;
/// Mosteller's constant: the variance of asin(√p) in degrees is about 821 / n.
pub const ARCSINE_VARIANCE: f64 = 821.0;

/// Mosteller's chi-square test of the Case V fit.
#[derive(Debug, Clone, PartialEq)]
pub struct MostellerTest {
    /// The chi-square statistic.
    pub chi_square: f64,
    /// Degrees of freedom, (k − 1)(k − 2) / 2.
    pub df: usize,
    /// Upper-tail probability of the statistic; `None` when df = 0 (two conditions fit exactly).
    pub p: Option<f64>,
}

/// The result of a Case V analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseV {
    /// Condition names, in the order of every matrix and vector here.
    pub conditions: Vec<String>,
    /// `counts[i][j]`: how often `i` was preferred to `j`.
    pub counts: Vec<Vec<u64>>,
    /// `proportions[i][j]`: clipped proportion of judgments preferring `i` to `j` (0.5 on the
    /// diagonal).
    pub proportions: Vec<Vec<f64>>,
    /// Scale values, the lowest at 0.
    pub scale: Vec<f64>,
    /// Mosteller's test of the fit.
    pub test: MostellerTest,
}

/// Choice counts from forced-choice responses: `counts[i][j]` is how often the condition with
/// index `i` in `responses.conditions` was chosen over `j`. Ratings are ignored.
pub fn choice_counts(responses: &Responses) -> Vec<Vec<u64>> {
    let k = responses.conditions.len();
    let mut counts = vec![vec![0u64; k]; k];
    for row in &responses.rows {
        let (Some(first), Some(second)) = (
            responses.condition_index(&row.first),
            responses.condition_index(&row.second),
        ) else {
            continue;
        };
        match row.answer {
            Answer::Choice(Choice::First) => counts[first][second] += 1,
            Answer::Choice(Choice::Second) => counts[second][first] += 1,
            Answer::Rating(_) => {}
        }
    }
    counts
}

/// Case V scale values and Mosteller's test from a square matrix of choice counts. Pairs with no
/// judgments count as ties (p = 0.5) and add nothing to the chi-square.
pub fn case_v(conditions: Vec<String>, counts: Vec<Vec<u64>>) -> CaseV {
    let k = conditions.len();
    let mut proportions = vec![vec![0.5; k]; k];
    for i in 0..k {
        for j in 0..k {
            let n = counts[i][j] + counts[j][i];
            if i != j && n > 0 {
                let p = counts[i][j] as f64 / n as f64;
                proportions[i][j] = p.clamp(PROPORTION_CLIP, 1.0 - PROPORTION_CLIP);
            }
        }
    }
    let scale = scale_from_proportions(&proportions);
    let mut chi_square = 0.0;
    for i in 0..k {
        for j in i + 1..k {
            let n = counts[i][j] + counts[j][i];
            if n == 0 {
                continue;
            }
            let observed = counts[i][j] as f64 / n as f64;
            let predicted = normal_cdf(scale[i] - scale[j]);
            let difference = arcsine_degrees(observed) - arcsine_degrees(predicted);
            chi_square += n as f64 * difference * difference / ARCSINE_VARIANCE;
        }
    }
    let df = (k.saturating_sub(1) * k.saturating_sub(2)) / 2;
    let p = (df > 0).then(|| chi_square_upper_tail(chi_square, df as f64));
    CaseV {
        conditions,
        counts,
        proportions,
        scale,
        test: MostellerTest { chi_square, df, p },
    }
}

/// Case V scale values from a square matrix of proportions, `proportions[i][j]` the share of
/// judgments preferring `i` to `j` (already clipped away from 0 and 1): the row means of the
/// normal deviates, shifted so that the lowest is 0.
pub fn scale_from_proportions(proportions: &[Vec<f64>]) -> Vec<f64> {
    let k = proportions.len();
    let mut scale: Vec<f64> = proportions
        .iter()
        .map(|row| row.iter().map(|&p| normal_quantile(p)).sum::<f64>() / k as f64)
        .collect();
    let lowest = scale.iter().copied().fold(f64::INFINITY, f64::min);
    for value in &mut scale {
        *value -= lowest;
    }
    scale
}

/// Case V analysis of forced-choice responses.
pub fn analyze(responses: &Responses) -> CaseV {
    case_v(responses.conditions.clone(), choice_counts(responses))
}

/// asin(√p) in degrees.
fn arcsine_degrees(p: f64) -> f64 {
    p.clamp(0.0, 1.0).sqrt().asin().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(k: usize) -> Vec<String> {
        (0..k).map(|i| format!("c{i}")).collect()
    }

    #[test]
    fn three_conditions_by_hand() {
        // 10 judgments per pair: a over b 7 times, a over c 9, b over c 6.
        let counts = vec![vec![0, 7, 9], vec![3, 0, 6], vec![1, 4, 0]];
        let result = case_v(names(3), counts);
        // z(0.7) = 0.524401, z(0.9) = 1.281552, z(0.6) = 0.253347;
        // row means 0.601984, -0.090351, -0.511633; shifted by 0.511633.
        let expected = [1.113_617, 0.421_282, 0.0];
        for (value, want) in result.scale.iter().zip(expected) {
            assert!((value - want).abs() < 1e-5, "{:?}", result.scale);
        }
        assert_eq!(result.test.df, 1);
        // The chi-square from its definition with the predicted proportions Φ(S_i − S_j).
        let theta = |p: f64| p.sqrt().asin().to_degrees();
        let s = &result.scale;
        let chi: f64 = [(0.7, s[0] - s[1]), (0.9, s[0] - s[2]), (0.6, s[1] - s[2])]
            .iter()
            .map(|&(p, d)| 10.0 * (theta(p) - theta(normal_cdf(d))).powi(2) / 821.0)
            .sum();
        assert!((result.test.chi_square - chi).abs() < 1e-12);
        let p = result.test.p.unwrap();
        assert!((p - chi_square_upper_tail(chi, 1.0)).abs() < 1e-15 && p > 0.0 && p <= 1.0);
    }

    #[test]
    fn unanimous_pairs_are_clipped() {
        let result = case_v(names(2), vec![vec![0, 5], vec![0, 0]]);
        assert_eq!(result.proportions[0][1], 0.98);
        assert_eq!(result.proportions[1][0], 0.02);
        // Two conditions: the scale difference is z(0.98) and nothing is left to test.
        assert!((result.scale[0] - 2.053_748_910_631_823).abs() < 1e-9);
        assert_eq!(result.test.df, 0);
        assert_eq!(result.test.p, None);
    }

    #[test]
    fn mosteller_degrees_of_freedom() {
        for (k, df) in [(2, 0), (3, 1), (4, 3), (5, 6), (6, 10)] {
            let counts = vec![vec![5; k]; k];
            assert_eq!(case_v(names(k), counts).test.df, df);
        }
    }

    #[test]
    fn a_perfect_case_v_matrix_fits_exactly() {
        let truth = [0.0, 0.3, 0.8, 1.5];
        let n = 1_000_000.0;
        let counts: Vec<Vec<u64>> = (0..4)
            .map(|i| {
                (0..4)
                    .map(|j| (n * normal_cdf(truth[i] - truth[j])).round() as u64)
                    .collect()
            })
            .collect();
        let result = case_v(names(4), counts);
        for (value, want) in result.scale.iter().zip(truth) {
            assert!((value - want).abs() < 1e-4, "{:?}", result.scale);
        }
        assert!(result.test.chi_square < 1e-3);
    }

    /// Guilford's (1954, Psychometric Methods) preferences among nine vegetables, the classic
    /// worked example of Case V scaling, as distributed with the R package psychTools (`veg`):
    /// `VEG[j][i]` is the share preferring vegetable `j` to vegetable `i`. The published scale
    /// values (psych::thurstone on these data, two decimals, lowest at 0) are turnips 0.00,
    /// cabbage 0.52, beets 0.65, asparagus 0.98, carrots 1.12, spinach 1.14, string beans 1.40,
    /// peas 1.44, corn 1.63.
    #[allow(clippy::approx_constant)] // 0.318 is a measured proportion, not 1/pi
    const VEG: [[f64; 9]; 9] = [
        [
            0.500, 0.182, 0.230, 0.189, 0.122, 0.108, 0.101, 0.108, 0.074,
        ],
        [
            0.818, 0.500, 0.399, 0.277, 0.257, 0.264, 0.189, 0.155, 0.142,
        ],
        [
            0.770, 0.601, 0.500, 0.439, 0.264, 0.324, 0.155, 0.203, 0.182,
        ],
        [
            0.811, 0.723, 0.561, 0.500, 0.439, 0.412, 0.324, 0.399, 0.270,
        ],
        [
            0.878, 0.743, 0.736, 0.561, 0.500, 0.507, 0.426, 0.291, 0.236,
        ],
        [
            0.892, 0.736, 0.676, 0.588, 0.493, 0.500, 0.372, 0.318, 0.372,
        ],
        [
            0.899, 0.811, 0.845, 0.676, 0.574, 0.628, 0.500, 0.473, 0.358,
        ],
        [
            0.892, 0.845, 0.797, 0.601, 0.709, 0.682, 0.527, 0.500, 0.372,
        ],
        [
            0.926, 0.858, 0.818, 0.730, 0.764, 0.628, 0.642, 0.628, 0.500,
        ],
    ];

    #[test]
    fn case_v_reproduces_guilfords_vegetable_scale() {
        let published = [0.00, 0.52, 0.65, 0.98, 1.12, 1.14, 1.40, 1.44, 1.63];
        let proportions: Vec<Vec<f64>> = VEG.iter().map(|row| row.to_vec()).collect();
        let scale = scale_from_proportions(&proportions);
        for (value, want) in scale.iter().zip(published) {
            assert!((value - want).abs() <= 0.005 + 1e-9, "{scale:?}");
        }
    }

    #[test]
    fn scale_values_are_recovered_from_simulated_choices() {
        let truth = [0.0, 0.4, 0.7, 1.2, 1.3];
        let mut rng = vitreous_trace::synth::SplitMix64(14);
        let mut counts = vec![vec![0u64; 5]; 5];
        for i in 0..5 {
            for j in i + 1..5 {
                for _ in 0..2000 {
                    if rng.unit() < normal_cdf(truth[i] - truth[j]) {
                        counts[i][j] += 1;
                    } else {
                        counts[j][i] += 1;
                    }
                }
            }
        }
        let result = case_v(names(5), counts);
        for (value, want) in result.scale.iter().zip(truth) {
            assert!((value - want).abs() < 0.06, "{:?}", result.scale);
        }
        // The data follow Case V, so the test should not reject at the 1% level.
        assert!(result.test.p.unwrap() > 0.01, "{:?}", result.test);
    }
}
