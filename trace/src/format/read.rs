//! Reading a trace: the version and column header lines, then one checked sample per line.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use glam::{Quat, Vec3};

use super::edit::{EDIT_TAG, EditRecord, check_edit, parse_edit};
use super::event::{EVENT_TAG, EventRecord, check_event, parse_event};
use super::report::parse_report;
use super::validate::{Preceding, check_sample};
use super::views::{VIEWS_TAG, ViewsRecord, check_views, parse_views};
use super::{
    COLUMNS, COLUMNS_V1_1, COMBINED, FIXATION, LEFT, PUPILS, RIGHT, TraceError, TraceSample,
    TraceVersion, VERSION_PREFIX, clean_ray,
};
use crate::frame::{GazeRay, GazeSample, Pose};
use crate::records::{Record, RecordReader, printable};

/// Column names of the three columns starting at `col`.
fn names3(col: usize) -> [&'static str; 3] {
    [COLUMNS[col], COLUMNS[col + 1], COLUMNS[col + 2]]
}

/// Parses three consecutive float fields starting at column `col`.
fn parse_vec3(record: &Record<'_>, col: usize) -> Result<Vec3, TraceError> {
    record.vec3([col, col + 1, col + 2], names3(col))
}

/// Parses a required integer time field.
fn parse_time(record: &Record<'_>, col: usize) -> Result<i64, TraceError> {
    record.i64(col, COLUMNS[col], "an integer number of nanoseconds")
}

/// Parses a ray group: `valid, origin xyz, dir xyz` starting at `col`. The caller has checked
/// that the valid flag is present.
fn parse_ray(record: &Record<'_>, col: usize) -> Result<GazeRay, TraceError> {
    let valid = match record.field(col) {
        "1" => true,
        "0" => false,
        other => return Err(record.bad(COLUMNS[col], other, "0 or 1")),
    };
    if !valid {
        // An invalid ray's numbers are meaningless: they may be empty and are not read.
        return Ok(GazeRay::INVALID);
    }
    let origin = parse_vec3(record, col + 1)?;
    let direction = parse_vec3(record, col + 4)?;
    Ok(clean_ray(GazeRay {
        origin,
        direction,
        valid,
    }))
}

/// Parses an optional pupil diameter column (empty: unknown). Its range is checked with the
/// rest of the sample.
fn parse_pupil(record: &Record<'_>, col: usize) -> Result<Option<f32>, TraceError> {
    if record.field(col).is_empty() {
        return Ok(None);
    }
    record.f32(col, COLUMNS_V1_1[col]).map(Some)
}

/// Parses one sample line of a trace of `version` without the time-order checks.
fn parse_record(record: &Record<'_>, version: TraceVersion) -> Result<TraceSample, TraceError> {
    record.expect_len(version.columns().len())?;
    let time_ns = parse_time(record, 0)?;
    let position = parse_vec3(record, 1)?;
    let orientation = Quat::from_xyzw(
        record.f32(4, COLUMNS[4])?,
        record.f32(5, COLUMNS[5])?,
        record.f32(6, COLUMNS[6])?,
        record.f32(7, COLUMNS[7])?,
    );
    let gaze_time_ns = parse_time(record, 8)?;
    let left = parse_ray(record, LEFT)?;
    let right = parse_ray(record, RIGHT)?;

    let combined = match optional_group(record, COMBINED, 7, "combined")? {
        false => None,
        true => Some(parse_ray(record, COMBINED)?),
    };
    let fixation = match optional_group(record, FIXATION, 3, "fixation")? {
        false => None,
        true => Some(parse_vec3(record, FIXATION)?),
    };
    let pupil_diameter_m = match version {
        TraceVersion::V1 => [None, None],
        TraceVersion::V1_1
        | TraceVersion::V1_2
        | TraceVersion::V1_3
        | TraceVersion::V1_4
        | TraceVersion::V1_5 => [
            parse_pupil(record, PUPILS)?,
            parse_pupil(record, PUPILS + 1)?,
        ],
    };
    let report = if version.has_reports() {
        parse_report(record)?
    } else {
        None
    };
    Ok(TraceSample {
        time_ns,
        head: Pose {
            position,
            orientation,
        },
        gaze: GazeSample {
            sample_time_ns: gaze_time_ns,
            left,
            right,
            combined,
            fixation,
            pupil_diameter_m,
            report,
        },
    })
}

