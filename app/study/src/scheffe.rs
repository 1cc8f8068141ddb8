//! Scheffe's method of paired comparisons in Nakaya's variant: each of `N` participants rates
//! every ordered pair (i shown first, j second) of `t` conditions once, on -3..3, positive when the
//! first-shown condition was the more convincing.
//!
//! With `x_ijl` the rating of participant `l` for the ordered pair (i, j), `X_i·l = Σ_j x_ijl`,
//! `X_·il = Σ_j x_jil`, `X_ij· = Σ_l x_ijl`, `X_i·· = Σ_l X_i·l` and `X_·i· = Σ_l X_·il`:
//!
//! | source                     | sum of squares                                        | df                  |
//! |----------------------------|-------------------------------------------------------|---------------------|
//! | main effect α              | S_α = Σ_i (X_i·· − X_·i·)² / (2tN)                    | t − 1               |
//! | α × participant            | S_α(B) = Σ_l Σ_i (X_i·l − X_·il)² / (2t) − S_α        | (t − 1)(N − 1)      |
//! | combination effect γ       | S_γ = Σ_{i<j} (X_ij· − X_ji·)² / (2N) − S_α           | (t − 1)(t − 2) / 2  |
//! | order effect δ             | S_δ = Σ_{i<j} (X_ij· + X_ji·)² / (2N)                 | t(t − 1) / 2        |
//! | error                      | S_e = S_T − S_α − S_α(B) − S_γ − S_δ                  | (t − 1)²(N − 1)     |
//! | total                      | S_T = Σ x_ijl²                                         | t(t − 1)N           |
//!
//! The main-effect scale values are `α_i = (X_i·· − X_·i·) / (2tN)` (they sum to zero), each
//! effect's F is its mean square over the error mean square, and the yardstick for a pair of scale
//! values at level a is `Y(a) = q(a; t, df_e) · sqrt(MS_e / (2tN))` with `q` the upper point of the
//! studentized range: two conditions differ at level a when `|α_i − α_j| > Y(a)`.

use super::distributions::f_upper_tail;
use super::responses::{Answer, Responses};
use super::studentized;

/// The significance levels reported.
pub const LEVELS: [f64; 2] = [0.05, 0.01];

/// One line of the ANOVA table.
#[derive(Debug, Clone, PartialEq)]
pub struct AnovaRow {
    /// The source of variation.
    pub source: &'static str,
    /// Sum of squares.
    pub sum_of_squares: f64,
    /// Degrees of freedom.
    pub df: usize,
    /// Mean square, the sum of squares over df (`None` when df = 0).
    pub mean_square: Option<f64>,
    /// F ratio against the error mean square (`None` for the error and total rows, or when the
    /// error has no degrees of freedom or no variance).
    pub f: Option<f64>,
    /// Upper-tail probability of F.
    pub p: Option<f64>,
}

/// A pair of conditions compared against the yardsticks.
#[derive(Debug, Clone, PartialEq)]
pub struct PairTest {
    /// Index of the first condition.
    pub a: usize,
    /// Index of the second condition.
    pub b: usize,
    /// α_a − α_b.
    pub difference: f64,
    /// For each of [`LEVELS`], whether |difference| exceeds the yardstick.
    pub significant: [bool; 2],
}

/// The result of the analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Scheffe {
    /// Condition names, in the order of the scale values.
    pub conditions: Vec<String>,
    /// Number of participants.
    pub participants: usize,
    /// Main-effect scale values α_i.
    pub scale: Vec<f64>,
    /// The ANOVA table: main effect, main effect × participant, combination effect, order effect,
    /// error, total.
    pub anova: Vec<AnovaRow>,
    /// Y(0.05) and Y(0.01); `None` when the error has no degrees of freedom.
    pub yardsticks: Option<[f64; 2]>,
    /// Every unordered pair of conditions.
    pub pairs: Vec<PairTest>,
}

