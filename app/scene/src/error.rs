//! Scene loading errors that point at the scene file's line and column.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A place in a scene file, 1-based like an editor shows it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The scene file, as given to [`super::load_scene`].
    pub file: PathBuf,
    /// Line number, starting at 1.
    pub line: usize,
    /// Column number in characters, starting at 1.
    pub column: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
    }
}

/// Why a scene could not be loaded. Every variant but [`SceneError::Read`] names the scene
/// file, line and column, and the dotted field (`object.diameter_m`) it is about.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file itself could not be read.
    #[error("{}: cannot read the scene file: {error}", path.display())]
    Read {
        /// The scene file.
        path: PathBuf,
        /// What the operating system said (in the message, so not also a source).
        error: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("{at}: in `{field}`: TOML syntax error: {message}")]
    Syntax {
        /// Where the parser stopped.
        at: Location,
        /// The dotted key being parsed, as far as it could be told (`(top level)` if none).
        field: String,
        /// What the parser expected.
        message: String,
    },
    /// Valid TOML, but a field is unknown, missing, of the wrong type or out of range.
    #[error("{at}: `{field}`: {message}")]
    Invalid {
        /// Where the field (or its table, for a missing field) is.
        at: Location,
        /// The dotted field name.
        field: String,
        /// What was expected and what was found.
        message: String,
    },
    /// A file the scene refers to is missing or broken.
    #[error("{at}: `{field}`: {}: {reason}", asset.display())]
    Asset {
        /// Where the field naming the asset is.
        at: Location,
        /// The dotted field name.
        field: String,
        /// The asset file, resolved against the scene file's folder.
        asset: PathBuf,
        /// The underlying reason.
        reason: String,
    },
}

impl SceneError {
    /// The location in the scene file, when there is one.
    pub fn location(&self) -> Option<&Location> {
        match self {
            SceneError::Read { .. } => None,
            SceneError::Syntax { at, .. }
            | SceneError::Invalid { at, .. }
            | SceneError::Asset { at, .. } => Some(at),
        }
    }

    /// The dotted field name, when there is one.
    pub fn field(&self) -> Option<&str> {
        match self {
            SceneError::Read { .. } => None,
            SceneError::Syntax { field, .. }
            | SceneError::Invalid { field, .. }
            | SceneError::Asset { field, .. } => Some(field),
        }
    }
}

/// The scene file's text and name, to turn byte offsets into [`Location`]s.
pub(crate) struct Source<'a> {
    /// The scene file path as given.
    pub file: &'a Path,
    /// Its text.
    pub text: &'a str,
}

