//! `vitreous trace ...`: importing recordings into the trace format and synthesising traces
//! for a scene.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use vitreous_trace::format::{TraceSample, TraceWriter};
use vitreous_trace::synth::{SynthError, SynthParams, synthesize_with_truth};

use vitreous_frames::input_files::InputFiles;
use vitreous_frames::output::write_atomic;
use vitreous_scene::{REFRACTED_TARGET, SURFACE_TARGET, load_scene, synth_params_for};

/// Writes `samples` as a trace file at `out` (atomically).
pub fn write_trace_file(samples: &[TraceSample], out: &Path) -> Result<()> {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).context("starting the trace")?;
    for sample in samples {
        writer.write(sample).context("encoding a trace sample")?;
    }
    let bytes = writer.finish().context("finishing the trace")?.into_inner();
    write_atomic(out, &bytes)
}

/// The recording formats `vitreous trace import --from` takes.
pub const IMPORT_FORMATS: &str = "sranipal, tobii-g3, neon";

/// Options of `vitreous trace import` that only some formats take.
#[derive(Clone, Copy, Debug, Default)]
pub struct ImportOptions {
    /// Neon: angle kappa, degrees, for gaze from the eye states (`None`: the default, 5).
    pub kappa_deg: Option<f64>,
    /// Neon: gaze from the eye states even when the recording has a gaze stream.
    pub eye_state_gaze: bool,
}

/// `vitreous trace import --from FORMAT FILE -o OUT`: `sranipal` (a CSV), `tobii-g3` (a
/// recording folder or its gazedata.gz) or `neon` (a native recording folder).
pub fn import(from: &str, file: &Path, out: &Path, options: &ImportOptions) -> Result<String> {
    if from != "neon" {
        for (given, option) in [
            (options.kappa_deg.is_some(), "--kappa-deg"),
            (options.eye_state_gaze, "--eye-state-gaze"),
        ] {
            if given {
                bail!("{option} applies to --from neon only, not to --from {from}");
            }
        }
    }
    let mut inputs = InputFiles::new();
    for path in recording_files(from, file) {
        inputs.add(&path, "RECORDING");
    }
    inputs.check_file("-o", out)?;
    let (samples, report, rows) = match from {
        "sranipal" => {
            let (samples, report) = vitreous_trace::sranipal::import_sranipal_with_report(file)
                .context("importing the recording")?;
            let rows = report.rows;
            (samples, report.to_string(), rows)
        }
        "tobii-g3" => {
            let (samples, report) = vitreous_trace::import::tobii_g3::import_tobii_g3(file)
                .context("importing the Tobii Pro Glasses 3 recording")?;
            let rows = report.records;
            (samples, report.to_string(), rows)
        }
        "neon" => {
            use vitreous_trace::import::neon::{GazeSource, NeonOptions, import_neon_with};
            let neon = NeonOptions {
                gaze: if options.eye_state_gaze {
                    GazeSource::EyeState
                } else {
                    GazeSource::Auto
                },
                kappa_deg: options
                    .kappa_deg
                    .unwrap_or(NeonOptions::default().kappa_deg),
            };
            let (samples, report) =
                import_neon_with(file, &neon).context("importing the Neon recording")?;
            let rows = report.records;
            (samples, report.to_string(), rows)
        }
        other => bail!("unknown recording format '{other}'; supported: {IMPORT_FORMATS}"),
    };
    if samples.is_empty() {
        bail!(
            "{} holds no usable samples (rows read: {rows}); nothing written",
            file.display()
        );
    }
    write_trace_file(&samples, out)?;
    Ok(format!(
        "{report}\nwrote {} ({} samples)",
        out.display(),
        samples.len()
    ))
}

/// The files an import may read: every file of a recording folder, or the named file and, for
/// Tobii, the IMU file beside it. The output must not replace any of them.
fn recording_files(from: &str, file: &Path) -> Vec<PathBuf> {
    if file.is_dir() {
        return std::fs::read_dir(file)
            .map(|entries| entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
    }
    let mut files = vec![file.to_path_buf()];
    if from == "tobii-g3" {
        let folder = file.parent().unwrap_or(Path::new(""));
        files.extend(["imudata.gz", "imudata"].map(|n| folder.join(n)));
    }
    files
}

/// The option of `vitreous trace synth` that sets a field of [`SynthParams`], if one does.
fn synth_option(field: &str) -> Option<&'static str> {
    match field {
        "duration_s" => Some("--duration"),
        "rate_hz" => Some("--rate"),
        "switch_period_s" => Some("--switch-period"),
        _ => None,
    }
}