/// Nakaya's analysis from `ratings[l][i][j]`, participant `l`'s rating of condition `i` shown
/// before `j` (the diagonal is ignored). Needs at least two conditions and one participant.
pub fn nakaya(conditions: Vec<String>, ratings: &[Vec<Vec<f64>>]) -> Scheffe {
    let t = conditions.len();
    let n = ratings.len();
    let (tf, nf) = (t as f64, n as f64);
    let mut first_sum = vec![0.0; t];
    let mut second_sum = vec![0.0; t];
    let mut pair_sum = vec![vec![0.0; t]; t];
    let mut total = 0.0;
    let mut per_participant = 0.0;
    for participant in ratings {
        let mut first_l = vec![0.0; t];
        let mut second_l = vec![0.0; t];
        for i in 0..t {
            for j in (0..t).filter(|&j| j != i) {
                let x = participant[i][j];
                first_l[i] += x;
                second_l[j] += x;
                pair_sum[i][j] += x;
                total += x * x;
            }
        }
        per_participant += first_l
            .iter()
            .zip(&second_l)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            / (2.0 * tf);
        for i in 0..t {
            first_sum[i] += first_l[i];
            second_sum[i] += second_l[i];
        }
    }
    let differences: Vec<f64> = first_sum
        .iter()
        .zip(&second_sum)
        .map(|(a, b)| a - b)
        .collect();
    let scale: Vec<f64> = differences.iter().map(|d| d / (2.0 * tf * nf)).collect();
    let main = differences.iter().map(|d| d * d).sum::<f64>() / (2.0 * tf * nf);
    let mut antisymmetric = 0.0;
    let mut order = 0.0;
    for (i, row) in pair_sum.iter().enumerate() {
        for (j, &forward) in row.iter().enumerate().skip(i + 1) {
            antisymmetric += (forward - pair_sum[j][i]).powi(2);
            order += (forward + pair_sum[j][i]).powi(2);
        }
    }
    let combination = antisymmetric / (2.0 * nf) - main;
    let order = order / (2.0 * nf);
    let main_by_participant = per_participant - main;
    let error = total - main - main_by_participant - combination - order;
    let df_error = (t - 1) * (t - 1) * n.saturating_sub(1);
    let ms_error = (df_error > 0).then(|| error / df_error as f64);
    let row = |source, sum_of_squares: f64, df: usize| {
        let mean_square = (df > 0).then(|| sum_of_squares / df as f64);
        let f = match (mean_square, ms_error) {
            (Some(ms), Some(mse)) if mse > 0.0 => Some(ms / mse),
            _ => None,
        };
        let p = f.map(|f| f_upper_tail(f, df as f64, df_error as f64));
        AnovaRow {
            source,
            sum_of_squares,
            df,
            mean_square,
            f,
            p,
        }
    };
    let anova = vec![
        row("main effect", main, t - 1),
        row(
            "main effect x participant",
            main_by_participant,
            (t - 1) * n.saturating_sub(1),
        ),
        row("combination effect", combination, (t - 1) * (t - 2) / 2),
        row("order effect", order, t * (t - 1) / 2),
        AnovaRow {
            source: "error",
            sum_of_squares: error,
            df: df_error,
            mean_square: ms_error,
            f: None,
            p: None,
        },
        AnovaRow {
            source: "total",
            sum_of_squares: total,
            df: t * (t - 1) * n,
            mean_square: None,
            f: None,
            p: None,
        },
    ];
    let yardsticks = ms_error.map(|mse| {
        let unit = (mse / (2.0 * tf * nf)).sqrt();
        LEVELS.map(|level| studentized::quantile(level, t, df_error as f64) * unit)
    });
    let mut pairs = Vec::new();
    for a in 0..t {
        for b in a + 1..t {
            let difference = scale[a] - scale[b];
            let significant = yardsticks.map_or([false; 2], |y| y.map(|y| difference.abs() > y));
            pairs.push(PairTest {
                a,
                b,
                difference,
                significant,
            });
        }
    }
    Scheffe {
        conditions,
        participants: n,
        scale,
        anova,
        yardsticks,
        pairs,
    }
}

