//! Delimited text records: the one CSV reading layer under the trace reader
//! ([`crate::format`], `,`-separated) and the SRanipal importer ([`crate::sranipal`],
//! `;`-separated).
//!
//! Both formats are plain delimiter-separated text without quoting, so the parser runs with
//! quoting off: a `"` is an ordinary character. Fields are trimmed of ASCII whitespace, lines
//! end with `\n`, `\r\n` or `\r`, and empty lines are skipped (they still count in line
//! numbers). Every error names the file, the 1-based line and, for a field, its column; any
//! text of the file quoted in a message goes through [`printable`] first.
//!
//! Line numbers are counted here, not taken from the parser (whose count skips the empty
//! lines before a record and does not count a lone `\r`): without quoting, every non-empty
//! line is exactly one record, so the n-th record is the n-th non-empty line.
//!
//! Reading is bounded: a line longer than [`MAX_LINE_BYTES`] is refused as soon as the limit
//! is passed, so a huge file without line endings is never held in memory whole.

use std::collections::VecDeque;
use std::io::{self, Read};

use glam::Vec3;

use crate::format::TraceError;

/// At most this many characters of file content are quoted in an error message.
pub const QUOTED_CHARS: usize = 60;

/// The longest line the trace reader and the SRanipal importer accept, in bytes, line ending
/// not counted (64 KiB). A trace line is under 1 KiB and an SRanipal row a few hundred bytes.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// File content as it may appear in a message: control characters, NUL and other
/// non-printing characters escaped (`\0`, `\u{1b}`, ...), cut after [`QUOTED_CHARS`]
/// characters with `...` appended.
pub fn printable(text: &str) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == QUOTED_CHARS {
            out.push_str("...");
            break;
        }
        out.extend(c.escape_debug());
    }
    out
}

/// A line passed the length limit: the payload of the I/O error [`LineNumbers`] returns.
#[derive(Debug)]
struct LineTooLong {
    /// Line number (1-based).
    line: usize,
    /// The limit passed, bytes.
    limit: usize,
    /// The first bytes of the line.
    start: Vec<u8>,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {} is longer than {} bytes", self.line, self.limit)
    }
}

impl std::error::Error for LineTooLong {}

/// A reader that notes the number of every non-empty line passing through it, ending lines
/// as the CSV parser does (`\n`, `\r` and `\r\n` each end one line), and fails once a line
/// grows past a limit.
struct LineNumbers<R> {
    /// The bytes being read.
    inner: R,
    /// The longest line allowed, bytes.
    limit: usize,
    /// Lines ended so far.
    ended: usize,
    /// Bytes of the current line so far.
    run: usize,
    /// Whether the last byte was `\r` (a following `\n` then ends no further line).
    after_cr: bool,
    /// Numbers (1-based) of the non-empty lines read ahead by the parser and not yet handed
    /// out as records; at most one per two bytes of the parser's buffer.
    pending: VecDeque<usize>,
    /// The first bytes of the current line, for the message when it is too long.
    start: Vec<u8>,
    /// The error to return from the next read, once a line has passed the limit.
    failed: Option<io::Error>,
}

impl<R> LineNumbers<R> {
    /// Bytes of a line kept for the message: enough for [`QUOTED_CHARS`] characters.
    const START_BYTES: usize = 4 * QUOTED_CHARS;

    fn new(inner: R, limit: usize) -> Self {
        LineNumbers {
            inner,
            limit,
            ended: 0,
            run: 0,
            after_cr: false,
            pending: VecDeque::new(),
            start: Vec::new(),
            failed: None,
        }
    }
}

