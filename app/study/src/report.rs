//! `vitreous study analyze`: the analysis a responses file calls for (Case V for forced choices,
//! Nakaya's Scheffe for ratings) and its text and JSON reports.

use std::fmt;
use std::path::Path;

use serde_json::{Map, Value, json};

use super::responses::{ResponseKind, Responses, ResponsesError};
use super::scheffe::{self, Scheffe};
use super::thurstone::{self, CaseV, PROPORTION_CLIP};

/// The analysis of one responses file.
#[derive(Debug, Clone, PartialEq)]
pub enum Analysis {
    /// Forced choices: Thurstone's Case V with Mosteller's test.
    CaseV(CaseV),
    /// Ratings: Nakaya's variant of Scheffe's method.
    Scheffe(Scheffe),
}

/// The analyses of a responses file: one per stimulus.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyReport {
    /// Each stimulus's name ("" for a file without a `stimulus` column) and analysis, by name.
    pub groups: Vec<(String, Analysis)>,
}

impl StudyReport {
    /// The `--json` report: one stimulus's object as [`Analysis::to_json`] gives it (with its
    /// `stimulus` name when it has one), or `{"stimuli": {name: object}}` for several.
    pub fn to_json(&self) -> Value {
        match self.groups.as_slice() {
            [(name, analysis)] => {
                let mut value = analysis.to_json();
                if !name.is_empty() {
                    value["stimulus"] = Value::String(name.clone());
                }
                value
            }
            groups => {
                let map: Map<String, Value> = groups
                    .iter()
                    .map(|(name, a)| (name.clone(), a.to_json()))
                    .collect();
                json!({ "stimuli": map })
            }
        }
    }
}

impl fmt::Display for StudyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (name, analysis)) in self.groups.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            if !name.is_empty() {
                writeln!(f, "stimulus {name}:")?;
            }
            write!(f, "{analysis}")?;
        }
        Ok(())
    }
}

/// Reads a responses file and runs, for each stimulus, the analysis its kind of answers calls
/// for.
pub fn analyze_file(path: &Path) -> Result<StudyReport, ResponsesError> {
    let groups = Responses::read_by_stimulus(path)?
        .into_iter()
        .map(|(name, responses)| (name, analyze(&responses)))
        .collect();
    Ok(StudyReport { groups })
}

/// Runs the analysis the kind of answers calls for.
pub fn analyze(responses: &Responses) -> Analysis {
    match responses.kind {
        ResponseKind::ForcedChoice => Analysis::CaseV(thurstone::analyze(responses)),
        ResponseKind::Rating => Analysis::Scheffe(scheffe::analyze(responses)),
    }
}

/// Indices of `scale` from the highest value to the lowest (ties by name order).
fn descending(scale: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..scale.len()).collect();
    order.sort_by(|&a, &b| scale[b].total_cmp(&scale[a]).then(a.cmp(&b)));
    order
}

/// A finite number as JSON, NaN and infinities as null.
fn number(value: f64) -> Value {
    serde_json::Number::from_f64(value).map_or(Value::Null, Value::Number)
}

/// Scale values keyed by condition name.
fn scale_json(conditions: &[String], scale: &[f64]) -> Value {
    let map: Map<String, Value> = conditions
        .iter()
        .zip(scale)
        .map(|(name, &value)| (name.clone(), number(value)))
        .collect();
    Value::Object(map)
}

impl Analysis {
    /// The `--json` report.
    pub fn to_json(&self) -> Value {
        match self {
            Analysis::CaseV(r) => json!({
                "method": "thurstone-case-v",
                "conditions": r.conditions,
                "scale": scale_json(&r.conditions, &r.scale),
                "proportion_clip": [PROPORTION_CLIP, 1.0 - PROPORTION_CLIP],
                "counts": r.counts,
                "chi_square": {
                    "statistic": number(r.test.chi_square),
                    "df": r.test.df,
                    "p": r.test.p.map(number),
                },
            }),
            Analysis::Scheffe(r) => {
                let yardstick = r
                    .yardsticks
                    .map(|y| json!({ "0.05": number(y[0]), "0.01": number(y[1]) }));
                let anova: Vec<Value> = r
                    .anova
                    .iter()
                    .map(|row| {
                        json!({
                            "source": row.source,
                            "sum_of_squares": number(row.sum_of_squares),
                            "df": row.df,
                            "mean_square": row.mean_square.map(number),
                            "f": row.f.map(number),
                            "p": row.p.map(number),
                        })
                    })
                    .collect();
                let pairs: Vec<Value> = r
                    .pairs
                    .iter()
                    .map(|pair| {
                        json!({
                            "a": r.conditions[pair.a],
                            "b": r.conditions[pair.b],
                            "difference": number(pair.difference),
                            "significant": { "0.05": pair.significant[0], "0.01": pair.significant[1] },
                        })
                    })
                    .collect();
                json!({
                    "method": "scheffe-nakaya",
                    "conditions": r.conditions,
                    "participants": r.participants,
                    "scale": scale_json(&r.conditions, &r.scale),
                    "yardstick": yardstick,
                    "anova": anova,
                    "pairs": pairs,
                })
            }
        }
    }
}

