//! `vitreous soak SCENE...`: the soak of `vitreous-frames` ([`vitreous_frames::soak`]) over
//! each scene, its passes and summaries printed, its reports written.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use vitreous_frames::soak::{SoakOptions, soak};

/// Soaks each of `scenes` in turn with `options` (its scene replaced), each on its own device:
/// prints every pass on stderr and each scene's summary line on stdout, writes the reports to
/// `json` (the report of one scene, an array of them for several) and fails naming every scene
/// that failed. Ctrl-C ends the scene being soaked and skips the rest.
pub fn soak_scenes(scenes: &[PathBuf], options: &SoakOptions, json: Option<&Path>) -> Result<()> {
    let mut reports = Vec::new();
    for scene in scenes {
        let options = SoakOptions {
            scene: scene.clone(),
            ..options.clone()
        };
        let report = soak(&options, |p| eprintln!("soak: {p}"))
            .with_context(|| format!("soaking {}", scene.display()))?;
        println!("{}", report.summary_line());
        reports.push(report);
        if vitreous_frames::interrupt::requested() {
            break;
        }
    }
    if let Some(path) = json {
        let bytes = match reports.as_slice() {
            [one] => serde_json::to_vec_pretty(one)?,
            all => serde_json::to_vec_pretty(all)?,
        };
        vitreous_frames::output::write_atomic(path, &bytes)?;
    }
    let failed: Vec<String> = reports
        .iter()
        .filter_map(|r| r.verdict().err().map(|e| e.to_string()))
        .collect();
    match failed.as_slice() {
        [] => Ok(()),
        [one] => bail!("{one}"),
        all => bail!(
            "{} of {} scenes failed:\n{}",
            all.len(),
            reports.len(),
            all.join("\n")
        ),
    }
}
