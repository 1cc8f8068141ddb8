//! The responses file of a paired-comparison study: one CSV line per answer,
//! `participant,trial,first,second,response`, where `first` and `second` are condition names in
//! presentation order and `response` is `first`/`second` (a forced choice) or an integer from -3
//! to 3 (a rating, positive when the first-shown condition was the more convincing).

use std::collections::{BTreeMap, BTreeSet};
use std::io::Read;
use std::path::{Path, PathBuf};

pub use super::response_error::ResponsesError;

/// The columns a responses file must have, in any order.
pub const COLUMNS: [&str; 5] = ["participant", "trial", "first", "second", "response"];
/// The optional column naming the stimulus (scene) of each answer; each stimulus is analysed
/// on its own.
pub const STIMULUS_COLUMN: &str = "stimulus";
/// The largest rating magnitude (ratings run from -3 to 3).
pub const RATING_LIMIT: i8 = 3;

/// Which condition a forced choice picked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The condition shown first.
    First,
    /// The condition shown second.
    Second,
}

/// One answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// A forced choice between the two presentations.
    Choice(Choice),
    /// A rating from -3 to 3, positive when the first-shown condition was the more convincing.
    Rating(i8),
}

/// The kind of answers a file holds (one kind per file).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResponseKind {
    /// `first`/`second` answers: analysed with Thurstone's Case V.
    ForcedChoice,
    /// -3..3 ratings: analysed with Nakaya's variant of Scheffe's method.
    Rating,
}

impl ResponseKind {
    /// The words used in messages.
    pub fn name(self) -> &'static str {
        match self {
            ResponseKind::ForcedChoice => "a forced choice",
            ResponseKind::Rating => "a rating",
        }
    }
}

/// One line of the responses file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Response {
    /// Line number in the file (1-based; the header is line 1).
    pub line: u64,
    /// Participant identifier.
    pub participant: String,
    /// Trial number within the participant's session.
    pub trial: u64,
    /// Condition shown first.
    pub first: String,
    /// Condition shown second.
    pub second: String,
    /// The answer.
    pub answer: Answer,
    /// The stimulus (scene) it was given in; empty without a `stimulus` column.
    pub stimulus: String,
}

/// A whole responses file, checked line by line.
#[derive(Debug, Clone)]
pub struct Responses {
    /// Where the responses came from (for messages).
    pub path: PathBuf,
    /// The kind of every answer in the file.
    pub kind: ResponseKind,
    /// The answers in file order.
    pub rows: Vec<Response>,
    /// The condition names, sorted.
    pub conditions: Vec<String>,
    /// The participant identifiers, sorted.
    pub participants: Vec<String>,
}

impl Responses {
    /// Reads and checks a responses file.
    pub fn read(path: &Path) -> Result<Self, ResponsesError> {
        let file = std::fs::File::open(path).map_err(|source| ResponsesError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, file)
    }

    /// Parses and checks responses from `reader`; `path` names them in messages. All answers
    /// are analysed together, whatever their stimulus.
    pub fn parse(path: &Path, reader: impl Read) -> Result<Self, ResponsesError> {
        Responses::from_rows(path, parse_rows(path, reader)?)
    }

