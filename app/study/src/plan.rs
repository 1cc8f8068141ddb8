//! Trial orders: `vitreous study plan`.
//!
//! Orders come from Williams designs (E. J. Williams, "Experimental designs balanced for the
//! estimation of residual effects of treatments", Aust. J. Sci. Res. A 2, 1949): over every
//! full cycle of participants, each trial sits at each position equally often and (for an even
//! number of trials) follows each other trial equally often, so position and carry-over effects
//! fall equally on all of them. Randomisation is layered on top, from the seed: which trial plays
//! which role in the design, which participant gets which row, and the order of the stimulus
//! blocks (itself a Williams design over the stimuli). With [`Orders::Balanced`], the
//! presentation order of each pair alternates across participants from a seeded start.
//!
//! The random numbers come from [`SplitMix64`], whose sequence for a seed never changes: a plan
//! written today is rebuilt bit for bit from its seed by any later version.

use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;
use vitreous_trace::synth::SplitMix64;

use super::protocol::{Orders, Protocol};

/// The most participants a plan may hold.
pub const MAX_PARTICIPANTS: usize = 10_000;
/// The plan file's columns, in order.
pub const COLUMNS: [&str; 5] = ["participant", "trial", "stimulus", "first", "second"];

/// One planned trial.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlannedTrial {
    /// Participant identifier (`p01`, ...).
    pub participant: String,
    /// Trial number within the participant's session, from 1.
    pub trial: u64,
    /// Stimulus (scene) name.
    pub stimulus: String,
    /// Condition shown first.
    pub first: String,
    /// Condition shown second.
    pub second: String,
}

/// The rows of a Williams design of order `n`: `n` rows for even `n`, `2n` for odd `n` (the
/// mirror images added), each a permutation of `0..n`.
pub fn williams(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return Vec::new();
    }
    // First row 0, 1, n-1, 2, n-2, ...; the others are its cyclic shifts.
    let mut first = Vec::with_capacity(n);
    let (mut low, mut high) = (0usize, n);
    for k in 0..n {
        if k % 2 == 0 {
            first.push(low);
            low += 1;
        } else {
            high -= 1;
            first.push(high);
        }
    }
    let mut rows: Vec<Vec<usize>> = (0..n)
        .map(|shift| first.iter().map(|&v| (v + shift) % n).collect())
        .collect();
    if n % 2 == 1 {
        let mirrored: Vec<Vec<usize>> = rows
            .iter()
            .map(|r| r.iter().rev().copied().collect())
            .collect();
        rows.extend(mirrored);
    }
    rows
}

/// A randomised Williams design: row `p` is participant `p`'s order of `0..n`.
struct Design {
    /// The design's rows, in a seeded order.
    rows: Vec<Vec<usize>>,
    /// Which item plays each role in the design.
    roles: Vec<usize>,
}

impl Design {
    fn new(n: usize, rng: &mut SplitMix64) -> Design {
        let mut rows = williams(n);
        rng.shuffle(&mut rows);
        let mut roles: Vec<usize> = (0..n).collect();
        rng.shuffle(&mut roles);
        Design { rows, roles }
    }

    /// Participant `p`'s order.
    fn order(&self, p: usize) -> Vec<usize> {
        self.rows[p % self.rows.len()]
            .iter()
            .map(|&r| self.roles[r])
            .collect()
    }
}

/// Participant identifiers `p01`.. (zero-padded to sort in order).
pub fn participant_ids(n: usize) -> Vec<String> {
    let width = n.to_string().len().max(2);
    (1..=n).map(|i| format!("p{i:0width$}")).collect()
}

/// Every participant's trials, in order.
pub fn plan(protocol: &Protocol, participants: usize, seed: u64) -> Vec<PlannedTrial> {
    let mut rng = SplitMix64(seed);
    let pairs = protocol.pairs();
    let blocks = Design::new(protocol.stimuli.len(), &mut rng);
    let within: Vec<Design> = protocol
        .stimuli
        .iter()
        .map(|_| Design::new(pairs.len(), &mut rng))
        .collect();
    // For balanced orders: each pair's presentation order for participant 0; it alternates.
    let flips: Vec<bool> = pairs.iter().map(|_| rng.next_u64() & 1 == 1).collect();
    let mut out = Vec::with_capacity(participants * protocol.trials_per_participant());
    for (p, id) in participant_ids(participants).into_iter().enumerate() {
        let mut trial = 0;
        for s in blocks.order(p) {
            for q in within[s].order(p) {
                let (a, b) = pairs[q];
                let (first, second) = match protocol.orders {
                    Orders::Both => (a, b),
                    Orders::Balanced if flips[q] ^ (p % 2 == 1) => (b, a),
                    Orders::Balanced => (a, b),
                };
                trial += 1;
                out.push(PlannedTrial {
                    participant: id.clone(),
                    trial,
                    stimulus: protocol.stimuli[s].name.clone(),
                    first: protocol.conditions[first].name.clone(),
                    second: protocol.conditions[second].name.clone(),
                });
            }
        }
    }
    out
}

