//! Neon's binary streams: `NAME psN.raw` (packed little-endian records, layout in
//! `NAME.dtype`) paired with `NAME psN.time` (one little-endian u64 nanosecond timestamp per
//! record), in parts N = 1, 2, ... read in order.
//!
//! A `.dtype` file is a numpy structured dtype written as a Python list of `(name, type)`
//! pairs, e.g. `[("x", "float32"), ("y", "float32")]`: packed, no padding. Only what these
//! imports need is understood: scalar fields of the numpy types below, little-endian or
//! native. A recording without a `.dtype` file is read with the layout the stream has always
//! had (given by the caller).

use std::path::Path;

use crate::import::RecordingError;

/// A scalar numpy field type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    /// `float32`, `f4`.
    F32,
    /// `float64`, `f8`.
    F64,
    /// `int8` .. `int64`, by size in bytes.
    Int(usize),
    /// `uint8` .. `uint64`, `bool`, by size in bytes.
    UInt(usize),
}

impl Scalar {
    /// Size in bytes.
    fn size(self) -> usize {
        match self {
            Scalar::F32 => 4,
            Scalar::F64 => 8,
            Scalar::Int(n) | Scalar::UInt(n) => n,
        }
    }

    /// The numpy name, for messages.
    fn name(self) -> String {
        match self {
            Scalar::F32 => "float32".to_owned(),
            Scalar::F64 => "float64".to_owned(),
            Scalar::Int(n) => format!("int{}", n * 8),
            Scalar::UInt(n) => format!("uint{}", n * 8),
        }
    }

    /// Parses a numpy type name or type code (`float32`, `<f4`, `=i8`, `|u1`, ...);
    /// `Err` says why not.
    fn parse(text: &str) -> Result<Scalar, String> {
        let (order, code) = match text.chars().next() {
            Some(c @ ('<' | '>' | '=' | '|')) => (Some(c), &text[1..]),
            _ => (None, text),
        };
        if order == Some('>') {
            return Err(format!("`{text}` is big-endian; Neon writes little-endian"));
        }
        let scalar = match code {
            "float32" | "f4" | "single" => Scalar::F32,
            "float64" | "f8" | "double" | "float" | "d" => Scalar::F64,
            "int8" | "i1" | "b" => Scalar::Int(1),
            "int16" | "i2" | "h" => Scalar::Int(2),
            "int32" | "i4" | "i" => Scalar::Int(4),
            "int64" | "i8" | "int" | "q" => Scalar::Int(8),
            "uint8" | "u1" | "B" | "bool" | "?" | "b1" => Scalar::UInt(1),
            "uint16" | "u2" | "H" => Scalar::UInt(2),
            "uint32" | "u4" | "I" => Scalar::UInt(4),
            "uint64" | "u8" | "Q" => Scalar::UInt(8),
            _ => return Err(format!("unsupported field type `{text}`")),
        };
        Ok(scalar)
    }

    /// Reads a value of this type from the start of `bytes` (at least `size()` long).
    fn read(self, bytes: &[u8]) -> f64 {
        let mut b = [0u8; 8];
        b[..self.size()].copy_from_slice(&bytes[..self.size()]);
        match self {
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
            Scalar::UInt(_) => u64::from_le_bytes(b) as f64,
            Scalar::Int(n) => {
                // Sign-extend from n bytes.
                let shift = 64 - 8 * n as u32;
                ((i64::from_le_bytes(b) << shift) >> shift) as f64
            }
        }
    }
}

/// A record layout: named fields at byte offsets.
#[derive(Clone, Debug)]
pub(super) struct Layout {
    /// Fields in record order: name, type, offset in bytes.
    fields: Vec<(String, Scalar, usize)>,
    /// Record size, bytes.
    size: usize,
    /// Where the layout comes from (the `.dtype` file, or a description of the default).
    source: String,
}

impl Layout {
    /// A layout from `(name, type)` pairs, packed.
    pub(super) fn packed(fields: &[(&str, Scalar)], source: impl Into<String>) -> Layout {
        let mut offset = 0;
        let fields = fields
            .iter()
            .map(|&(name, ty)| {
                let field = (name.to_owned(), ty, offset);
                offset += ty.size();
                field
            })
            .collect();
        Layout {
            fields,
            size: offset,
            source: source.into(),
        }
    }

