//! The studentized range distribution: the range of `k` independent standard normal variables
//! divided by an independent estimate of their standard deviation on `df` degrees of freedom.
//!
//! The CDF is the double integral of Copenhaver and Holland (1988), also used by Lund and Lund
//! (1983):
//!
//! ```text
//! W(w)       = k ∫ φ(z) [Φ(z) − Φ(z − w)]^(k−1) dz          (range of k normals below w)
//! P(q; k, ν) = ∫_0^∞ f_ν(s) W(q s) ds,   f_ν(s) = ν^(ν/2) s^(ν−1) e^(−ν s²/2) / (Γ(ν/2) 2^(ν/2−1))
//! ```
//!
//! where `f_ν` is the density of `s = sqrt(χ²_ν / ν)`. Both integrals are evaluated by composite
//! Gauss-Legendre quadrature; for ν = ∞ the estimate is exact (s = 1) and P = W(q). The quantile
//! inverts the CDF by the Illinois variant of regula falsi on a bracket (each CDF costs about
//! 10^5 normal CDFs, and the smooth, monotone CDF converges in a handful of steps where
//! bisection takes two dozen).

use super::distributions::{ln_gamma, normal_cdf, normal_pdf};

/// Gauss-Legendre points per panel.
const POINTS: usize = 10;
/// Panels of the inner integral over z ∈ [-Z_LIMIT, Z_LIMIT].
const INNER_PANELS: usize = 24;
/// Half-width of the inner integration range: φ(8.5) · 8.5 is below 1e-15.
const Z_LIMIT: f64 = 8.5;
/// Panels of the outer integral over the chi density.
const OUTER_PANELS: usize = 40;

/// Nodes and weights of the `n`-point Gauss-Legendre rule on [-1, 1]: the roots of the Legendre
/// polynomial P_n by Newton's method from the Chebyshev-like start cos(π (i − 1/4) / (n + 1/2)),
/// with weights 2 / ((1 − x²) P_n'(x)²).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 1..=n {
        let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            // Three-term recurrence: (j + 1) P_{j+1} = (2j + 1) x P_j − j P_{j−1}.
            let (mut previous, mut current) = (1.0, x);
            for j in 1..n {
                let j = j as f64;
                let next = ((2.0 * j + 1.0) * x * current - j * previous) / (j + 1.0);
                previous = current;
                current = next;
            }
            derivative = n as f64 * (x * current - previous) / (x * x - 1.0);
            let step = current / derivative;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * derivative * derivative)));
    }
    rule
}

/// Composite Gauss-Legendre nodes and weights on [a, b] with `panels` equal panels.
fn composite_rule(a: f64, b: f64, panels: usize) -> Vec<(f64, f64)> {
    let base = gauss_legendre(POINTS);
    let width = (b - a) / panels as f64;
    let mut rule = Vec::with_capacity(panels * POINTS);
    for panel in 0..panels {
        let centre = a + width * (panel as f64 + 0.5);
        for &(x, w) in &base {
            rule.push((centre + 0.5 * width * x, 0.5 * width * w));
        }
    }
    rule
}

/// The inner integral W(w) for `k` normals on a prepared rule: (z, weight, φ(z), Φ(z)).
fn range_cdf(w: f64, k: usize, inner: &[(f64, f64, f64, f64)]) -> f64 {
    if w <= 0.0 {
        return 0.0;
    }
    let sum: f64 = inner
        .iter()
        .map(|&(z, weight, pdf, cdf)| {
            let inside = (cdf - normal_cdf(z - w)).max(0.0);
            weight * pdf * inside.powi(k as i32 - 1)
        })
        .sum();
    (k as f64 * sum).min(1.0)
}

/// The inner rule with φ and Φ evaluated once per node.
fn inner_rule() -> Vec<(f64, f64, f64, f64)> {
    composite_rule(-Z_LIMIT, Z_LIMIT, INNER_PANELS)
        .into_iter()
        .map(|(z, w)| (z, w, normal_pdf(z), normal_cdf(z)))
        .collect()
}

/// CDF of the studentized range, P(Q <= q) for `k >= 2` means and `df` error degrees of freedom
/// (`f64::INFINITY` for a known standard deviation). Returns NaN for `k < 2` or `df <= 0`.
pub fn cdf(q: f64, k: usize, df: f64) -> f64 {
    if k < 2 || df.is_nan() || df <= 0.0 {
        return f64::NAN;
    }
    if q <= 0.0 {
        return 0.0;
    }
    let inner = inner_rule();
    if df.is_infinite() {
        return range_cdf(q, k, &inner);
    }
    // s = sqrt(χ²_ν / ν): mean and standard deviation from the gamma function; the density is
    // negligible (below e^-40 of its peak) more than 12 standard deviations from the mean.
    let ln_mean = 0.5 * (2.0 / df).ln() + ln_gamma(0.5 * (df + 1.0)) - ln_gamma(0.5 * df);
    let mean = ln_mean.exp();
    let spread = (1.0 - mean * mean).max(0.0).sqrt();
    let low = (mean - 12.0 * spread).max(0.0);
    let high = mean + 12.0 * spread;
    let ln_norm = 0.5 * df * df.ln() - ln_gamma(0.5 * df) - (0.5 * df - 1.0) * 2f64.ln();
    let total: f64 = composite_rule(low, high, OUTER_PANELS)
        .into_iter()
        .filter(|&(s, _)| s > 0.0)
        .map(|(s, weight)| {
            let density = (ln_norm + (df - 1.0) * s.ln() - 0.5 * df * s * s).exp();
            weight * density * range_cdf(q * s, k, &inner)
        })
        .sum();
    total.clamp(0.0, 1.0)
}

