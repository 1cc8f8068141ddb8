//! `vitreous trace ...`: importing recordings into the trace format and synthesising traces
//! for a scene.

use std::io::Cursor;
use std::path::Path;

use anyhow::{Context, Result, bail};
use vitreous_xr::synth::{SynthParams, synthesize_with_truth};
use vitreous_xr::trace::{TraceSample, TraceWriter};

use crate::output::write_atomic;
use crate::scene::{Scene, load_scene};

/// Distance behind the object's centre where the refracted image is assumed to lie when the
/// scene's background plane is not in line with the object, metres.
const FALLBACK_REFRACTED_DEPTH_M: f32 = 0.2;

/// Synthetic-trace parameters for a scene: the head at the viewer's position looking at the
/// object; the gaze alternates between the front of the object's surface and the point of the
/// background plane seen through the object's centre (where the refracted image lies).
pub fn synth_params_for(scene: &Scene) -> SynthParams {
    let head = scene.viewer.head_position_m;
    let center = scene.object.center_m;
    let to_object = (center - head).normalize_or(glam::Vec3::NEG_Z);
    let surface_point = center - to_object * scene.object.radius_m;
    let plane_point = scene.background.pose.position;
    let normal = scene.background.normal();
    let denom = to_object.dot(normal);
    let behind = center + to_object * FALLBACK_REFRACTED_DEPTH_M;
    let refracted_point = if denom.abs() > 1e-3 {
        let t = (plane_point - head).dot(normal) / denom;
        if t > (center - head).length() {
            head + to_object * t
        } else {
            behind
        }
    } else {
        behind
    };
    SynthParams {
        head_position: head,
        surface_point,
        refracted_point,
        ipd_m: scene.viewer.ipd_m,
        ..SynthParams::default()
    }
}

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
        .with_context(|| format!("importing {}", file.display()))?;
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
        params.surface_point.to_array(),
        params.refracted_point.to_array(),
        trace.blinks.len()
    ))
}