/// Writes a plan as CSV (with a header and a comment naming protocol, seed and size).
pub fn write_plan(
    out: &mut impl Write,
    protocol: &Protocol,
    seed: u64,
    trials: &[PlannedTrial],
) -> std::io::Result<()> {
    writeln!(
        out,
        "# vitreous study plan: protocol {} ({}), seed {seed}",
        protocol.name,
        protocol.path.display()
    )?;
    writeln!(out, "{}", COLUMNS.join(","))?;
    for t in trials {
        writeln!(
            out,
            "{},{},{},{},{}",
            t.participant, t.trial, t.stimulus, t.first, t.second
        )?;
    }
    Ok(())
}

/// Reads a plan and checks it against the protocol: known stimuli and conditions, trials
/// numbered 1.. without gaps per participant, no pair of a condition with itself.
pub fn read_plan(path: &Path, protocol: &Protocol) -> Result<Vec<PlannedTrial>, PlanError> {
    let file = std::fs::File::open(path).map_err(|source| PlanError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_plan(path, file, protocol)
}

/// [`read_plan`] from `reader`; `path` names it in messages.
pub fn parse_plan(
    path: &Path,
    reader: impl std::io::Read,
    protocol: &Protocol,
) -> Result<Vec<PlannedTrial>, PlanError> {
    let mut csv = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(reader);
    let line_error = |line: u64, message: String| PlanError::Line {
        path: path.to_path_buf(),
        line,
        message,
    };
    let header = csv
        .headers()
        .map_err(|e| line_error(0, e.to_string()))?
        .clone();
    let mut index = [0usize; 5];
    for (slot, column) in index.iter_mut().zip(COLUMNS) {
        *slot = header
            .iter()
            .position(|h| h == column)
            .ok_or_else(|| line_error(1, format!("no `{column}` column")))?;
    }
    let mut out: Vec<PlannedTrial> = Vec::new();
    for record in csv.records() {
        let record =
            record.map_err(|e| line_error(e.position().map_or(0, |p| p.line()), e.to_string()))?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |i: usize| record.get(index[i]).unwrap_or("").to_owned();
        let trial: u64 = field(1)
            .parse()
            .map_err(|_| line_error(line, format!("trial `{}` is not a number", field(1))))?;
        let t = PlannedTrial {
            participant: field(0),
            trial,
            stimulus: field(2),
            first: field(3),
            second: field(4),
        };
        if t.participant.is_empty() {
            return Err(line_error(line, "empty participant".into()));
        }
        if protocol.stimulus_index(&t.stimulus).is_none() {
            return Err(line_error(
                line,
                format!("stimulus `{}` is not in the protocol", t.stimulus),
            ));
        }
        for name in [&t.first, &t.second] {
            if protocol.condition_index(name).is_none() {
                return Err(line_error(
                    line,
                    format!("condition `{name}` is not in the protocol"),
                ));
            }
        }
        if t.first == t.second {
            return Err(line_error(
                line,
                format!("`{}` paired with itself", t.first),
            ));
        }
        let expected = out
            .iter()
            .rev()
            .find(|o| o.participant == t.participant)
            .map_or(1, |o| o.trial + 1);
        if t.trial != expected {
            return Err(line_error(
                line,
                format!(
                    "participant {} trial {}: expected trial {expected} (trials run 1, 2, ... \
                     in file order)",
                    t.participant, t.trial
                ),
            ));
        }
        out.push(t);
    }
    if out.is_empty() {
        return Err(line_error(0, "no trials".into()));
    }
    Ok(out)
}

/// Errors reading a plan.
#[derive(Debug, Error)]
pub enum PlanError {
    /// The file could not be read.
    #[error("reading the study plan {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A line is wrong.
    #[error("{}:{line}: {message}", path.display())]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line (0: the file as a whole).
        line: u64,
        /// What is wrong.
        message: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn is_williams(rows: &[Vec<usize>], n: usize) {
        // Every row a permutation; every item at every position equally often; every ordered
        // adjacent pair equally often.
        for r in rows {
            let mut s = r.clone();
            s.sort();
            assert_eq!(s, (0..n).collect::<Vec<_>>());
        }
        for pos in 0..n {
            let mut count = vec![0; n];
            for r in rows {
                count[r[pos]] += 1;
            }
            assert!(count.iter().all(|&c| c == rows.len() / n), "{count:?}");
        }
        let mut follows: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for r in rows {
            for w in r.windows(2) {
                *follows.entry((w[0], w[1])).or_default() += 1;
            }
        }
        assert_eq!(
            follows.len(),
            n * (n - 1),
            "every ordered pair adjacent somewhere"
        );
        let per = rows.len() * (n - 1) / (n * (n - 1));
        assert!(follows.values().all(|&c| c == per), "{follows:?}");
    }

    #[test]
    fn williams_designs_balance_positions_and_carry_over() {
        for n in 2..=20 {
            let rows = williams(n);
            assert_eq!(rows.len(), if n % 2 == 0 { n } else { 2 * n });
            is_williams(&rows, n);
        }
    }

    #[test]
    fn participant_ids_sort_in_order() {
        let ids = participant_ids(120);
        assert_eq!(ids[0], "p001");
        let mut sorted = ids.clone();
        sorted.sort();
        assert_eq!(sorted, ids);
    }
}
