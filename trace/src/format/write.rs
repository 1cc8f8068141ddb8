//! Writing a trace: the header lines, then one checked sample per line, flushed each time.

use std::io::{self, Write};
use std::path::Path;

use super::edit::{EditRecord, check_edit, format_edit};
use super::event::{EventRecord, check_event, format_event};
use super::report::write_report;
use super::validate::{Preceding, check_sample};
use super::views::{ViewsRecord, check_views, format_views};
use super::{AtomicFile, TraceError, TraceSample, TraceVersion};
use crate::frame::GazeRay;

/// Writes [`TraceSample`]s as a version-1.1 trace (version 1 and the pupil diameters), or as
/// version 1.2 with scene edits among them ([`TraceWriter::create_with_edits`]), or as version
/// 1.3 (1.2 and the tracker's report of each sample) when asked or when the first sample
/// carries a report.
///
/// Every sample is checked like the reader checks it (finite head pose, unit quaternion,
/// increasing times, gaze time not after the pose time) and flushed once written. The header
/// lines are written with the first sample (or by [`TraceWriter::finish`] when there is
/// none), because that sample decides whether the trace needs version 1.3; scene edits before
/// it wait with them. A report on a later sample of a trace that had to start as 1.1 or 1.2 is
/// left out (a header once written cannot grow columns), counted
/// ([`TraceWriter::reports_left_out`]) and logged once.
pub struct TraceWriter<W: Write> {
    /// Where the text goes.
    writer: W,
    /// File name used in error messages.
    name: String,
    /// Line number the next sample will have (1-based).
    line: usize,
    /// What the ordering checks need of the samples before.
    previous: Option<Preceding>,
    /// Time of the last edit or event written.
    previous_edit_ns: Option<i64>,
    /// The version asked for (1.1; 1.2 when edits may come; 1.3 for reports from the start).
    asked: TraceVersion,
    /// The version written, once the header lines are out.
    written: Option<TraceVersion>,
    /// Edit lines that came before the first sample, written after the header lines.
    pending_edits: String,
    /// Reports of samples that a version-1.1 or 1.2 trace could not hold.
    reports_left_out: u64,
    /// Reused line buffer.
    buf: String,
    /// What [`TraceWriter::finish`] does after flushing: nothing, or commit a file.
    complete: fn(&mut W) -> io::Result<()>,
}

impl TraceWriter<AtomicFile> {
    /// Starts a trace file. The trace is written to a temporary file in the same folder
    /// (flushed after every sample) and appears under `path`, replacing any earlier file, only
    /// when [`TraceWriter::finish`] succeeds; see [`AtomicFile`].
    pub fn create(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        TraceWriter::create_version(path, TraceVersion::V1_1)
    }

    /// [`TraceWriter::create`] for a version-1.2 trace (1.3 when its first sample carries a
    /// tracker report), which may hold scene edits ([`TraceWriter::write_edit`]).
    pub fn create_with_edits(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        TraceWriter::create_version(path, TraceVersion::V1_2)
    }

    /// [`TraceWriter::create`] of a trace of `version` (see [`TraceWriter::with_version`]).
    pub fn create_version(
        path: impl AsRef<Path>,
        version: TraceVersion,
    ) -> Result<Self, TraceError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = AtomicFile::create(path).map_err(|source| TraceError::Io {
            file: name.clone(),
            context: "creating trace".to_owned(),
            source,
        })?;
        let mut this = TraceWriter::with_version(file, name, version)?;
        this.complete = AtomicFile::commit;
        Ok(this)
    }
}

impl<W: Write> TraceWriter<W> {
    /// Writes a trace into any writer (named `<output>` in error messages).
    pub fn new(writer: W) -> Result<Self, TraceError> {
        TraceWriter::with_name(writer, "<output>")
    }

    /// Like [`TraceWriter::new`], with the name to use in error messages.
    pub fn with_name(writer: W, name: impl Into<String>) -> Result<Self, TraceError> {
        TraceWriter::with_version(writer, name, TraceVersion::V1_1)
    }

