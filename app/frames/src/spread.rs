//! The median and spread of a timing, as the summaries report them.

use serde::Serialize;

/// Median and spread of a timing.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Spread {
    /// Median, milliseconds.
    pub median_ms: f64,
    /// 10th percentile, milliseconds.
    pub p10_ms: f64,
    /// 90th percentile, milliseconds.
    pub p90_ms: f64,
}

impl Spread {
    /// The spread of `values`, or `None` when empty.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Spread> {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        Some(Spread {
            median_ms: at(0.5),
            p10_ms: at(0.1),
            p90_ms: at(0.9),
        })
    }
}
