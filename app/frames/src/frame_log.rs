//! `frames.csv`: the defocus decision of every frame, written by `vitreous replay` and
//! `vitreous run` alike so that a session and a replay of its recording can be compared line
//! by line; and the gaze-image switches and pupil statistics their summaries report.
//!
//! Columns: `frame,time_ns,gaze_time_ns,condition,gaze_image,k_surface_px,k_refracted_px,
//! pupil_m`; see docs/cli.md. Lines are buffered and the file is written under a temporary
//! name in the output folder, renamed to `frames.csv` only by [`FrameLog::finish`]: a run that
//! fails leaves no `frames.csv`, never a half-written one under the final name.

use std::fmt::Write as _;
use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;
use tempfile::NamedTempFile;
use vitreous_trace::FrameInput;

use crate::look::DefocusFrame;
use vitreous_gaze::separability::SeparabilitySummary;
use vitreous_gaze::{GazeImage, PupilSource, Separability};

/// File name of the per-frame log in an output folder.
pub const FRAME_LOG_NAME: &str = "frames.csv";

/// The header line of `frames.csv`.
pub const FRAME_LOG_HEADER: &str =
    "frame,time_ns,gaze_time_ns,condition,gaze_image,k_surface_px,k_refracted_px,pupil_m";

/// The pupil statistics of a summary: where A_p came from and the values used.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PupilSummary {
    /// `paper` (the fixed diameter) or `measured` (the tracker's, smoothed).
    pub source: String,
    /// Smallest A_p used, millimetres (`null` when no frame had defocus).
    pub min_mm: Option<f64>,
    /// Mean A_p over the frames with defocus, millimetres.
    pub mean_mm: Option<f64>,
    /// Largest A_p used, millimetres.
    pub max_mm: Option<f64>,
    /// Tracker samples with a pupil measurement (0 for `paper`).
    pub measured_samples: u64,
}

/// The per-frame log being written, and the statistics over its frames.
pub struct FrameLog {
    /// The temporary file and its final path, when the log is written to a folder.
    file: Option<(BufWriter<NamedTempFile>, PathBuf)>,
    /// Reused line buffer.
    line: String,
    /// The newest known gaze image (surface or refracted).
    last_image: Option<GazeImage>,
    /// The newest separability of the images.
    separability: Option<Separability>,
    /// Changes between surface and refracted.
    switches: u64,
    /// Smallest, sum and largest A_p of the frames with defocus, metres, and their count.
    pupil: (f64, f64, f64, u64),
}

impl FrameLog {
    /// A log that only keeps statistics (no output folder).
    pub fn in_memory() -> FrameLog {
        FrameLog {
            file: None,
            line: String::new(),
            last_image: None,
            separability: None,
            switches: 0,
            pupil: (f64::INFINITY, 0.0, f64::NEG_INFINITY, 0),
        }
    }