    /// Like [`TraceWriter::with_name`], writing `version`: 1.1 or 1.2, each written as 1.3 when
    /// the first sample carries a tracker report, or 1.3 (1 is written as 1.1).
    pub fn with_version(
        writer: W,
        name: impl Into<String>,
        version: TraceVersion,
    ) -> Result<Self, TraceError> {
        let asked = match version {
            TraceVersion::V1 => TraceVersion::V1_1,
            v => v,
        };
        Ok(TraceWriter {
            writer,
            name: name.into(),
            line: 3,
            previous: None,
            previous_edit_ns: None,
            asked,
            written: None,
            pending_edits: String::new(),
            reports_left_out: 0,
            buf: String::new(),
            complete: |_| Ok(()),
        })
    }

    /// The version written: known once the first sample is written (or the trace finished).
    pub fn version(&self) -> Option<TraceVersion> {
        self.written
    }

    /// How many samples' tracker reports were left out because the trace had started as
    /// version 1.1 or 1.2 (its first sample carried none).
    pub fn reports_left_out(&self) -> u64 {
        self.reports_left_out
    }

    /// Checks and writes one sample, then flushes. Invalid gaze rays (flagged, non-finite,
    /// zero direction) are written as `0` with empty numbers; a non-finite fixation point is
    /// written as absent; an unknown pupil diameter as an empty field; no report as two empty
    /// fields (version 1.3).
    pub fn write(&mut self, sample: &TraceSample) -> Result<(), TraceError> {
        use std::fmt::Write as _;

        let s = check_sample(&self.name, self.line, sample, self.previous)?;
        let b = &mut self.buf;
        b.clear();
        let version = match self.written {
            Some(v) => v,
            None => {
                let v = if s.gaze.report.is_some() && !self.asked.has_reports() {
                    TraceVersion::V1_3
                } else {
                    self.asked
                };
                header(b, v, &mut self.pending_edits);
                v
            }
        };
        let p = s.head.position;
        let q = s.head.orientation;
        // Writing into a String cannot fail.
        let _ = write!(
            b,
            "{},{},{},{},{},{},{},{},{}",
            s.time_ns, p.x, p.y, p.z, q.x, q.y, q.z, q.w, s.gaze.sample_time_ns
        );
        write_ray(b, Some(s.gaze.left));
        write_ray(b, Some(s.gaze.right));
        write_ray(b, s.gaze.combined);
        match s.gaze.fixation {
            Some(f) => {
                let _ = write!(b, ",{},{},{}", f.x, f.y, f.z);
            }
            None => b.push_str(",,,"),
        }
        for pupil in s.gaze.pupil_diameter_m {
            match pupil {
                Some(d) => {
                    let _ = write!(b, ",{d}");
                }
                None => b.push(','),
            }
        }
        if version.has_reports() {
            write_report(b, s.gaze.report);
        }
        b.push('\n');
        self.flush_buf("writing sample")?;
        self.written = Some(version);
        if s.gaze.report.is_some() && !version.has_reports() {
            if self.reports_left_out == 0 {
                tracing::warn!(
                    "{}: samples carry the tracker's report from line {} on, but the trace \
                     started as {} (its first sample had none): the reports are left out",
                    self.name,
                    self.line,
                    version.version_line()
                );
            }
            self.reports_left_out += 1;
        }
        self.previous = Some(Preceding::after(self.previous, &s));
        self.line += 1;
        Ok(())
    }

    /// Checks and writes one scene edit (a version-1.2 or 1.3 trace only), then flushes; before
    /// the first sample it waits for it (see [`TraceWriter`]). Its time must not be before the
    /// sample or edit written before it.
    pub fn write_edit(&mut self, edit: &EditRecord) -> Result<(), TraceError> {
        if !self.asked.has_edits() {
            return Err(TraceError::EditsNotInVersion {
                file: self.name.clone(),
                version: self.asked.version_line(),
            });
        }
        let e = check_edit(
            &self.name,
            self.line,
            edit,
            self.previous.map(|p| p.time_ns()),
            self.previous_edit_ns,
        )?;
        self.write_between(e.time_ns, format_edit(&e), "writing edit")
    }

