//! `vitreous trace ...`: importing recordings into the trace format and synthesising traces
//! for a scene.

use std::io::Cursor;
use std::path::Path;

use anyhow::{Context, Result, bail};
use vitreous_xr::synth::{SynthParams, synthesize_with_truth};
use vitreous_xr::trace::{TraceSample, TraceWriter};

use crate::output::write_atomic;
use crate::scene::{REFRACTED_TARGET, SURFACE_TARGET, load_scene};

pub use crate::scene::synth_params_for;

/// Writes `samples` as a trace file at `out` (atomically).
pub fn write_trace_file(samples: &[TraceSample], out: &Path) -> Result<()> {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).context("starting the trace")?;
    for sample in samples {
        writer.write(sample).context("encoding a trace sample")?;
    }
    let bytes = writer.finish().context("finishing the trace")?.into_inner();
    write_atomic(out, &bytes)
}

/// `vitreous trace import --from sranipal FILE -o OUT`.
pub fn import(from: &str, file: &Path, out: &Path) -> Result<String> {
    match from {
        "sranipal" => {}
        other => bail!("unknown recording format '{other}'; supported: sranipal"),
    }
    let (samples, report) = vitreous_xr::sranipal::import_sranipal_with_report(file)
        .context("importing the recording")?;
    if samples.is_empty() {
        bail!(
            "{} holds no usable samples (rows read: {}); nothing written",
            file.display(),
            report.rows
        );
    }
    write_trace_file(&samples, out)?;
    Ok(format!(
        "{report}\nwrote {} ({} samples)",
        out.display(),
        samples.len()
    ))
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
    let params = SynthParams {
        duration_s: options.duration_s,
        rate_hz: options.rate_hz,
        switch_period_s: options.switch_period_s,
        seed: options.seed,
        ..synth_params_for(&scene)
    };
    let trace = synthesize_with_truth(&params).context("synthesising the trace")?;
    write_trace_file(&trace.samples, out)?;
    Ok(format!(
        "wrote {} ({} samples, {:.1} s at {} Hz; gaze alternates every {} s between the surface \
         point {:.3?} and the refracted point {:.3?}; {} blinks)",
        out.display(),
        trace.samples.len(),
        params.duration_s,
        params.rate_hz,
        params.switch_period_s,
        params.targets[SURFACE_TARGET].point_m.to_array(),
        params.targets[REFRACTED_TARGET].point_m.to_array(),
        trace.blinks.len()
    ))
}