    /// Parses the text of a `.dtype` file named `file`.
    pub(super) fn parse(text: &str, file: &str) -> Result<Layout, RecordingError> {
        let err = |message: String| RecordingError::Dtype {
            file: file.to_owned(),
            message,
        };
        let tokens = tokenize(text).map_err(err)?;
        let mut pairs: Vec<(String, Scalar)> = Vec::new();
        let mut it = tokens.iter().peekable();
        let expect = |tok: Option<&Token>, what: Token| -> Result<(), RecordingError> {
            match tok {
                Some(t) if *t == what => Ok(()),
                other => Err(err(format!(
                    "expected {what:?} in the dtype list, found {}",
                    other.map_or("the end".to_owned(), |t| format!("{t:?}"))
                ))),
            }
        };
        expect(it.next(), Token::Open('['))?;
        loop {
            match it.next() {
                Some(Token::Close(']')) => break,
                Some(Token::Open('(')) => {}
                other => {
                    return Err(err(format!(
                        "expected a `(name, type)` pair, found {}",
                        other.map_or("the end".to_owned(), |t| format!("{t:?}"))
                    )));
                }
            }
            let Some(Token::Str(name)) = it.next() else {
                return Err(err(
                    "a field pair must start with its name in quotes".to_owned()
                ));
            };
            expect(it.next(), Token::Comma)?;
            let Some(Token::Str(ty)) = it.next() else {
                return Err(err(format!(
                    "field `{name}`: its type must be a quoted string"
                )));
            };
            let ty = Scalar::parse(ty).map_err(|m| err(format!("field `{name}`: {m}")))?;
            if it.peek() == Some(&&Token::Comma) {
                it.next();
            }
            if it.next() != Some(&Token::Close(')')) {
                return Err(err(format!(
                    "field `{name}`: only scalar `(name, type)` fields are supported"
                )));
            }
            if pairs.iter().any(|(n, _)| n == name) {
                return Err(err(format!("field `{name}` appears twice")));
            }
            pairs.push((name.clone(), ty));
            if it.peek() == Some(&&Token::Comma) {
                it.next();
            }
        }
        if it.next().is_some() {
            return Err(err("text after the closing `]`".to_owned()));
        }
        if pairs.is_empty() {
            return Err(err("the dtype has no fields".to_owned()));
        }
        let borrowed: Vec<(&str, Scalar)> = pairs.iter().map(|(n, t)| (n.as_str(), *t)).collect();
        Ok(Layout::packed(&borrowed, file))
    }

