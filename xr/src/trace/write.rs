//! Writing a trace: the header lines, then one checked sample per line, flushed each time.

use std::io::{self, Write};
use std::path::Path;

use super::edit::{EditRecord, check_edit, format_edit};
use super::validate::{Preceding, check_sample};
use super::{AtomicFile, COLUMNS_V1_1, TraceError, TraceSample, TraceVersion};
use crate::frame::GazeRay;

/// Writes [`TraceSample`]s as a version-1.1 trace (version 1 and the pupil diameters), or as
/// version 1.2 with scene edits among them ([`TraceWriter::create_with_edits`]).
///
/// Every sample is checked like the reader checks it (finite head pose, unit quaternion,
/// increasing times, gaze time not after the pose time) and flushed once written.
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
    /// The version written (1.1, or 1.2 when edits may come).
    version: TraceVersion,
    /// Reused line buffer.
    buf: String,
    /// What [`TraceWriter::finish`] does after flushing: nothing, or commit a file.
    complete: fn(&mut W) -> io::Result<()>,
}

impl TraceWriter<AtomicFile> {
    /// Starts a trace file and writes its header lines. The trace is written to a temporary
    /// file in the same folder (flushed after every sample) and appears under `path`,
    /// replacing any earlier file, only when [`TraceWriter::finish`] succeeds; see
    /// [`AtomicFile`].
    pub fn create(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        TraceWriter::create_version(path.as_ref(), TraceVersion::V1_1)
    }

    /// [`TraceWriter::create`] for a version-1.2 trace, which may hold scene edits
    /// ([`TraceWriter::write_edit`]).
    pub fn create_with_edits(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        TraceWriter::create_version(path.as_ref(), TraceVersion::V1_2)
    }

    /// [`TraceWriter::create`] of a version-1.1 or 1.2 trace.
    fn create_version(path: &Path, version: TraceVersion) -> Result<Self, TraceError> {
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
    /// Writes a trace into any writer (named `<output>` in error messages) and writes its
    /// header lines.
    pub fn new(writer: W) -> Result<Self, TraceError> {
        TraceWriter::with_name(writer, "<output>")
    }

    /// Like [`TraceWriter::new`], with the name to use in error messages.
    pub fn with_name(writer: W, name: impl Into<String>) -> Result<Self, TraceError> {
        TraceWriter::with_version(writer, name, TraceVersion::V1_1)
    }

    /// Like [`TraceWriter::with_name`], writing `version` (1.1 or 1.2; 1 is written as 1.1).
    pub fn with_version(
        writer: W,
        name: impl Into<String>,
        version: TraceVersion,
    ) -> Result<Self, TraceError> {
        let version = match version {
            TraceVersion::V1 => TraceVersion::V1_1,
            v => v,
        };
        let mut this = TraceWriter {
            writer,
            name: name.into(),
            line: 3,
            previous: None,
            previous_edit_ns: None,
            version,
            buf: String::new(),
            complete: |_| Ok(()),
        };
        this.buf = format!("{}\n{}\n", version.version_line(), COLUMNS_V1_1.join(","));
        this.flush_buf("writing header")?;
        Ok(this)
    }

    /// Checks and writes one sample, then flushes. Invalid gaze rays (flagged, non-finite,
    /// zero direction) are written as `0` with empty numbers; a non-finite fixation point is
    /// written as absent; an unknown pupil diameter as an empty field.
    pub fn write(&mut self, sample: &TraceSample) -> Result<(), TraceError> {
        use std::fmt::Write as _;

        let s = check_sample(&self.name, self.line, sample, self.previous)?;
        let p = s.head.position;
        let q = s.head.orientation;
        let b = &mut self.buf;
        b.clear();
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
        b.push('\n');
        self.flush_buf("writing sample")?;
        self.previous = Some(Preceding::after(self.previous, &s));
        self.line += 1;
        Ok(())
    }

    /// Checks and writes one scene edit (a version-1.2 trace only), then flushes. Its time
    /// must not be before the sample or edit written before it.
    pub fn write_edit(&mut self, edit: &EditRecord) -> Result<(), TraceError> {
        if !self.version.has_edits() {
            return Err(TraceError::EditsNotInVersion {
                file: self.name.clone(),
                version: self.version.version_line(),
            });
        }
        let e = check_edit(
            &self.name,
            self.line,
            edit,
            self.previous.map(|p| p.time_ns()),
            self.previous_edit_ns,
        )?;
        self.buf = format_edit(&e);
        self.flush_buf("writing edit")?;
        self.previous_edit_ns = Some(e.time_ns);
        self.line += 1;
        Ok(())
    }

    /// Flushes and returns the underlying writer; for a file from [`TraceWriter::create`],
    /// first moves it to its final name.
    pub fn finish(mut self) -> Result<W, TraceError> {
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
    use crate::frame::{GazeRay, GazeSample, Pose};

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
            ),
        )
            .prop_map(
                |(dt, lag, position, axis, angle, (left, right, combined), (fixation, lp, rp))| {
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
                            report: None,
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