impl Source<'_> {
    /// The location of a byte offset (clamped to the text).
    pub fn location(&self, offset: usize) -> Location {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before[line_start..].chars().count() + 1;
        Location {
            file: self.file.to_path_buf(),
            line,
            column,
        }
    }

    /// An [`SceneError::Invalid`] at a span.
    pub fn invalid(
        &self,
        span: Range<usize>,
        field: &str,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            at: self.location(span.start),
            field: field.to_owned(),
            message: message.into(),
        }
    }

    /// An [`SceneError::Asset`] at a span.
    pub fn asset(
        &self,
        span: Range<usize>,
        field: &str,
        asset: &Path,
        reason: impl Into<String>,
    ) -> SceneError {
        SceneError::Asset {
            at: self.location(span.start),
            field: field.to_owned(),
            asset: asset.to_path_buf(),
            reason: reason.into(),
        }
    }

    /// Converts a `toml` parse or deserialisation error, recovering the dotted field name
    /// from the error's span.
    pub fn toml_error(&self, err: &toml::de::Error) -> SceneError {
        let offset = err.span().map_or(0, |s| s.start);
        let at = self.location(offset);
        let message = err.message().trim().to_owned();
        match toml::de::DeTable::parse(self.text) {
            // An array or inline table left open is only noticed where the parser gives up,
            // often in a later table: report the bracket that was never closed.
            Err(_) => match unclosed_bracket(self.text, offset) {
                Some((open, bracket)) => {
                    let stop = self.location(offset);
                    let (what, close) = if bracket == '[' {
                        ("array", ']')
                    } else {
                        ("inline table", '}')
                    };
                    SceneError::Syntax {
                        at: self.location(open),
                        field: self.textual_key_path(open),
                        message: format!(
                            "this {what} is never closed with `{close}` (the parser stopped at \
                             line {}, column {}: {message})",
                            stop.line, stop.column
                        ),
                    }
                }
                None => SceneError::Syntax {
                    at,
                    field: self.textual_key_path(offset),
                    message,
                },
            },
            Ok(root) => {
                let mut path = Vec::new();
                key_path_at(root.get_ref(), offset, &mut path);
                // A missing field is reported at its table: add the field's own name.
                if let Some(name) = backticked_after(&message, "missing field ") {
                    path.push(name.to_owned());
                }
                let field = if path.is_empty() {
                    "(top level)".to_owned()
                } else {
                    path.join(".")
                };
                SceneError::Invalid {
                    at,
                    field,
                    message: in_words(&message),
                }
            }
        }
    }

    /// The dotted key on the line of `offset`, found from the text alone (for syntax errors,
    /// where no parse tree exists): the last `[table]` header before it plus the line's key.
    fn textual_key_path(&self, offset: usize) -> String {
        let loc = self.location(offset);
        let mut table = String::new();
        let mut key = None;
        for (i, line) in self.text.lines().enumerate() {
            let trimmed = line.trim();
            if i + 1 == loc.line {
                if let Some(eq) = trimmed.find('=') {
                    let k = trimmed[..eq].trim().trim_matches('"');
                    if !k.is_empty() && !k.starts_with('[') {
                        key = Some(k.to_owned());
                    }
                } else if let Some(header) = table_header(trimmed) {
                    table = header;
                }
                break;
            }
            if let Some(header) = table_header(trimmed) {
                table = header;
            }
        }
        match (table.is_empty(), key) {
            (true, None) => "(top level)".to_owned(),
            (true, Some(k)) => k,
            (false, None) => table,
            (false, Some(k)) => format!("{table}.{k}"),
        }
    }
}

/// The byte offset and kind (`[` or `{`) of the outermost array or inline table that is open
/// at `offset` and still open at the end of `text`, if any. Strings and comments are skipped;
/// a `[` that starts a line outside any value is a table header.
fn unclosed_bracket(text: &str, offset: usize) -> Option<(usize, char)> {
    let bytes = text.as_bytes();
    let mut stack: Vec<(usize, char)> = Vec::new();
    let mut open_at_offset = None;
    let mut line_start = true;
    let mut i = 0;
    while i < bytes.len() {
        if i >= offset && open_at_offset.is_none() {
            open_at_offset = Some(stack.first().copied());
        }
        let c = bytes[i];
        match c {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'"' | b'\'' => {
                let triple = bytes[i..].starts_with(&[c, c, c]);
                let quote_len = if triple { 3 } else { 1 };
                i += quote_len;
                while i < bytes.len() {
                    if c == b'"' && bytes[i] == b'\\' {
                        i += 2;
                        continue;
                    }
                    if !triple && bytes[i] == b'\n' {
                        break; // an unterminated one-line string ends at its line
                    }
                    if bytes[i] == c && (!triple || bytes[i..].starts_with(&[c, c, c])) {
                        i += quote_len;
                        break;
                    }
                    i += 1;
                }
                line_start = false;
                continue;
            }
            b'[' if line_start && stack.is_empty() => {
                // A `[table]` or `[[array of tables]]` header: skip to its end of line.
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'[' | b'{' => stack.push((i, c as char)),
            b']' | b'}' => {
                stack.pop();
            }
            _ => {}
        }
        if c == b'\n' {
            line_start = true;
        } else if !c.is_ascii_whitespace() {
            line_start = false;
        }
        i += 1;
    }
    let candidate = open_at_offset.unwrap_or_else(|| stack.first().copied())?;
    stack.contains(&candidate).then_some(candidate)
}

/// A value of the wrong type in words: serde's `invalid type: string "x", expected f32` as
/// `expected a number, found string "x"`, the Rust type names (`f32`, `i64`) said as what they
/// hold and a sequence as TOML's array; any other message as it is.
fn in_words(message: &str) -> String {
    const NAMES: [(&str, &str); 4] = [
        ("f32", "a number"),
        ("f64", "a number"),
        ("i64", "a whole number"),
        ("a sequence", "an array"),
    ];
    let Some(rest) = ["invalid type: ", "invalid value: "]
        .iter()
        .find_map(|p| message.strip_prefix(p))
    else {
        return message.to_owned();
    };
    let Some((found, expected)) = rest.rsplit_once(", expected ") else {
        return message.to_owned();
    };
    let expected = NAMES
        .iter()
        .find(|(name, _)| *name == expected)
        .map_or(expected, |(_, words)| words);
    let found = found.replace(" as i128", "").replace(" as u128", "");
    format!("expected {expected}, found {found}")
}

fn table_header(line: &str) -> Option<String> {
    let inner = line.strip_prefix('[')?;
    let end = inner.find(']')?;
    let name = inner[..end].trim_matches(['[', ']', ' ']).trim();
    (!name.is_empty()).then(|| name.replace([' ', '"'], ""))
}

fn backticked_after<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    let rest = &message[message.find(prefix)? + prefix.len()..];
    let rest = rest.strip_prefix('`')?;
    Some(&rest[..rest.find('`')?])
}