    /// The offset of field `name`, which must have type `ty`.
    fn offset_of(&self, name: &str, ty: Scalar) -> Result<usize, RecordingError> {
        let err = |message: String| RecordingError::Dtype {
            file: self.source.clone(),
            message,
        };
        match self.fields.iter().find(|(n, _, _)| n == name) {
            Some(&(_, found, offset)) if found == ty => Ok(offset),
            Some(&(_, found, _)) => Err(err(format!(
                "field `{name}` is {}, expected {}",
                found.name(),
                ty.name()
            ))),
            None => Err(err(format!(
                "no field `{name}` ({} expected); fields: {}",
                ty.name(),
                self.fields
                    .iter()
                    .map(|(n, _, _)| n.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }
}

/// A token of a `.dtype` list.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Token {
    /// `[` or `(`.
    Open(char),
    /// `]` or `)`.
    Close(char),
    /// `,`.
    Comma,
    /// A quoted string, quotes removed.
    Str(String),
}

/// Splits `.dtype` text into tokens; `Err` names what is not understood.
fn tokenize(text: &str) -> Result<Vec<Token>, String> {
    let mut tokens = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '[' | '(' => tokens.push(Token::Open(c)),
            ']' | ')' => tokens.push(Token::Close(c)),
            ',' => tokens.push(Token::Comma),
            '"' | '\'' => {
                let mut s = String::new();
                loop {
                    match chars.next() {
                        Some(q) if q == c => break,
                        Some(ch) => s.push(ch),
                        None => return Err("a quoted name is not closed".to_owned()),
                    }
                }
                tokens.push(Token::Str(s));
            }
            c if c.is_whitespace() => {}
            other => {
                return Err(format!(
                    "unexpected `{}`: expected a list of (\"name\", \"type\") pairs",
                    other.escape_debug()
                ));
            }
        }
    }
    Ok(tokens)
}

/// The records of one stream: timestamps and the requested fields as `f64` (64-bit integers
/// lose precision past 2^53: below a microsecond for nanosecond times, which is fine here).
#[derive(Clone, Debug, Default)]
pub(super) struct Stream {
    /// Timestamp of every record, nanoseconds (Unix epoch), from the `.time` files.
    pub(super) times_ns: Vec<i64>,
    /// The requested fields of every record, record after record.
    values: Vec<f64>,
    /// Fields per record.
    width: usize,
    /// The `.raw` file of each part and the index of its first record.
    parts: Vec<(String, usize)>,
}

impl Stream {
    /// Number of records.
    pub(super) fn len(&self) -> usize {
        self.times_ns.len()
    }

    /// The requested fields of record `i`, in the order requested.
    pub(super) fn record(&self, i: usize) -> &[f64] {
        &self.values[i * self.width..(i + 1) * self.width]
    }

    /// The part file holding record `i` and the record's number (1-based) in it.
    pub(super) fn locate(&self, i: usize) -> (&str, usize) {
        let k = self.parts.partition_point(|&(_, start)| start <= i);
        match k.checked_sub(1).and_then(|k| self.parts.get(k)) {
            Some((file, start)) => (file, i - start + 1),
            None => ("", i + 1),
        }
    }
}

/// Reads stream `base` of the recording in `folder`: every `BASE psN.raw` with its
/// `BASE psN.time`, fields `wanted` (name and type), with the layout of `BASE.dtype` or
/// `default` when there is none. `None` when the recording has no part of the stream.
pub(super) fn read_stream(
    folder: &Path,
    base: &str,
    wanted: &[(&str, Scalar)],
    default: &[(&str, Scalar)],
) -> Result<Option<Stream>, RecordingError> {
    let parts = find_parts(folder, base)?;
    if parts.is_empty() {
        return Ok(None);
    }
    let dtype_path = folder.join(format!("{base}.dtype"));
    let layout = if dtype_path.is_file() {
        let name = dtype_path.display().to_string();
        let text = std::fs::read_to_string(&dtype_path).map_err(|source| RecordingError::Io {
            file: name.clone(),
            context: "reading".to_owned(),
            source,
        })?;
        Layout::parse(&text, &name)?
    } else {
        Layout::packed(
            default,
            format!(
                "{} (no {base}.dtype: the stream's usual layout assumed)",
                folder.display()
            ),
        )
    };
    let offsets = wanted
        .iter()
        .map(|&(name, ty)| layout.offset_of(name, ty).map(|o| (o, ty)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut stream = Stream {
        width: wanted.len(),
        ..Stream::default()
    };
    for n in parts {
        let raw = folder.join(format!("{base} ps{n}.raw"));
        let time = folder.join(format!("{base} ps{n}.time"));
        let (raw_name, time_name) = (raw.display().to_string(), time.display().to_string());
        let raw_bytes = read_file(&raw, "the stream's records")?;
        let time_bytes = read_file(&time, "each .raw part needs its .time part")?;
        for (bytes, file, size) in [
            (&raw_bytes, &raw_name, layout.size),
            (&time_bytes, &time_name, 8),
        ] {
            if bytes.len() % size != 0 {
                return Err(RecordingError::Truncated {
                    file: file.clone(),
                    bytes: bytes.len() as u64,
                    record_bytes: size,
                });
            }
        }
        let (records, times) = (raw_bytes.len() / layout.size, time_bytes.len() / 8);
        if records != times {
            return Err(RecordingError::CountMismatch {
                raw: raw_name,
                records,
                time: time_name,
                times,
            });
        }
        stream.parts.push((raw_name, stream.times_ns.len()));
        for (i, t) in time_bytes.chunks_exact(8).enumerate() {
            let t = u64::from_le_bytes(t.try_into().unwrap_or_default());
            let t = i64::try_from(t).map_err(|_| RecordingError::BadValue {
                file: time_name.clone(),
                at: format!("record {}", i + 1),
                field: "timestamp".to_owned(),
                found: t.to_string(),
                expected: "nanoseconds since 1970 that fit a signed 64-bit integer",
            })?;
            stream.times_ns.push(t);
        }
        for record in raw_bytes.chunks_exact(layout.size) {
            stream
                .values
                .extend(offsets.iter().map(|&(o, ty)| ty.read(&record[o..])));
        }
    }
    Ok(Some(stream))
}

/// The part numbers N of the files `BASE psN.raw` in `folder`, in increasing order.
fn find_parts(folder: &Path, base: &str) -> Result<Vec<u32>, RecordingError> {
    let entries = std::fs::read_dir(folder).map_err(|source| RecordingError::Io {
        file: folder.display().to_string(),
        context: "listing the recording folder".to_owned(),
        source,
    })?;
    let prefix = format!("{base} ps");
    let mut parts: Vec<u32> = entries
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            name.strip_prefix(&prefix)?
                .strip_suffix(".raw")?
                .parse()
                .ok()
        })
        .collect();
    parts.sort_unstable();
    Ok(parts)
}

/// The bytes of `path`; a missing file is [`RecordingError::Missing`].
fn read_file(path: &Path, why: &'static str) -> Result<Vec<u8>, RecordingError> {
    std::fs::read(path).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => RecordingError::Missing {
            file: path.display().to_string(),
            why,
        },
        _ => RecordingError::Io {
            file: path.display().to_string(),
            context: "reading".to_owned(),
            source,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dtype_files_as_neon_writes_them_parse() {
        let text =
            "[\n(\"timestamp_ns\", \"int64\"),\n('gyro_x', '<f4'), \n(\"q\", \"float32\",),\n]\n\n";
        let layout = Layout::parse(text, "imu.dtype").unwrap();
        assert_eq!(layout.size, 16);
        assert_eq!(layout.offset_of("gyro_x", Scalar::F32).unwrap(), 8);
        assert_eq!(layout.offset_of("q", Scalar::F32).unwrap(), 12);
        let e = layout
            .offset_of("gyro_x", Scalar::F64)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("imu.dtype") && e.contains("is float32, expected float64"),
            "{e}"
        );
        let e = layout
            .offset_of("nope", Scalar::F32)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no field `nope`") && e.contains("timestamp_ns, gyro_x, q"),
            "{e}"
        );
    }

    #[test]
    fn malformed_dtype_files_are_refused_with_the_reason() {
        for (text, needle) in [
            ("", "expected Open('[')"),
            ("[(\"x\", \">f4\")]", "big-endian"),
            ("[(\"x\", \"complex64\")]", "unsupported field type"),
            ("[(\"x\", \"f4\", (3,))]", "unexpected `3`"),
            ("[(\"x\", \"f4\"), (\"x\", \"f4\")]", "appears twice"),
            (
                "[(\"x\", \"f4\")",
                "expected a `(name, type)` pair, found the end",
            ),
            ("np.dtype([])", "unexpected `n`"),
            ("[]", "no fields"),
        ] {
            let e = Layout::parse(text, "g.dtype").unwrap_err().to_string();
            assert!(
                e.starts_with("g.dtype: ") && e.contains(needle),
                "{text}: {e}"
            );
        }
    }

    #[test]
    fn scalars_read_little_endian_and_sign_extend() {
        assert_eq!(Scalar::Int(4).read(&(-7i32).to_le_bytes()), -7.0);
        assert_eq!(Scalar::Int(2).read(&(-300i16).to_le_bytes()), -300.0);
        assert_eq!(Scalar::UInt(1).read(&[200]), 200.0);
        assert_eq!(Scalar::F32.read(&1.5f32.to_le_bytes()), 1.5);
        assert_eq!(Scalar::F64.read(&(-2.25f64).to_le_bytes()), -2.25);
        assert_eq!(Scalar::Int(8).read(&(-5i64).to_le_bytes()), -5.0);
    }
}