/// Options of `vitreous trace synth`.
#[derive(Clone, Debug)]
pub struct SynthOptions {
    /// Length, seconds.
    pub duration_s: f32,
    /// Tracker rate, hertz.
    pub rate_hz: f32,
    /// Seconds between gaze switches.
    pub switch_period_s: f32,
    /// Seed.
    pub seed: u64,
}

/// `vitreous trace synth --scene SCENE -o OUT`.
pub fn synth(scene_path: &Path, options: &SynthOptions, out: &Path) -> Result<String> {
    let scene = load_scene(scene_path)?;
    InputFiles::new()
        .add_scene(&scene, "--scene")
        .check_file("-o", out)?;
    let params = SynthParams {
        duration_s: options.duration_s,
        rate_hz: options.rate_hz,
        switch_period_s: options.switch_period_s,
        seed: options.seed,
        ..synth_params_for(&scene)
    };
    let trace = synthesize_with_truth(&params).map_err(|e| {
        if let SynthError::BadParam {
            field,
            value,
            expected,
        } = &e
            && let Some(option) = synth_option(field)
        {
            return anyhow::anyhow!("{option} {value}: expected {expected}");
        }
        anyhow::Error::new(e).context("synthesising the trace")
    })?;
    write_trace_file(&trace.samples, out)?;
    let surface = params.targets[SURFACE_TARGET].point_m.to_array();
    let refracted = params.targets[REFRACTED_TARGET].point_m.to_array();
    let gaze = if params.switch_period_s > 0.0 {
        format!(
            "gaze alternates every {} s between the surface point {surface:.3?} and the \
             refracted point {refracted:.3?}",
            params.switch_period_s
        )
    } else {
        format!("gaze stays on the surface point {surface:.3?}")
    };
    Ok(format!(
        "wrote {} ({} samples, {:.1} s at {} Hz; {gaze}; {} blinks)",
        out.display(),
        trace.samples.len(),
        params.duration_s,
        params.rate_hz,
        trace.blinks.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn neon_data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../trace/tests/data")
            .join(name)
    }

    /// A Neon recording without a gaze stream imports from its eye states, with the kappa
    /// asked for named in the report; the Neon options are refused for other formats.
    #[test]
    fn neon_without_gaze_imports_from_the_eye_states_with_the_kappa_given() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("n.trace");
        let report = import(
            "neon",
            &neon_data("neon-eye-state"),
            &out,
            &ImportOptions::default(),
        )
        .unwrap();
        assert!(
            report.contains("turned 5.0 degrees toward the nose") && report.contains("unreliable"),
            "{report}"
        );
        assert_eq!(vitreous_trace::read_trace(&out).unwrap().len(), 200);
        let options = ImportOptions {
            kappa_deg: Some(3.5),
            eye_state_gaze: true,
        };
        let report = import("neon", &neon_data("neon"), &out, &options).unwrap();
        assert!(
            report.contains("turned 3.5 degrees toward the nose"),
            "{report}"
        );
        let e = import("tobii-g3", &neon_data("tobii_g3"), &out, &options)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--kappa-deg applies to --from neon only"), "{e}");
    }

    /// The report says what the trace holds: alternating gaze, or, with no switch period,
    /// the gaze staying on the surface point.
    #[test]
    fn synth_reports_whether_the_gaze_switches() {
        let scene =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/visual-effects.toml");
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("s.trace");
        let options = |switch_period_s| SynthOptions {
            duration_s: 2.0,
            rate_hz: 30.0,
            switch_period_s,
            seed: 1,
        };
        let report = synth(&scene, &options(0.5), &out).unwrap();
        assert!(report.contains("gaze alternates every 0.5 s"), "{report}");
        for still in [0.0, -1.0] {
            let report = synth(&scene, &options(still), &out).unwrap();
            assert!(
                report.contains("gaze stays on the surface point"),
                "{report}"
            );
            assert!(!report.contains("alternates"), "{report}");
        }
    }
}