    /// A log that becomes `dir/frames.csv` when finished. An earlier run's `frames.csv` there
    /// is removed first, so the folder never pairs this run's summary with another's log.
    pub fn create(dir: &Path) -> Result<FrameLog> {
        let path = dir.join(FRAME_LOG_NAME);
        match fs::remove_file(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                return Err(e).with_context(|| format!("removing an earlier {}", path.display()));
            }
        }
        let temp = tempfile::Builder::new()
            .prefix(".vitreous-")
            .suffix(".partial")
            .tempfile_in(dir)
            .with_context(|| format!("creating {}", path.display()))?;
        let mut writer = BufWriter::new(temp);
        writeln!(writer, "{FRAME_LOG_HEADER}")
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(FrameLog {
            file: Some((writer, path)),
            ..FrameLog::in_memory()
        })
    }

    /// Logs one frame: its input, the effect condition shown and the defocus decision
    /// (`None` for a condition without defocus, logged as `unknown` with empty numbers).
    pub fn record(
        &mut self,
        input: &FrameInput,
        condition: &str,
        defocus: Option<&DefocusFrame>,
    ) -> Result<()> {
        let image = defocus.map_or(GazeImage::Unknown, |d| d.image);
        if image != GazeImage::Unknown {
            if self.last_image.is_some_and(|last| last != image) {
                self.switches += 1;
            }
            self.last_image = Some(image);
        }
        if let Some(s) = defocus.and_then(|d| d.separability) {
            self.separability = Some(s);
        }
        if let Some(d) = defocus {
            let p = f64::from(d.pupil_m);
            let (min, sum, max, n) = &mut self.pupil;
            *min = min.min(p);
            *sum += p;
            *max = max.max(p);
            *n += 1;
        }
        let Some((writer, path)) = &mut self.file else {
            return Ok(());
        };
        let l = &mut self.line;
        l.clear();
        let _ = write!(l, "{},{},", input.index, input.time_ns);
        if let Some(g) = &input.gaze {
            let _ = write!(l, "{}", g.sample_time_ns);
        }
        // Effect names are comma-separated elsewhere; here they are joined by `+`.
        let _ = write!(l, ",{},{image},", condition.replace(',', "+"));
        if let Some(k) = defocus.and_then(|d| d.defocus) {
            let _ = write!(l, "{},{}", k.surface_k_g_px, k.refracted_k_g_px);
        } else {
            l.push(',');
        }
        l.push(',');
        if let Some(d) = defocus {
            let _ = write!(l, "{}", d.pupil_m);
        }
        l.push('\n');
        writer
            .write_all(l.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    }

    /// Changes of the gaze-image decision between surface and refracted (frames whose image
    /// is unknown are skipped: a blink that ends on the same image is no change).
    pub fn gaze_image_switches(&self) -> u64 {
        self.switches
    }

    /// How far apart the images were in the tracker's vergence noise at the end (the noise
    /// estimated over the whole session); `None` without defocus or a sample with a depth.
    pub fn separability_summary(&self) -> Option<SeparabilitySummary> {
        self.separability.map(|s| s.summary())
    }

    /// The pupil statistics, given where A_p came from and how many tracker samples had a
    /// measurement (see [`LookPlanner::pupil_source`](crate::look::LookPlanner::pupil_source));
    /// `None` without defocus.
    pub fn pupil_summary(&self, source: Option<(PupilSource, u64)>) -> Option<PupilSummary> {
        let (source, measured_samples) = source?;
        let (min, sum, max, n) = self.pupil;
        let mm = |m: f64| (n > 0).then_some(m * 1000.0);
        Some(PupilSummary {
            source: source.to_string(),
            min_mm: mm(min),
            mean_mm: mm(sum / n.max(1) as f64),
            max_mm: mm(max),
            measured_samples,
        })
    }

    /// Flushes the log and moves it to `frames.csv`; nothing to do without a folder.
    pub fn finish(&mut self) -> Result<()> {
        let Some((writer, path)) = self.file.take() else {
            return Ok(());
        };
        let temp = writer
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("writing {}", path.display()))?;
        temp.as_file()
            .sync_data()
            .with_context(|| format!("writing {}", path.display()))?;
        use std::os::unix::fs::PermissionsExt;
        // Like a plain create: 0666 less the umask, not tempfile's private 0600.
        let _ = temp
            .as_file()
            .set_permissions(fs::Permissions::from_mode(0o644));
        temp.persist(&path)
            .map_err(|e| e.error)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_gaze::ImageDistances;
    use vitreous_render::Defocus;

    fn decision(image: GazeImage, pupil_m: f32) -> DefocusFrame {
        DefocusFrame {
            image,
            distances: ImageDistances {
                surface_m: 0.125,
                refracted_m: 0.4,
            },
            defocus: (image != GazeImage::Unknown).then_some(Defocus {
                surface_k_g_px: 0.0,
                refracted_k_g_px: 12.5,
            }),
            pupil_m,
            pupil_measured: false,
            separability: None,
        }
    }

    #[test]
    fn log_appears_only_when_finished_and_counts_switches_and_pupils() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(dir.path().join(FRAME_LOG_NAME), "an earlier run's log").unwrap();
        let mut log = FrameLog::create(dir.path()).unwrap();
        assert!(!dir.path().join(FRAME_LOG_NAME).exists());
        let mut input = crate::test_frame::test_frame();
        let images = [
            GazeImage::Unknown,
            GazeImage::Surface,
            GazeImage::Unknown,
            GazeImage::Surface,
            GazeImage::Refracted,
            GazeImage::Surface,
        ];
        for (i, image) in images.into_iter().enumerate() {
            input.index = i as u64;
            let d = decision(image, (4 + i) as f32 / 1000.0);
            log.record(&input, "disparity,defocus", Some(&d)).unwrap();
        }
        log.record(&input, "none", None).unwrap();
        assert_eq!(log.gaze_image_switches(), 2);
        let p = log.pupil_summary(Some((PupilSource::Measured, 5))).unwrap();
        assert_eq!(p.source, "measured");
        assert!((p.min_mm.unwrap() - 4.0).abs() < 1e-4 && (p.max_mm.unwrap() - 9.0).abs() < 1e-4);
        assert!((p.mean_mm.unwrap() - 6.5).abs() < 1e-4);
        assert!(log.pupil_summary(None).is_none());
        log.finish().unwrap();
        let text = fs::read_to_string(dir.path().join(FRAME_LOG_NAME)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], FRAME_LOG_HEADER);
        assert_eq!(lines.len(), 8);
        assert_eq!(lines[1], "0,5,,disparity+defocus,unknown,,,0.004");
        assert_eq!(lines[2], "1,5,,disparity+defocus,surface,0,12.5,0.005");
        assert_eq!(lines[7], "5,5,,none,unknown,,,");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn an_abandoned_log_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let mut log = FrameLog::create(dir.path()).unwrap();
        log.record(&crate::test_frame::test_frame(), "none", None)
            .unwrap();
        drop(log);
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