/// Appends to `path` the keys leading to the deepest entry whose key or value contains
/// `offset`; returns whether one was found. A `[table]`'s own span covers only its header,
/// so tables are searched inside before their span is looked at.
fn key_path_at(table: &toml::de::DeTable<'_>, offset: usize, path: &mut Vec<String>) -> bool {
    for (key, value) in table {
        path.push(key.get_ref().to_string());
        if descend(value.get_ref(), offset, path)
            || key.span().contains(&offset)
            || value.span().contains(&offset)
        {
            return true;
        }
        path.pop();
    }
    false
}

fn descend(value: &toml::de::DeValue<'_>, offset: usize, path: &mut Vec<String>) -> bool {
    match value {
        toml::de::DeValue::Table(t) => key_path_at(t, offset, path),
        toml::de::DeValue::Array(items) => items.iter().any(|item| match item.get_ref() {
            toml::de::DeValue::Table(t) => key_path_at(t, offset, path),
            _ => false,
        }),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unclosed_array_is_reported_where_it_opens() {
        let text = "[object]\nmodel = \"m.glb\" # [not a bracket]\nposition_m = [0.0, -0.26, -1.5\n\n[light]\nposition_m = [0.0, 1.0, -1.0]\n";
        let stopped = text.find("[light]").unwrap();
        let (open, kind) = unclosed_bracket(text, stopped).unwrap();
        assert_eq!(kind, '[');
        let src = Source {
            file: Path::new("s.toml"),
            text,
        };
        assert_eq!(src.location(open).line, 3);
        assert_eq!(src.textual_key_path(open), "object.position_m");
    }

    #[test]
    fn a_closed_multi_line_array_is_not_blamed_for_an_error_inside_it() {
        let text = "[object]\npos = [\n  1.0,\n  x,\n]\ns = \"a]b\"\n";
        assert_eq!(unclosed_bracket(text, text.find('x').unwrap()), None);
        let text = "a = \"[\" # {\nb = '''[\n'''\nc = [1, {x = 2}]\nd = = 1\n";
        assert_eq!(unclosed_bracket(text, text.find("= =").unwrap()), None);
    }

    #[test]
    fn type_errors_are_said_in_words() {
        assert_eq!(
            in_words("invalid type: string \"x\", expected f32"),
            "expected a number, found string \"x\""
        );
        assert_eq!(
            in_words("invalid type: integer `99999999999999999999` as i128, expected i64"),
            "expected a whole number, found integer `99999999999999999999`"
        );
        assert_eq!(in_words("missing field `model`"), "missing field `model`");
    }

    #[test]
    fn location_counts_lines_and_characters_from_one() {
        let src = Source {
            file: Path::new("s.toml"),
            text: "a = 1\nbé = 2\n",
        };
        assert_eq!(src.location(0).to_string(), "s.toml:1:1");
        // 'b', 'é' (2 bytes), ' ' -> offset 10 is the space after bé: column 3.
        assert_eq!(src.location(9).to_string(), "s.toml:2:3");
        assert_eq!(src.location(1000).line, 3);
    }

    #[test]
    fn textual_key_path_uses_last_header() {
        let src = Source {
            file: Path::new("s.toml"),
            text: "[object]\nmodel = \"x\"\n[light]\nposition_m = [1, 2\n",
        };
        let offset = src.text.find("[1").unwrap();
        assert_eq!(src.textual_key_path(offset), "light.position_m");
    }
}