/// The analysis of rating responses (the design is already checked complete by
/// [`Responses::parse`]).
pub fn analyze(responses: &Responses) -> Scheffe {
    let t = responses.conditions.len();
    let mut ratings = vec![vec![vec![0.0; t]; t]; responses.participants.len()];
    for row in &responses.rows {
        let (Ok(l), Some(i), Some(j), Answer::Rating(x)) = (
            responses.participants.binary_search(&row.participant),
            responses.condition_index(&row.first),
            responses.condition_index(&row.second),
            row.answer,
        ) else {
            continue;
        };
        ratings[l][i][j] = f64::from(x);
    }
    nakaya(responses.conditions.clone(), &ratings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(t: usize) -> Vec<String> {
        (0..t).map(|i| format!("c{i}")).collect()
    }

    fn sum_of_squares(result: &Scheffe, source: &str) -> f64 {
        result
            .anova
            .iter()
            .find(|row| row.source == source)
            .map(|row| row.sum_of_squares)
            .unwrap()
    }

    #[test]
    fn two_conditions_three_participants_by_hand() {
        // (c0 then c1, c1 then c0) per participant: (2, -1), (1, 0), (0, 0).
        let ratings = vec![
            vec![vec![0.0, 2.0], vec![-1.0, 0.0]],
            vec![vec![0.0, 1.0], vec![0.0, 0.0]],
            vec![vec![0.0, 0.0], vec![0.0, 0.0]],
        ];
        let r = nakaya(names(2), &ratings);
        // X_0·· − X_·0· = 3 − (−1) = 4, so α = ±4 / (2·2·3).
        assert!((r.scale[0] - 1.0 / 3.0).abs() < 1e-12 && (r.scale[1] + 1.0 / 3.0).abs() < 1e-12);
        let expected = [
            ("main effect", 8.0 / 3.0, 1),
            ("main effect x participant", 7.0 / 3.0, 2),
            ("combination effect", 0.0, 0),
            ("order effect", 2.0 / 3.0, 1),
            ("error", 1.0 / 3.0, 2),
            ("total", 6.0, 6),
        ];
        for (row, (source, ss, df)) in r.anova.iter().zip(expected) {
            assert_eq!((row.source, row.df), (source, df));
            assert!((row.sum_of_squares - ss).abs() < 1e-12, "{row:?}");
        }
        // F = (8/3) / (1/6) = 16 on (1, 2) df; F(1, 2) is t² on 2 df: p = 1 − 4/√18.
        let main = &r.anova[0];
        assert!((main.f.unwrap() - 16.0).abs() < 1e-12);
        assert!((main.p.unwrap() - (1.0 - 4.0 / 18f64.sqrt())).abs() < 1e-9);
        // q(0.05; 2, 2) = √2 · t(0.975; 2) = √2 · 4.302653; Y = q · sqrt((1/6) / 12) = 0.717113.
        let y = r.yardsticks.unwrap();
        assert!((y[0] - 0.717_113).abs() < 1e-3, "{y:?}");
        assert_eq!(r.pairs.len(), 1);
        assert!((r.pairs[0].difference - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(r.pairs[0].significant, [false, false]);
    }

    #[test]
    fn sums_of_squares_add_up_and_the_error_is_the_residual() {
        let (t, n) = (4, 5);
        let mut rng = vitreous_trace::synth::SplitMix64(7);
        let ratings: Vec<Vec<Vec<f64>>> = (0..n)
            .map(|_| {
                (0..t)
                    .map(|_| (0..t).map(|_| (rng.unit() * 7.0).floor() - 3.0).collect())
                    .collect()
            })
            .collect();
        let r = nakaya(names(t), &ratings);
        let parts: f64 = r.anova[..5].iter().map(|row| row.sum_of_squares).sum();
        assert!((parts - sum_of_squares(&r, "total")).abs() < 1e-9);
        let dfs: usize = r.anova[..5].iter().map(|row| row.df).sum();
        assert_eq!(dfs, t * (t - 1) * n);
        assert!(r.anova[..5].iter().all(|row| row.sum_of_squares > -1e-9));
        // The error is what no effect explains: fit per-participant main effects, the
        // combination effects and the order effects, and sum the squared residuals.
        let (tf, nf) = (t as f64, n as f64);
        let mut pair = vec![vec![0.0; t]; t];
        for x in &ratings {
            for i in 0..t {
                for j in 0..t {
                    pair[i][j] += x[i][j];
                }
            }
        }
        let mut residual = 0.0;
        for x in &ratings {
            let a: Vec<f64> = (0..t)
                .map(|i| {
                    (0..t)
                        .filter(|&j| j != i)
                        .map(|j| x[i][j] - x[j][i])
                        .sum::<f64>()
                        / (2.0 * tf)
                })
                .collect();
            for i in 0..t {
                for j in (0..t).filter(|&j| j != i) {
                    let gamma = (pair[i][j] - pair[j][i]) / (2.0 * nf) - (r.scale[i] - r.scale[j]);
                    let delta = (pair[i][j] + pair[j][i]) / (2.0 * nf);
                    let fitted = a[i] - a[j] + gamma + delta;
                    residual += (x[i][j] - fitted).powi(2);
                }
            }
        }
        assert!(
            (residual - sum_of_squares(&r, "error")).abs() < 1e-9,
            "{residual} vs {r:?}"
        );
    }

    #[test]
    fn scale_values_are_recovered_from_simulated_ratings() {
        let truth = [-0.6, -0.2, 0.0, 0.3, 0.5];
        let (t, n) = (5, 60);
        let mut rng = vitreous_trace::synth::SplitMix64(99);
        let ratings: Vec<Vec<Vec<f64>>> = (0..n)
            .map(|_| {
                (0..t)
                    .map(|i| {
                        (0..t)
                            .map(|j| truth[i] - truth[j] + 0.2 + 0.8 * rng.gaussian())
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let r = nakaya(names(t), &ratings);
        for (value, want) in r.scale.iter().zip(truth) {
            assert!((value - want).abs() < 0.05, "{:?}", r.scale);
        }
        // The order effect (0.2 everywhere) is detected; the largest gap is significant at 1%.
        let order = &r.anova[3];
        assert!(order.p.unwrap() < 0.01, "{order:?}");
        let widest = r.pairs.iter().find(|p| (p.a, p.b) == (0, 4)).unwrap();
        assert_eq!(widest.significant, [true, true]);
    }

    #[test]
    fn the_papers_yardsticks_are_consistent_with_the_studentized_range() {
        // The paper reports Y(0.05) = 0.2061 and Y(0.01) = 0.2466 for t = 5 conditions and
        // 21-23 participants. Y(a) = q(a; t, df) · sqrt(MS_e / (2tN)), so the ratio of the two
        // yardsticks is q(0.01; 5, df) / q(0.05; 5, df), whatever MS_e was.
        let ratio = 0.2466 / 0.2061;
        let q_ratio =
            |df: f64| studentized::quantile(0.01, 5, df) / studentized::quantile(0.05, 5, df);
        // With the design's error df, (t − 1)²(N − 1) = 320..352, the quantile ratio matches
        // the paper's to within the rounding of its 4-decimal yardsticks (about ±3e-4):
        // q(0.05; 5, 320) = 3.8797, q(0.01; 5, 320) = 4.6420, ratio 1.19648 against 1.19651.
        for n in [21.0, 22.0, 23.0] {
            let df = 16.0 * (n - 1.0);
            assert!((q_ratio(df) - ratio).abs() < 5e-4, "N {n}: {}", q_ratio(df));
        }
        // A much smaller error df would not match: the check can tell them apart.
        assert!(q_ratio(60.0) - ratio > 0.01 && q_ratio(120.0) - ratio > 0.005);
        // The MS_e that Y(0.05) implies for N = 21 (df 320), (Y / q)² · 2tN, reproduces Y(0.01).
        let q05 = studentized::quantile(0.05, 5, 320.0);
        let ms_error = (0.2061 / q05).powi(2) * 2.0 * 5.0 * 21.0;
        assert!((ms_error - 0.5926).abs() < 1e-3, "MS_e {ms_error}");
        let y01 = studentized::quantile(0.01, 5, 320.0) * (ms_error / (2.0 * 5.0 * 21.0)).sqrt();
        assert!(
            (y01 - 0.2466).abs() < 1e-4,
            "Y(0.01) {y01} from MS_e {ms_error}"
        );
    }
}
