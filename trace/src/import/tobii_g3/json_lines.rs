//! Reading a Tobii Pro Glasses 3 data file line by line: gzip-compressed as the glasses write
//! it (`gazedata.gz`), or already decompressed (`gazedata`), told apart by the gzip magic
//! bytes. Lines are bounded in length and numbered from 1 for messages.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use flate2::read::MultiGzDecoder;

use crate::import::RecordingError;
use crate::records::MAX_LINE_BYTES;

/// The first two bytes of every gzip stream.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Opens `path` for reading its text, decompressing when it is gzip. `why` says what the
/// file holds, for the message when it is missing.
pub(super) fn open_text(
    path: &Path,
    why: &'static str,
) -> Result<Box<dyn BufRead>, RecordingError> {
    let name = path.display().to_string();
    let file = File::open(path).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => RecordingError::Missing {
            file: name.clone(),
            why,
        },
        _ => RecordingError::Io {
            file: name.clone(),
            context: "opening".to_owned(),
            source,
        },
    })?;
    text_reader(BufReader::new(file), &name)
}

/// The text of `reader`, decompressed when it starts with the gzip magic bytes.
pub(super) fn text_reader<'a, R: BufRead + 'a>(
    mut reader: R,
    name: &str,
) -> Result<Box<dyn BufRead + 'a>, RecordingError> {
    let start = reader.fill_buf().map_err(|source| RecordingError::Io {
        file: name.to_owned(),
        context: "reading".to_owned(),
        source,
    })?;
    if start.starts_with(&GZIP_MAGIC) {
        Ok(Box::new(BufReader::new(MultiGzDecoder::new(reader))))
    } else {
        Ok(Box::new(reader))
    }
}

/// Calls `f` with the number and text of every non-blank line (line ending removed).
pub(super) fn for_each_line(
    mut reader: impl BufRead,
    name: &str,
    mut f: impl FnMut(usize, &str) -> Result<(), RecordingError>,
) -> Result<(), RecordingError> {
    let mut buf = Vec::new();
    let mut line = 0usize;
    loop {
        buf.clear();
        line += 1;
        let limit = MAX_LINE_BYTES as u64 + 2;
        let n = (&mut reader)
            .take(limit)
            .read_until(b'\n', &mut buf)
            .map_err(|source| RecordingError::Io {
                file: name.to_owned(),
                context: format!(
                    "reading line {line} (a gzip stream that ends early means the file was cut short)"
                ),
                source,
            })?;
        if n == 0 {
            return Ok(());
        }
        let text = buf.strip_suffix(b"\n").unwrap_or(&buf);
        let text = text.strip_suffix(b"\r").unwrap_or(text);
        if text.len() > MAX_LINE_BYTES {
            return Err(RecordingError::LineTooLong {
                file: name.to_owned(),
                line,
                limit: MAX_LINE_BYTES,
            });
        }
        let text = std::str::from_utf8(text).map_err(|e| RecordingError::Json {
            file: name.to_owned(),
            line,
            message: format!("not UTF-8 text (byte {})", e.valid_up_to() + 1),
        })?;
        if text.trim().is_empty() {
            continue;
        }
        f(line, text)?;
    }
}