/// Whether an optional group is present. All empty: absent. For the combined ray, a `0` flag
/// with empty numbers is allowed (present but invalid); otherwise every field must be filled.
fn optional_group(
    record: &Record<'_>,
    col: usize,
    len: usize,
    group: &'static str,
) -> Result<bool, TraceError> {
    let empty = |i: usize| record.field(col + i).is_empty();
    if (0..len).all(empty) {
        return Ok(false);
    }
    let flag_only_invalid = group == "combined" && record.field(col) == "0";
    let needed = if flag_only_invalid { 1 } else { len };
    if let Some(i) = (0..needed).find(|&i| empty(i)) {
        return Err(TraceError::PartialGroup {
            file: record.file().to_owned(),
            line: record.line(),
            group,
            column: COLUMNS[col + i],
        });
    }
    Ok(true)
}

/// Streams [`TraceSample`]s out of a trace of any version this crate reads.
///
/// The version and column header lines are checked by the constructor; samples are parsed
/// and checked one line at a time as the iterator is advanced. After the first error the
/// iterator ends.
pub struct TraceReader<R: Read> {
    /// The lines being read.
    records: RecordReader<R>,
    /// What the ordering checks need of the samples before.
    previous: Option<Preceding>,
    /// Set after an error or the end of the input: the iterator is fused.
    done: bool,
    /// The version named by the first line.
    version: TraceVersion,
    /// The edit lines read so far (version 1.2 and later), in file order.
    edits: Vec<EditRecord>,
    /// The event lines read so far (version 1.4), in file order.
    events: Vec<EventRecord>,
    /// The views lines read so far (version 1.5), in file order.
    views: Vec<ViewsRecord>,
    /// Time of the last edit or event line read.
    previous_line_ns: Option<i64>,
}

impl TraceReader<BufReader<File>> {
    /// Opens a trace file and checks its version and column header lines.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = File::open(path).map_err(|source| TraceError::Io {
            file: name.clone(),
            context: "opening trace".to_owned(),
            source,
        })?;
        TraceReader::new(BufReader::new(file), name)
    }
}

impl<R: Read> TraceReader<R> {
    /// Reads a trace from any reader; `name` is used in error messages. Checks the version
    /// and column header lines.
    pub fn new(reader: R, name: impl Into<String>) -> Result<Self, TraceError> {
        let mut this = TraceReader {
            records: RecordReader::new(reader, name, b','),
            previous: None,
            done: false,
            version: TraceVersion::V1,
            edits: Vec::new(),
            events: Vec::new(),
            views: Vec::new(),
            previous_line_ns: None,
        };
        this.read_headers()?;
        Ok(this)
    }

    /// The version of the trace, from its first line.
    pub fn version(&self) -> TraceVersion {
        self.version
    }

    /// The scene edits read so far (the lines among the samples already read; all of them once
    /// the iterator has ended), taken out of the reader.
    pub fn take_edits(&mut self) -> Vec<EditRecord> {
        std::mem::take(&mut self.edits)
    }

    /// The session events read so far (the lines among the samples already read; all of them
    /// once the iterator has ended), taken out of the reader.
    pub fn take_events(&mut self) -> Vec<EventRecord> {
        std::mem::take(&mut self.events)
    }

    /// The views lines read so far (the lines among the samples already read; all of them
    /// once the iterator has ended), taken out of the reader.
    pub fn take_views(&mut self) -> Vec<ViewsRecord> {
        std::mem::take(&mut self.views)
    }

    /// The file name used in error messages.
    pub fn name(&self) -> &str {
        self.records.file()
    }

    /// Checks the version line and the column header line.
    fn read_headers(&mut self) -> Result<(), TraceError> {
        let name = self.records.file().to_owned();
        let Some(first) = self.records.next_record()? else {
            return Err(TraceError::Empty {
                file: name,
                expected: "first line `# vitreous-trace v1`",
            });
        };
        let text = first.text();
        let text = text.trim_start_matches('\u{feff}').trim();
        match text.strip_prefix(VERSION_PREFIX) {
            Some("v1") => self.version = TraceVersion::V1,
            Some("v1.1") => self.version = TraceVersion::V1_1,
            Some("v1.2") => self.version = TraceVersion::V1_2,
            Some("v1.3") => self.version = TraceVersion::V1_3,
            Some("v1.4") => self.version = TraceVersion::V1_4,
            Some("v1.5") => self.version = TraceVersion::V1_5,
            Some(version) => {
                return Err(TraceError::UnsupportedVersion {
                    file: name,
                    line: first.line(),
                    version: printable(version.trim()),
                });
            }
            None => {
                return Err(TraceError::BadVersionLine {
                    file: name,
                    line: first.line(),
                    found: printable(text),
                });
            }
        }
        let Some(header) = self.records.next_content_record()? else {
            return Err(TraceError::MissingColumnHeader { file: name });
        };
        let columns = self.version.columns();
        for i in 0..header.len().max(columns.len()) {
            let found = if i < header.len() {
                header.field(i)
            } else {
                ""
            };
            let expected = columns.get(i).copied().unwrap_or("");
            if found != expected {
                return Err(TraceError::BadColumnHeader {
                    file: name,
                    line: header.line(),
                    column: i + 1,
                    found: printable(found),
                    expected,
                });
            }
        }
        Ok(())
    }