/// A p value for the tables.
fn p_text(p: Option<f64>) -> String {
    match p {
        Some(p) if p < 1e-4 => "<0.0001".to_string(),
        Some(p) => format!("{p:.4}"),
        None => "-".to_string(),
    }
}

impl fmt::Display for Analysis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Analysis::CaseV(r) => {
                writeln!(
                    f,
                    "Thurstone's paired comparison, Case V ({} conditions)",
                    r.conditions.len()
                )?;
                writeln!(
                    f,
                    "scale values (z units, lowest at 0; proportions clipped to [0.02, 0.98]):"
                )?;
                for i in descending(&r.scale) {
                    writeln!(f, "  {:<24} {:>8.4}", r.conditions[i], r.scale[i])?;
                }
                write!(
                    f,
                    "Mosteller's chi-square: {:.4} on {} df",
                    r.test.chi_square, r.test.df
                )?;
                match r.test.p {
                    Some(p) => writeln!(
                        f,
                        ", p = {} (small p: Case V does not fit)",
                        p_text(Some(p))
                    ),
                    None => writeln!(f, " (two conditions always fit)"),
                }
            }
            Analysis::Scheffe(r) => {
                writeln!(
                    f,
                    "Scheffe's paired comparison, Nakaya's variant ({} conditions, {} participants)",
                    r.conditions.len(),
                    r.participants
                )?;
                writeln!(f, "main-effect scale values:")?;
                for i in descending(&r.scale) {
                    writeln!(f, "  {:<24} {:>8.4}", r.conditions[i], r.scale[i])?;
                }
                writeln!(f, "analysis of variance:")?;
                writeln!(
                    f,
                    "  {:<26} {:>10} {:>5} {:>10} {:>9} {:>8}",
                    "source", "SS", "df", "MS", "F", "p"
                )?;
                for row in &r.anova {
                    let ms = row
                        .mean_square
                        .map_or("-".to_string(), |m| format!("{m:.4}"));
                    let f_text = row.f.map_or("-".to_string(), |v| format!("{v:.3}"));
                    writeln!(
                        f,
                        "  {:<26} {:>10.4} {:>5} {:>10} {:>9} {:>8}",
                        row.source,
                        row.sum_of_squares,
                        row.df,
                        ms,
                        f_text,
                        p_text(row.p)
                    )?;
                }
                match r.yardsticks {
                    Some(y) => {
                        writeln!(
                            f,
                            "yardsticks: Y(0.05) = {:.4}, Y(0.01) = {:.4}",
                            y[0], y[1]
                        )?;
                        writeln!(f, "pairs (|difference| > Y: * at 5%, ** at 1%):")?;
                        for pair in &r.pairs {
                            let mark = match pair.significant {
                                [_, true] => "**",
                                [true, false] => "*",
                                _ => "",
                            };
                            let line = format!(
                                "  {:<16} - {:<16} {:>8.4} {}",
                                r.conditions[pair.a], r.conditions[pair.b], pair.difference, mark
                            );
                            writeln!(f, "{}", line.trim_end())?;
                        }
                        Ok(())
                    }
                    None => writeln!(
                        f,
                        "no yardsticks: one participant leaves the error no degrees of freedom"
                    ),
                }
            }
        }
    }
}

/// The levels of [`scheffe::LEVELS`] as JSON keys, for readers of the report.
pub const LEVEL_KEYS: [&str; 2] = ["0.05", "0.01"];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheffe::LEVELS;

    #[test]
    fn level_keys_match_the_levels() {
        for (key, level) in LEVEL_KEYS.iter().zip(LEVELS) {
            assert_eq!(key.parse::<f64>().unwrap(), level);
        }
    }
}