    /// Reads a responses file and splits it by stimulus (one group named "" without a
    /// `stimulus` column), each group checked as a whole study of its own.
    pub fn read_by_stimulus(path: &Path) -> Result<Vec<(String, Responses)>, ResponsesError> {
        let file = std::fs::File::open(path).map_err(|source| ResponsesError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let rows = parse_rows(path, file)?;
        if rows.is_empty() {
            return Err(ResponsesError::Empty {
                path: path.to_path_buf(),
            });
        }
        let names: BTreeSet<String> = rows.iter().map(|r| r.stimulus.clone()).collect();
        names
            .into_iter()
            .map(|name| {
                let group: Vec<Response> = rows
                    .iter()
                    .filter(|r| r.stimulus == name)
                    .cloned()
                    .collect();
                Responses::from_rows(path, group).map(|r| (name, r))
            })
            .collect()
    }

    /// Checks answers as one study.
    fn from_rows(path: &Path, rows: Vec<Response>) -> Result<Self, ResponsesError> {
        let Some(first_row) = rows.first() else {
            return Err(ResponsesError::Empty {
                path: path.to_path_buf(),
            });
        };
        let kind = kind_of(first_row.answer);
        let conditions: BTreeSet<&str> = rows
            .iter()
            .flat_map(|r| [r.first.as_str(), r.second.as_str()])
            .collect();
        let participants: BTreeSet<&str> = rows.iter().map(|r| r.participant.as_str()).collect();
        let responses = Responses {
            path: path.to_path_buf(),
            kind,
            conditions: conditions.into_iter().map(str::to_string).collect(),
            participants: participants.into_iter().map(str::to_string).collect(),
            rows,
        };
        if responses.conditions.len() < 2 {
            return Err(ResponsesError::TooFewConditions {
                path: path.to_path_buf(),
                count: responses.conditions.len(),
            });
        }
        match kind {
            ResponseKind::ForcedChoice => responses.check_every_pair_judged()?,
            ResponseKind::Rating => responses.check_complete_rating_design()?,
        }
        Ok(responses)
    }
}

/// Parses every line, checking each on its own and against the lines before it (one kind of
/// answer per file, no trial twice).
fn parse_rows(path: &Path, reader: impl Read) -> Result<Vec<Response>, ResponsesError> {
    let path_buf = path.to_path_buf();
    let csv_error = |error: csv::Error| ResponsesError::Csv {
        path: path_buf.clone(),
        line: error.position().map_or(0, |p| p.line()),
        message: error.to_string(),
    };
    let mut csv = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(reader);
    let header = csv.headers().map_err(csv_error)?.clone();
    let mut index = [0usize; 5];
    for (slot, column) in index.iter_mut().zip(COLUMNS) {
        *slot = header
            .iter()
            .position(|name| name == column)
            .ok_or_else(|| ResponsesError::MissingColumn {
                path: path.to_path_buf(),
                column,
                expected: COLUMNS.join(","),
            })?;
    }
    let stimulus_index = header.iter().position(|name| name == STIMULUS_COLUMN);
    let mut rows: Vec<Response> = Vec::new();
    let mut trials: BTreeMap<(String, u64), u64> = BTreeMap::new();
    for record in csv.records() {
        let record = record.map_err(csv_error)?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |i: usize| record.get(index[i]).unwrap_or("");
        let bad =
            |name: &'static str, value: &str, expected: &'static str| ResponsesError::BadField {
                path: path.to_path_buf(),
                line,
                field: name,
                value: value.to_string(),
                expected,
            };
        let participant = field(0);
        if participant.is_empty() {
            return Err(bad("participant", participant, "a participant identifier"));
        }
        let trial: u64 = field(1)
            .parse()
            .map_err(|_| bad("trial", field(1), "a non-negative integer"))?;
        let (first, second) = (field(2), field(3));
        if first.is_empty() {
            return Err(bad("first", first, "a condition name"));
        }
        if second.is_empty() {
            return Err(bad("second", second, "a condition name"));
        }
        if first == second {
            return Err(ResponsesError::SameCondition {
                path: path.to_path_buf(),
                line,
                condition: first.to_string(),
            });
        }
        let answer = parse_answer(path, line, field(4))?;
        if let Some(earlier) = rows.first() {
            let (found, expected) = (kind_of(answer), kind_of(earlier.answer));
            if found != expected {
                return Err(ResponsesError::MixedKinds {
                    path: path.to_path_buf(),
                    line,
                    found: found.name(),
                    expected: expected.name(),
                    first_line: earlier.line,
                });
            }
        }
        if let Some(&first_line) = trials.get(&(participant.to_string(), trial)) {
            return Err(ResponsesError::DuplicateTrial {
                path: path.to_path_buf(),
                line,
                participant: participant.to_string(),
                trial,
                first_line,
            });
        }
        trials.insert((participant.to_string(), trial), line);
        rows.push(Response {
            line,
            participant: participant.to_string(),
            trial,
            first: first.to_string(),
            second: second.to_string(),
            answer,
            stimulus: stimulus_index
                .and_then(|i| record.get(i))
                .unwrap_or("")
                .to_string(),
        });
    }
    Ok(rows)
}

impl Responses {
    /// Index of a condition in [`Responses::conditions`].
    pub fn condition_index(&self, name: &str) -> Option<usize> {
        self.conditions
            .binary_search_by(|c| c.as_str().cmp(name))
            .ok()
    }