impl<R: Read> Read for LineNumbers<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if let Some(error) = self.failed.take() {
            return Err(error);
        }
        let n = self.inner.read(buf)?;
        for (i, &b) in buf[..n].iter().enumerate() {
            match b {
                b'\n' if self.after_cr => self.after_cr = false,
                b'\n' | b'\r' => {
                    self.ended += 1;
                    self.run = 0;
                    self.start.clear();
                    self.after_cr = b == b'\r';
                }
                _ => {
                    self.after_cr = false;
                    if self.run == 0 {
                        self.pending.push_back(self.ended + 1);
                    }
                    self.run += 1;
                    if self.start.len() < Self::START_BYTES {
                        self.start.push(b);
                    }
                    if self.run > self.limit {
                        let error = io::Error::other(LineTooLong {
                            line: self.ended + 1,
                            limit: self.limit,
                            start: std::mem::take(&mut self.start),
                        });
                        // The lines before this one are handed out first: the parser reads
                        // again, and gets the error, since this line has not ended.
                        if i == 0 {
                            return Err(error);
                        }
                        self.failed = Some(error);
                        return Ok(i);
                    }
                }
            }
        }
        Ok(n)
    }
}

/// Reads delimiter-separated records one at a time, tracking the line of each for messages.
pub(crate) struct RecordReader<R: Read> {
    /// The CSV parser, over the input with its lines numbered and bounded.
    csv: csv::Reader<LineNumbers<R>>,
    /// File name used in error messages.
    file: String,
    /// The field separator.
    separator: char,
    /// The record read last.
    record: csv::StringRecord,
    /// Line number (1-based) of the record read last; 0 before the first.
    line: usize,
}

impl<R: Read> RecordReader<R> {
    /// Reads records separated by `separator` (an ASCII character) from `reader`; `file` is
    /// the name used in error messages.
    pub(crate) fn new(reader: R, file: impl Into<String>, separator: u8) -> Self {
        RecordReader::with_line_limit(reader, file, separator, MAX_LINE_BYTES)
    }

    /// Like [`RecordReader::new`], refusing lines longer than `limit` bytes.
    fn with_line_limit(reader: R, file: impl Into<String>, separator: u8, limit: usize) -> Self {
        let csv = csv::ReaderBuilder::new()
            .delimiter(separator)
            .has_headers(false)
            .flexible(true)
            .quoting(false)
            .trim(csv::Trim::All)
            .from_reader(LineNumbers::new(reader, limit));
        RecordReader {
            csv,
            file: file.into(),
            separator: char::from(separator),
            record: csv::StringRecord::new(),
            line: 0,
        }
    }

    /// The file name used in error messages.
    pub(crate) fn file(&self) -> &str {
        &self.file
    }

    /// Reads the next non-empty record; `None` at the end of the input.
    pub(crate) fn next_record(&mut self) -> Result<Option<Record<'_>>, TraceError> {
        match self.csv.read_record(&mut self.record) {
            Ok(false) => Ok(None),
            Ok(true) => {
                self.line = self.next_line_number();
                Ok(Some(Record {
                    file: &self.file,
                    line: self.line,
                    separator: self.separator,
                    fields: &self.record,
                }))
            }
            Err(e) => Err(self.read_error(e)),
        }
    }

    /// Reads the next record that is neither blank nor a `#` comment; `None` at the end.
    pub(crate) fn next_content_record(&mut self) -> Result<Option<Record<'_>>, TraceError> {
        loop {
            // Two calls because the borrow checker does not let a returned borrow out of a
            // loop that continues after it.
            match self.next_record()? {
                None => return Ok(None),
                Some(r) if r.is_blank() || r.is_comment() => continue,
                Some(_) => {}
            }
            return Ok(Some(Record {
                file: &self.file,
                line: self.line,
                separator: self.separator,
                fields: &self.record,
            }));
        }
    }

    /// The line of the record the parser is reading (or has just read).
    fn next_line_number(&mut self) -> usize {
        let pending = &mut self.csv.get_mut().pending;
        pending.pop_front().unwrap_or(self.line + 1)
    }

    /// Turns a CSV error into a trace error naming the file and line.
    fn read_error(&mut self, error: csv::Error) -> TraceError {
        match error.into_kind() {
            csv::ErrorKind::Io(source) => match source
                .get_ref()
                .and_then(|e| e.downcast_ref::<LineTooLong>())
            {
                Some(long) => TraceError::LineTooLong {
                    file: self.file.clone(),
                    line: long.line,
                    limit: long.limit,
                    start: printable(&String::from_utf8_lossy(&long.start)),
                },
                None => TraceError::Io {
                    file: self.file.clone(),
                    context: format!("reading line {}", self.line + 1),
                    source,
                },
            },
            csv::ErrorKind::Utf8 { err, .. } => TraceError::NotUtf8 {
                file: self.file.clone(),
                line: self.next_line_number(),
                field: err.field() + 1,
            },
            other => TraceError::Io {
                file: self.file.clone(),
                context: format!("reading line {}", self.line + 1),
                source: std::io::Error::other(format!("{other:?}")),
            },
        }
    }
}

