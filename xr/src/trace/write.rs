//! Writing a trace: the header lines, then one checked sample per line, flushed each time.

use std::io::{self, Write};
use std::path::Path;

use super::edit::{EditRecord, check_edit, format_edit};
use super::report::write_report;
use super::validate::{Preceding, check_sample};
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
    /// Time of the last edit written.
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
                let v = if s.gaze.report.is_some() {
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
        if self.written.is_some() {
            self.buf = format_edit(&e);
            self.flush_buf("writing edit")?;
        } else {
            self.pending_edits.push_str(&format_edit(&e));
        }
        self.previous_edit_ns = Some(e.time_ns);
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
mod tests {
    use glam::{Quat, Vec3};
    use proptest::prelude::*;

    use super::super::test_traces::*;
    use super::super::validate::unit_quat;
    use super::super::*;
    use crate::frame::{
        GazeBehaviour, GazeRay, GazeSample, Pose, TrackerConfidence, TrackerReport,
    };

    fn report(confidence: TrackerConfidence, behaviour: GazeBehaviour) -> Option<TrackerReport> {
        Some(TrackerReport {
            confidence,
            behaviour,
        })
    }

    fn edit(time_ns: i64) -> EditRecord {
        EditRecord {
            time_ns,
            action: "object+1mmx".to_owned(),
            object_offset_m: Vec3::new(0.001, 0.0, 0.0),
            object_turn: Quat::IDENTITY,
            light_offset_m: Vec3::ZERO,
            world_offset_m: Vec3::ZERO,
        }
    }

    fn text_of(w: TraceWriter<Vec<u8>>) -> String {
        String::from_utf8(w.finish().unwrap()).unwrap()
    }

    #[test]
    fn round_trip_keeps_samples_exactly() {
        let mut samples: Vec<_> = (1..=5).map(|i| sample(i * 1_000_000)).collect();
        samples[1].gaze.left = GazeRay::INVALID;
        samples[2].gaze.combined = Some(ray(Vec3::ZERO, Vec3::new(0.0, 0.1, -1.0)));
        samples[3].gaze.combined = Some(GazeRay::INVALID);
        samples[4].gaze.fixation = Some(Vec3::new(0.01, -0.02, -0.75));
        samples[0].gaze.pupil_diameter_m = [Some(0.0041), Some(0.003_95)];
        samples[2].gaze.pupil_diameter_m = [None, Some(0.0062)];
        let text = to_text(&samples);
        assert!(text.starts_with("# vitreous-trace v1.1\n"), "{text}");
        assert_eq!(read_str(&text).unwrap(), samples);
    }

    #[test]
    fn reports_round_trip_in_version_1_3() {
        use GazeBehaviour::*;
        use TrackerConfidence::*;
        let mut samples: Vec<_> = (1..=8).map(|i| sample(i * 1_000_000)).collect();
        let reports = [
            report(High, Fixation),
            report(Medium, Pursuit),
            report(Low, Saccade),
            None,
            report(Low, Blink),
            report(Low, EyesClosed),
            report(High, Unknown),
            report(Medium, Fixation),
        ];
        for (s, r) in samples.iter_mut().zip(reports) {
            s.gaze.report = r;
        }
        samples[4].gaze.left = GazeRay::INVALID;
        samples[4].gaze.right = GazeRay::INVALID;
        samples[1].gaze.pupil_diameter_m = [Some(0.004), None];
        // Asked for nothing in particular: the first sample's report makes it version 1.3.
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        assert_eq!(w.version(), Some(TraceVersion::V1_3));
        let text = text_of(w);
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some(VERSION_LINE_V1_3));
        assert_eq!(lines.next(), Some(COLUMNS_V1_3.join(",").as_str()));
        assert!(
            lines.next().unwrap().ends_with(",,,high,fixation"),
            "{text}"
        );
        assert!(text.lines().nth(5).unwrap().ends_with(",,"), "{text}");
        let mut r = TraceReader::new(text.as_bytes(), "r.trace").unwrap();
        assert_eq!(r.version(), TraceVersion::V1_3);
        let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(read, samples);
    }

    #[test]
    fn traces_without_reports_are_written_as_before() {
        let samples: Vec<_> = (1..=2).map(|i| sample(i * 1000)).collect();
        // Byte for byte the text of the 1.1 and 1.2 writers before version 1.3 existed.
        let line = |t: i64| {
            format!(
                "{t},0.1,1.6,-0.2,0,0.14943814,0,0.9887711,{},1,-0.032,0,0.01,0.09950372,0,-0.99503714,1,0.032,0,0.01,-0.09950372,0,-0.99503714,,,,,,,,,,,,",
                t - 5
            )
        };
        let expected = |version: &str| {
            format!(
                "{version}\n{}\n{}\n{}\n",
                COLUMNS_V1_1.join(","),
                line(1000),
                line(2000)
            )
        };
        assert_eq!(to_text(&samples), expected(VERSION_LINE_V1_1));
        let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        assert_eq!(w.version(), Some(TraceVersion::V1_2));
        assert_eq!(text_of(w), expected(VERSION_LINE_V1_2));
        // With no samples the header lines come at the end, in the version asked for.
        let w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
        assert_eq!(
            text_of(w),
            format!("{VERSION_LINE_V1_2}\n{}\n", COLUMNS_V1_1.join(","))
        );
    }

    #[test]
    fn version_1_3_when_asked_even_without_reports() {
        let samples: Vec<_> = (1..=2).map(|i| sample(i * 1000)).collect();
        let mut w = TraceWriter::with_version(Vec::new(), "a", TraceVersion::V1_3).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        let text = text_of(w);
        assert!(text.starts_with("# vitreous-trace v1.3\n"), "{text}");
        assert!(text.lines().nth(2).unwrap().ends_with(",,,,"), "{text}");
        assert_eq!(read_str(&text).unwrap(), samples);
    }

    #[test]
    fn edits_before_the_first_sample_wait_for_its_version() {
        let mut first = sample(1000);
        first.gaze.report = report(TrackerConfidence::Medium, GazeBehaviour::Saccade);
        let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
        w.write_edit(&edit(0)).unwrap();
        assert_eq!(w.version(), None);
        w.write(&first).unwrap();
        w.write_edit(&edit(1500)).unwrap();
        w.write(&sample(2000)).unwrap();
        let text = text_of(w);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], VERSION_LINE_V1_3);
        assert!(lines[2].starts_with("edit,0,") && lines[4].starts_with("edit,1500,"));
        let mut r = TraceReader::new(text.as_bytes(), "e").unwrap();
        let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(read, vec![first, sample(2000)]);
        assert_eq!(r.take_edits(), vec![edit(0), edit(1500)]);
        // A trace of edits alone is the version asked for.
        let mut w = TraceWriter::with_version(Vec::new(), "e", TraceVersion::V1_2).unwrap();
        w.write_edit(&edit(0)).unwrap();
        let text = text_of(w);
        assert!(text.starts_with("# vitreous-trace v1.2\n"), "{text}");
        assert!(text.ends_with("\nedit,0,object+1mmx,0.001,0,0,0,0,0,1,0,0,0,0,0,0\n"));
        // A writer asked for version 1.1 takes no edits, reports or not.
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        assert!(matches!(
            w.write_edit(&edit(0)),
            Err(TraceError::EditsNotInVersion { .. })
        ));
    }

    #[test]
    fn reports_after_a_first_sample_without_one_are_left_out_and_counted() {
        let mut samples: Vec<_> = (1..=3).map(|i| sample(i * 1000)).collect();
        samples[1].gaze.report = report(TrackerConfidence::High, GazeBehaviour::Fixation);
        samples[2].gaze.report = report(TrackerConfidence::Low, GazeBehaviour::Blink);
        let mut w = TraceWriter::with_version(Vec::new(), "late", TraceVersion::V1_2).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        assert_eq!(w.reports_left_out(), 2);
        let text = text_of(w);
        assert!(text.starts_with("# vitreous-trace v1.2\n"), "{text}");
        let read = read_str(&text).unwrap();
        assert!(read.iter().all(|s| s.gaze.report.is_none()));
        assert_eq!(read[1].gaze.left, samples[1].gaze.left);
    }

    #[test]
    fn version_1_files_read_as_before_without_pupils() {
        let mut samples: Vec<_> = (1..=3).map(|i| sample(i * 1000)).collect();
        samples[1].gaze.left = GazeRay::INVALID;
        // The same samples as a version-1 file: the pupil columns cut off.
        let v1: Vec<String> = to_text(&samples)
            .lines()
            .enumerate()
            .map(|(i, line)| match i {
                0 => VERSION_LINE.to_owned(),
                _ => line.rsplitn(3, ',').nth(2).unwrap().to_owned(),
            })
            .collect();
        assert_eq!(v1[1], COLUMNS.join(","));
        assert_eq!(v1[2].split(',').count(), COLUMNS.len());
        let v1 = v1.join("\n");
        let mut r = TraceReader::new(v1.as_bytes(), "v1.trace").unwrap();
        assert_eq!(r.version(), TraceVersion::V1);
        let read: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(read, samples);
        // A v1 file with the pupil columns is refused at its header.
        let e = read_str(&to_text(&samples).replacen("v1.1", "v1", 1)).unwrap_err();
        assert!(
            matches!(e, TraceError::BadColumnHeader { column: 34, .. }),
            "{e}"
        );
    }

    #[test]
    fn file_round_trip_and_read_trace() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.trace");
        let samples: Vec<_> = (1..=3).map(|i| sample(i * 10)).collect();
        let mut w = TraceWriter::create(&path).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        // Nothing under the final name before finish().
        assert!(!path.exists());
        w.finish().unwrap();
        assert_eq!(read_trace(&path).unwrap(), samples);
        // Writing it again replaces it only on finish; an abandoned writer leaves it as it was
        // and no temporary file behind.
        let mut w = TraceWriter::create(&path).unwrap();
        w.write(&samples[0]).unwrap();
        drop(w);
        assert_eq!(read_trace(&path).unwrap(), samples);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn writer_refuses_what_reader_would() {
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        w.write(&sample(100)).unwrap();
        let e = w.write(&sample(100)).unwrap_err();
        assert!(
            matches!(e, TraceError::TimeNotIncreasing { line: 4, .. }),
            "{e}"
        );
        let mut bad = sample(200);
        bad.head.position.x = f32::NAN;
        assert!(matches!(w.write(&bad), Err(TraceError::NonFinite { .. })));
        w.write(&sample(200)).unwrap();
    }

    fn arb_vec3(range: f32) -> impl Strategy<Value = Vec3> {
        (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn arb_ray() -> impl Strategy<Value = GazeRay> {
        (any::<bool>(), arb_vec3(0.1), arb_vec3(1.0)).prop_map(|(valid, o, d)| {
            clean_ray(GazeRay {
                origin: o,
                direction: d,
                valid,
            })
        })
    }

    fn arb_report() -> impl Strategy<Value = TrackerReport> {
        use GazeBehaviour::*;
        use TrackerConfidence::*;
        (
            prop::sample::select(vec![Low, Medium, High]),
            prop::sample::select(vec![Unknown, EyesClosed, Blink, Fixation, Pursuit, Saccade]),
        )
            .prop_map(|(confidence, behaviour)| TrackerReport {
                confidence,
                behaviour,
            })
    }

    fn arb_sample() -> impl Strategy<Value = (i64, i64, TraceSample)> {
        (
            1i64..1_000_000_000,
            0i64..1_000_000,
            arb_vec3(100.0),
            arb_vec3(1.0),
            -3.0f32..3.0,
            (arb_ray(), arb_ray(), proptest::option::of(arb_ray())),
            (
                proptest::option::of(arb_vec3(10.0)),
                proptest::option::of(0.001f32..=0.010),
                proptest::option::of(0.001f32..=0.010),
                proptest::option::of(arb_report()),
            ),
        )
            .prop_map(
                |(
                    dt,
                    lag,
                    position,
                    axis,
                    angle,
                    (left, right, combined),
                    (fixation, lp, rp, report),
                )| {
                    let axis = axis.try_normalize().unwrap_or(Vec3::Y);
                    let sample = TraceSample {
                        time_ns: 0,
                        head: Pose {
                            position,
                            orientation: Quat::from_axis_angle(axis, angle),
                        },
                        gaze: GazeSample {
                            sample_time_ns: 0,
                            left,
                            right,
                            combined,
                            fixation,
                            pupil_diameter_m: [lp, rp],
                            report,
                        },
                    };
                    (dt, lag, sample)
                },
            )
    }

    proptest! {
        #[test]
        fn random_traces_round_trip(raw in proptest::collection::vec(arb_sample(), 0..20)) {
            let mut time_ns = -5_000_000_000i64;
            let mut gaze_ns = i64::MIN;
            let mut samples = Vec::new();
            for (dt, lag, mut s) in raw {
                time_ns += dt;
                gaze_ns = gaze_ns.max(time_ns - lag);
                s.time_ns = time_ns;
                s.gaze.sample_time_ns = gaze_ns;
                s.head.orientation = unit_quat(s.head.orientation);
                samples.push(s);
            }
            let text = to_text(&samples);
            prop_assert_eq!(read_str(&text).unwrap(), samples);
        }
    }
}