/// Quantile of the studentized range: the q with P(Q > q) = `alpha` (the upper `alpha` point of
/// the tables, e.g. q(0.05; 5, 60) ≈ 3.977). Returns NaN for `alpha` outside (0, 1), `k < 2` or
/// `df <= 0`.
pub fn quantile(alpha: f64, k: usize, df: f64) -> f64 {
    if !(alpha > 0.0 && alpha < 1.0) || k < 2 || df.is_nan() || df <= 0.0 {
        return f64::NAN;
    }
    let target = 1.0 - alpha;
    let (mut low, mut high) = (0.0, 1.0);
    while cdf(high, k, df) < target {
        low = high;
        high *= 2.0;
        if high > 1e6 {
            return f64::NAN;
        }
    }
    // Illinois: the secant of the bracket's ends, halving the value kept at an end that stays
    // twice in a row so that both ends move; stops when the bracket is below 1e-7 of q.
    let (mut a, mut b) = (low, high);
    let (mut fa, mut fb) = (cdf(a, k, df) - target, cdf(b, k, df) - target);
    for _ in 0..200 {
        if (b - a).abs() <= 1e-7 * b.abs().max(a.abs()) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c.is_finite() && c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let fc = cdf(c, k, df) - target;
        if fc == 0.0 {
            return c;
        }
        if (fc < 0.0) == (fb < 0.0) {
            fa *= 0.5;
        } else {
            a = b;
            fa = fb;
        }
        b = c;
        fb = fc;
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let rule = gauss_legendre(POINTS);
        let weights: f64 = rule.iter().map(|&(_, w)| w).sum();
        assert!((weights - 2.0).abs() < 1e-14);
        // A rule of n points is exact up to degree 2n − 1: ∫ x^18 over [-1, 1] = 2/19.
        let moment: f64 = rule.iter().map(|&(x, w)| w * x.powi(18)).sum();
        assert!((moment - 2.0 / 19.0).abs() < 1e-14);
    }

    #[test]
    fn two_means_with_known_sigma_is_a_scaled_normal() {
        // For k = 2 and ν = ∞, Q = |Z1 − Z2| so P(Q <= q) = 2Φ(q/√2) − 1.
        for q in [0.5, 1.0, 2.772, 4.0] {
            let exact = 2.0 * normal_cdf(q / std::f64::consts::SQRT_2) - 1.0;
            assert!((cdf(q, 2, f64::INFINITY) - exact).abs() < 1e-10, "q = {q}");
        }
    }

    #[test]
    fn two_means_with_estimated_sigma_is_a_scaled_t() {
        // For k = 2, Q/√2 is |t_ν|: with ν = 10 the two-sided 5% point of t is 2.228139.
        let q = 2.228_138_851_986_273 * std::f64::consts::SQRT_2;
        assert!((cdf(q, 2, 10.0) - 0.95).abs() < 1e-7);
    }

    #[test]
    fn quantiles_match_published_tables() {
        let cases = [
            (0.05, 2, f64::INFINITY, 2.772),
            (0.05, 3, 10.0, 3.877),
            (0.05, 5, 60.0, 3.977),
            (0.01, 5, 120.0, 4.709),
            (0.01, 5, 60.0, 4.818),
            (0.05, 5, f64::INFINITY, 3.858),
            (0.01, 5, f64::INFINITY, 4.603),
        ];
        for (alpha, k, df, table) in cases {
            let q = quantile(alpha, k, df);
            assert!(
                (q - table).abs() < 1e-3,
                "q({alpha}; {k}, {df}) = {q}, table {table}"
            );
        }
    }

    #[test]
    fn quantile_inverts_the_cdf() {
        for (alpha, k, df) in [(0.05, 2, 4.0), (0.01, 7, 30.0), (0.5, 3, f64::INFINITY)] {
            let q = quantile(alpha, k, df);
            let p = cdf(q, k, df);
            assert!(
                (p - (1.0 - alpha)).abs() < 1e-7,
                "P(Q <= {q}; {k}, {df}) = {p}"
            );
            // Within 1e-7 of q: moving by 1e-5 q changes the probability visibly.
            assert!(cdf(q * (1.0 - 1e-5), k, df) < 1.0 - alpha);
            assert!(cdf(q * (1.0 + 1e-5), k, df) > 1.0 - alpha);
        }
    }

    #[test]
    fn bad_arguments_give_nan() {
        assert!(quantile(0.0, 5, 10.0).is_nan());
        assert!(quantile(0.05, 1, 10.0).is_nan());
        assert!(cdf(1.0, 3, 0.0).is_nan());
    }
}