/// One record (line) of a file, with what error messages need.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Record<'a> {
    /// File name used in error messages.
    file: &'a str,
    /// Line number (1-based).
    line: usize,
    /// The field separator, for messages.
    separator: char,
    /// The trimmed fields.
    fields: &'a csv::StringRecord,
}

impl<'a> Record<'a> {
    /// The file name used in error messages.
    pub(crate) fn file(&self) -> &'a str {
        self.file
    }

    /// Line number (1-based).
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// Number of fields.
    pub(crate) fn len(&self) -> usize {
        self.fields.len()
    }

    /// Field `index` (trimmed); empty past the last field.
    pub(crate) fn field(&self, index: usize) -> &'a str {
        self.fields.get(index).unwrap_or("")
    }

    /// All fields, in order.
    pub(crate) fn fields(&self) -> impl Iterator<Item = &'a str> {
        self.fields.iter()
    }

    /// The line again, fields joined by the separator (whitespace around fields dropped).
    pub(crate) fn text(&self) -> String {
        let separator = self.separator.to_string();
        self.fields.iter().collect::<Vec<_>>().join(&separator)
    }

    /// Whether the line holds only whitespace.
    pub(crate) fn is_blank(&self) -> bool {
        self.fields.iter().all(str::is_empty) && self.fields.len() <= 1
    }

    /// Whether the line is a comment: its first non-blank character is `#`.
    pub(crate) fn is_comment(&self) -> bool {
        self.field(0).starts_with('#')
    }

    /// Checks that the record has `expected` fields.
    pub(crate) fn expect_len(&self, expected: usize) -> Result<(), TraceError> {
        if self.len() == expected {
            return Ok(());
        }
        Err(TraceError::FieldCount {
            file: self.file.to_owned(),
            line: self.line,
            found: self.len(),
            expected,
            separator: self.separator,
        })
    }

    /// A [`TraceError::BadField`] for this line.
    pub(crate) fn bad(
        &self,
        column: &'static str,
        found: &str,
        expected: &'static str,
    ) -> TraceError {
        TraceError::BadField {
            file: self.file.to_owned(),
            line: self.line,
            column,
            found: printable(found),
            expected,
        }
    }

    /// Parses field `index` (column `column`) as an integer; `expected` says what it holds.
    pub(crate) fn i64(
        &self,
        index: usize,
        column: &'static str,
        expected: &'static str,
    ) -> Result<i64, TraceError> {
        let text = self.field(index);
        text.parse().map_err(|_| self.bad(column, text, expected))
    }

    /// Parses field `index` (column `column`) as a decimal number; NaN and infinities parse.
    pub(crate) fn f32(&self, index: usize, column: &'static str) -> Result<f32, TraceError> {
        let text = self.field(index);
        text.parse()
            .map_err(|_| self.bad(column, text, "a decimal number"))
    }

    /// Parses three decimal fields.
    pub(crate) fn vec3(
        &self,
        index: [usize; 3],
        columns: [&'static str; 3],
    ) -> Result<Vec3, TraceError> {
        Ok(Vec3::new(
            self.f32(index[0], columns[0])?,
            self.f32(index[1], columns[1])?,
            self.f32(index[2], columns[2])?,
        ))
    }

    /// Parses three decimal fields that must be finite.
    pub(crate) fn finite_vec3(
        &self,
        index: [usize; 3],
        columns: [&'static str; 3],
    ) -> Result<Vec3, TraceError> {
        let v = self.vec3(index, columns)?;
        for (value, column) in v.to_array().into_iter().zip(columns) {
            if !value.is_finite() {
                return Err(TraceError::NonFinite {
                    file: self.file.to_owned(),
                    line: self.line,
                    column,
                    value,
                });
            }
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines_of(text: &str, separator: u8) -> Vec<(usize, Vec<String>)> {
        let mut r = RecordReader::new(text.as_bytes(), "t.csv", separator);
        let mut out = Vec::new();
        while let Some(rec) = r.next_record().unwrap() {
            out.push((rec.line(), rec.fields().map(str::to_owned).collect()));
        }
        out
    }

    #[test]
    fn line_numbers_count_empty_lines_and_every_line_ending() {
        let got = lines_of("a;b\n\n c ; d \r\n\r\ne\rf\n", b';');
        let lines: Vec<usize> = got.iter().map(|(l, _)| *l).collect();
        assert_eq!(lines, [1, 3, 5, 6]);
        assert_eq!(got[1].1, ["c", "d"]);
    }

    #[test]
    fn quotes_are_ordinary_characters() {
        let got = lines_of("a,\"b,c\"\n", b',');
        assert_eq!(got[0].1, ["a", "\"b", "c\""]);
    }

    #[test]
    fn invalid_utf8_names_line_and_field() {
        let mut r = RecordReader::new(&b"a,b\nc,\xff\n"[..], "t.csv", b',');
        assert!(r.next_record().unwrap().is_some());
        let e = r.next_record().unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::NotUtf8 {
                    line: 2,
                    field: 2,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn a_line_past_the_limit_is_refused_with_its_start_escaped() {
        let text = format!("a,b\r\n\nc,d\n\0{}\n", "x".repeat(100));
        let mut r = RecordReader::with_line_limit(text.as_bytes(), "t.csv", b',', 50);
        assert!(r.next_record().unwrap().is_some());
        assert!(r.next_record().unwrap().is_some());
        let e = r.next_record().unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::LineTooLong {
                    line: 4,
                    limit: 50,
                    ..
                }
            ),
            "{e}"
        );
        let message = e.to_string();
        assert!(message.starts_with("t.csv:4:"), "{message}");
        assert!(message.contains("\\0xxx"), "{message}");
        assert!(!message.contains('\0'), "{message}");
        // Lines up to the limit are fine.
        let text = format!("{}\n", "y".repeat(50));
        let mut r = RecordReader::with_line_limit(text.as_bytes(), "t.csv", b',', 50);
        assert!(r.next_record().unwrap().is_some());
    }

    #[test]
    fn a_long_input_without_line_endings_stops_at_the_limit() {
        // An endless stream of NULs: reading must stop soon after the limit.
        let mut r = RecordReader::new(io::repeat(0), "zeros", b',');
        let e = r.next_record().unwrap_err();
        assert!(
            matches!(
                e,
                TraceError::LineTooLong {
                    line: 1,
                    limit: MAX_LINE_BYTES,
                    ..
                }
            ),
            "{e}"
        );
        assert!(!e.to_string().contains('\0'));
    }

    #[test]
    fn printable_escapes_and_truncates() {
        assert_eq!(printable("a\0b\u{1b}"), "a\\0b\\u{1b}");
        let long = "x".repeat(1000);
        let p = printable(&long);
        assert_eq!(p.len(), QUOTED_CHARS + 3);
        assert!(p.ends_with("..."));
    }
}