    /// Forced choice: every unordered pair of conditions has at least one answer.
    fn check_every_pair_judged(&self) -> Result<(), ResponsesError> {
        let judged: BTreeSet<(&str, &str)> = self
            .rows
            .iter()
            .map(|r| ordered(r.first.as_str(), r.second.as_str()))
            .collect();
        for (i, a) in self.conditions.iter().enumerate() {
            for b in &self.conditions[i + 1..] {
                if !judged.contains(&(a.as_str(), b.as_str())) {
                    return Err(ResponsesError::UnjudgedPair {
                        path: self.path.clone(),
                        a: a.clone(),
                        b: b.clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// Ratings (Nakaya's design): every participant rates every ordered pair exactly once.
    fn check_complete_rating_design(&self) -> Result<(), ResponsesError> {
        let mut seen: BTreeMap<(&str, &str, &str), u64> = BTreeMap::new();
        for r in &self.rows {
            let key = (r.participant.as_str(), r.first.as_str(), r.second.as_str());
            if let Some(&first_line) = seen.get(&key) {
                return Err(ResponsesError::RepeatedPair {
                    path: self.path.clone(),
                    line: r.line,
                    participant: r.participant.clone(),
                    first: r.first.clone(),
                    second: r.second.clone(),
                    first_line,
                });
            }
            seen.insert(key, r.line);
        }
        for participant in &self.participants {
            for first in &self.conditions {
                for second in &self.conditions {
                    if first != second
                        && !seen.contains_key(&(
                            participant.as_str(),
                            first.as_str(),
                            second.as_str(),
                        ))
                    {
                        return Err(ResponsesError::MissingPair {
                            path: self.path.clone(),
                            participant: participant.clone(),
                            first: first.clone(),
                            second: second.clone(),
                        });
                    }
                }
            }
        }
        Ok(())
    }
}

/// The two names in sorted order.
fn ordered<'a>(a: &'a str, b: &'a str) -> (&'a str, &'a str) {
    if a <= b { (a, b) } else { (b, a) }
}

/// The kind of one answer.
fn kind_of(answer: Answer) -> ResponseKind {
    match answer {
        Answer::Choice(_) => ResponseKind::ForcedChoice,
        Answer::Rating(_) => ResponseKind::Rating,
    }
}

/// Parses the `response` field.
fn parse_answer(path: &Path, line: u64, value: &str) -> Result<Answer, ResponsesError> {
    match value {
        "first" => return Ok(Answer::Choice(Choice::First)),
        "second" => return Ok(Answer::Choice(Choice::Second)),
        _ => {}
    }
    let rating: i64 = value
        .strip_prefix('+')
        .unwrap_or(value)
        .parse()
        .map_err(|_| ResponsesError::UnknownResponse {
            path: path.to_path_buf(),
            line,
            value: value.to_string(),
        })?;
    if rating.abs() > i64::from(RATING_LIMIT) {
        return Err(ResponsesError::RatingOutOfRange {
            path: path.to_path_buf(),
            line,
            value: rating,
        });
    }
    // The range check above keeps the value within i8.
    Ok(Answer::Rating(rating as i8))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "participant,trial,first,second,response\n";

    fn parse(body: &str) -> Result<Responses, ResponsesError> {
        Responses::parse(Path::new("r.csv"), format!("{HEADER}{body}").as_bytes())
    }

    fn message(body: &str) -> String {
        match parse(body) {
            Ok(_) => panic!("accepted: {body}"),
            Err(error) => error.to_string(),
        }
    }

    #[test]
    fn reads_forced_choices() {
        let r = parse("p1,1,a,b,first\np1,2,b,c,second\np1,3,c,a,first\n").unwrap();
        assert_eq!(r.kind, ResponseKind::ForcedChoice);
        assert_eq!(r.conditions, ["a", "b", "c"]);
        assert_eq!(r.rows[1].line, 3);
        assert_eq!(r.rows[1].answer, Answer::Choice(Choice::Second));
    }

    #[test]
    fn reads_ratings_in_a_complete_design() {
        let r = parse("p1,1,a,b,2\np1,2,b,a,-3\np2,1,b,a,+1\np2,2,a,b,0\n").unwrap();
        assert_eq!(r.kind, ResponseKind::Rating);
        assert_eq!(r.participants, ["p1", "p2"]);
        assert_eq!(r.rows[2].answer, Answer::Rating(1));
    }

    #[test]
    fn errors_name_the_file_and_line() {
        assert_eq!(
            message("p1,1,a,b,first\np1,2,a,b,maybe\n"),
            "r.csv: line 3: response \"maybe\" is neither `first`/`second` nor an integer rating from -3 to 3"
        );
        assert!(message("p1,1,a,b,4\n").starts_with("r.csv: line 2: rating 4 is outside -3..3"));
        assert!(
            message("p1,1,a,b,first\np1,2,b,a,1\n").starts_with("r.csv: line 3: a rating among")
        );
        assert!(message("p1,1,a,a,first\n").starts_with("r.csv: line 2: first and second"));
        assert!(
            message("p1,1,a,b,first\np1,1,b,a,first\n").starts_with(
                "r.csv: line 3: participant \"p1\" trial 1 already answered on line 2"
            )
        );
        assert!(message("p1,x,a,b,first\n").starts_with("r.csv: line 2: `trial` is \"x\""));
        assert!(message("").contains("no responses"));
    }

    #[test]
    fn a_missing_column_is_named() {
        let error = Responses::parse(
            Path::new("r.csv"),
            "participant,trial,first,second\n".as_bytes(),
        )
        .unwrap_err();
        assert!(
            error.to_string().contains("no `response` column"),
            "{error}"
        );
    }

    #[test]
    fn rating_designs_need_every_ordered_pair_once() {
        let missing = message("p1,1,a,b,1\np1,2,b,a,1\np2,1,a,b,1\n");
        assert_eq!(
            missing,
            "r.csv: participant \"p2\" has no rating of \"b\" then \"a\"; every participant rates every ordered pair once"
        );
        let repeated = message("p1,1,a,b,1\np1,2,a,b,1\np1,3,b,a,0\n");
        assert!(
            repeated.starts_with("r.csv: line 3: participant \"p1\" already rated"),
            "{repeated}"
        );
    }

    #[test]
    fn forced_choice_designs_need_every_pair_judged() {
        let error = message("p1,1,a,b,first\np1,2,b,c,first\n");
        assert!(
            error.contains("no participant compared \"a\" with \"c\""),
            "{error}"
        );
    }
}