    /// Reads, parses and checks the next sample (keeping the edit lines before it).
    fn next_sample(&mut self) -> Result<Option<TraceSample>, TraceError> {
        let record = loop {
            let Some(record) = self.records.next_content_record()? else {
                return Ok(None);
            };
            let previous_ns = self.previous.map(|p| p.time_ns());
            if self.version.has_events() && record.field(0) == EVENT_TAG {
                let raw = parse_event(&record)?;
                let latest = previous_ns.into_iter().chain(self.previous_line_ns).max();
                let event = check_event(record.file(), record.line(), &raw, latest)?;
                self.previous_line_ns = Some(event.time_ns);
                self.events.push(event);
                continue;
            }
            if self.version.has_views() && record.field(0) == VIEWS_TAG {
                let raw = parse_views(&record)?;
                let latest = previous_ns.into_iter().chain(self.previous_line_ns).max();
                let views = check_views(record.file(), record.line(), &raw, latest)?;
                self.previous_line_ns = Some(views.time_ns);
                self.views.push(views);
                continue;
            }
            if !(self.version.has_edits() && record.field(0) == EDIT_TAG) {
                break record;
            }
            let raw = parse_edit(&record)?;
            let edit = check_edit(
                record.file(),
                record.line(),
                &raw,
                previous_ns,
                self.previous_line_ns,
            )?;
            self.previous_line_ns = Some(edit.time_ns);
            self.edits.push(edit);
        };
        let raw = parse_record(&record, self.version)?;
        let sample = check_sample(record.file(), record.line(), &raw, self.previous)?;
        self.previous = Some(Preceding::after(self.previous, &sample));
        Ok(Some(sample))
    }
}

impl<R: Read> Iterator for TraceReader<R> {
    type Item = Result<TraceSample, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.next_sample() {
            Ok(Some(sample)) => Some(Ok(sample)),
            Ok(None) => {
                self.done = true;
                None
            }
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

impl<R: Read> std::iter::FusedIterator for TraceReader<R> {}

/// Reads a whole trace file into memory, with its scene edits (none before version 1.2).
pub fn read_trace_with_edits(
    path: impl AsRef<Path>,
) -> Result<(Vec<TraceSample>, Vec<EditRecord>), TraceError> {
    let mut reader = TraceReader::open(path)?;
    let samples = reader.by_ref().collect::<Result<Vec<_>, _>>()?;
    Ok((samples, reader.take_edits()))
}

/// A whole trace file: its samples, scene edits and session events.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Recording {
    /// The samples.
    pub samples: Vec<TraceSample>,
    /// The scene edits (none before version 1.2).
    pub edits: Vec<EditRecord>,
    /// The session events (none before version 1.4).
    pub events: Vec<EventRecord>,
    /// The eyes the headset drew from (none before version 1.5).
    pub views: Vec<ViewsRecord>,
}

/// Reads a whole trace file into memory, with its scene edits and session events.
pub fn read_recording(path: impl AsRef<Path>) -> Result<Recording, TraceError> {
    let mut reader = TraceReader::open(path)?;
    let samples = reader.by_ref().collect::<Result<Vec<_>, _>>()?;
    Ok(Recording {
        samples,
        edits: reader.take_edits(),
        events: reader.take_events(),
        views: reader.take_views(),
    })
}

/// Reads a whole trace file into memory (the samples; scene edits and events are skipped).
pub fn read_trace(path: impl AsRef<Path>) -> Result<Vec<TraceSample>, TraceError> {
    TraceReader::open(path)?.collect()
}

#[cfg(test)]
mod tests;