    /// Checks and writes one session event (a version-1.4 trace only), then flushes; before
    /// the first sample it waits for it, as an edit does. Its time must not be before the
    /// sample, edit or event written before it.
    pub fn write_event(&mut self, event: &EventRecord) -> Result<(), TraceError> {
        if !self.asked.has_events() {
            return Err(TraceError::EventsNotInVersion {
                file: self.name.clone(),
                version: self.asked.version_line(),
            });
        }
        let e = check_event(&self.name, self.line, event, self.latest_line_ns())?;
        self.write_between(e.time_ns, format_event(&e), "writing event")
    }

    /// Checks and writes one views line (a version-1.5 trace only), then flushes; before the
    /// first sample it waits for it, as an event does. Its time must not be before the
    /// sample, edit, event or views line written before it.
    pub fn write_views(&mut self, views: &ViewsRecord) -> Result<(), TraceError> {
        if !self.asked.has_views() {
            return Err(TraceError::ViewsNotInVersion {
                file: self.name.clone(),
                version: self.asked.version_line(),
            });
        }
        let v = check_views(&self.name, self.line, views, self.latest_line_ns())?;
        self.write_between(v.time_ns, format_views(&v), "writing views")
    }

    /// Time of the newest line written (sample, edit, event or views).
    fn latest_line_ns(&self) -> Option<i64> {
        self.previous
            .map(|p| p.time_ns())
            .into_iter()
            .chain(self.previous_edit_ns)
            .max()
    }

    /// Writes a checked line that stands between the samples (an edit, event or views line at
    /// `time_ns`) and flushes; before the first sample it waits for the header lines.
    fn write_between(&mut self, time_ns: i64, line: String, what: &str) -> Result<(), TraceError> {
        if self.written.is_some() {
            self.buf = line;
            self.flush_buf(what)?;
        } else {
            self.pending_edits.push_str(&line);
        }
        self.previous_edit_ns = Some(time_ns);
        self.line += 1;
        Ok(())
    }

    /// Writes the header lines if no sample did (with the version asked for), flushes and
    /// returns the underlying writer; for a file from [`TraceWriter::create`], first moves it
    /// to its final name.
    pub fn finish(mut self) -> Result<W, TraceError> {
        if self.written.is_none() {
            self.buf.clear();
            header(&mut self.buf, self.asked, &mut self.pending_edits);
            self.flush_buf("writing header")?;
            self.written = Some(self.asked);
        }
        let result = self
            .writer
            .flush()
            .and_then(|()| (self.complete)(&mut self.writer));
        result.map_err(|source| TraceError::Io {
            file: self.name.clone(),
            context: "finishing trace".to_owned(),
            source,
        })?;
        Ok(self.writer)
    }

    /// Writes `self.buf` and flushes, so a crash loses at most the line being written.
    fn flush_buf(&mut self, what: &str) -> Result<(), TraceError> {
        let result = self
            .writer
            .write_all(self.buf.as_bytes())
            .and_then(|()| self.writer.flush());
        result.map_err(|source| TraceError::Io {
            file: self.name.clone(),
            context: format!("{what} (line {})", self.line),
            source,
        })
    }
}

/// Appends the version and column header lines of `version`, then the edit lines that waited
/// for them (taken out of `pending_edits`).
fn header(b: &mut String, version: TraceVersion, pending_edits: &mut String) {
    b.push_str(version.version_line());
    b.push('\n');
    b.push_str(&version.columns().join(","));
    b.push('\n');
    b.push_str(pending_edits);
    pending_edits.clear();
}

/// Appends one ray group (with its leading comma); `None` writes all-empty fields.
fn write_ray(b: &mut String, ray: Option<GazeRay>) {
    use std::fmt::Write as _;
    match ray {
        None => b.push_str(",,,,,,,"),
        Some(r) if !r.valid => b.push_str(",0,,,,,,"),
        Some(r) => {
            let (o, d) = (r.origin, r.direction);
            let _ = write!(b, ",1,{},{},{},{},{},{}", o.x, o.y, o.z, d.x, d.y, d.z);
        }
    }
}

#[cfg(test)]
mod tests;
