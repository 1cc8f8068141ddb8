//! `vitreous bake SCENE` (and `vitreous-caustics bake SCENE`): bakes a scene's caustic gain map
//! to an EXR with a progress bar on a terminal, prints what the light did, and checks the bake
//! against a quarter-budget one (and, when asked, against a reference with more rays).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};

use crate::{BakeOutput, BakeParams, CausticScene, bake, compare, write_bake};

/// Options of `vitreous bake` (docs/cli.md, docs/caustics.md).
#[derive(clap::Args, Debug)]
pub struct BakeArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output EXR [default: config/bakes/<scene name>.exr next to the scene's folder].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Texels per side of the floor map.
    #[arg(long, default_value_t = 1980)]
    pub resolution: u32,
    /// Grid rays to trace from the light.
    #[arg(long, default_value_t = BakeParams::default().budget_rays)]
    pub budget: u64,
    /// Seed (rotates the ray grid); the same seed gives a byte-identical file.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Also bake a reference with this many times the budget and print the RMS
    /// difference against it (16 for the figure; slow).
    #[arg(long)]
    pub reference_factor: Option<u64>,
    /// Most reflections and refractions on one light path.
    #[arg(long, default_value_t = BakeParams::default().max_interactions)]
    pub max_interactions: u32,
    /// Skip the quick self-check (a quarter-budget bake compared with the result).
    #[arg(long)]
    pub no_self_check: bool,
}

/// Runs `vitreous bake`: bakes `args.scene` into `args.output` (or the default beside the
/// scene's folder) and prints the figures.
pub fn bake_command(args: BakeArgs) -> Result<()> {
    let params = BakeParams {
        width_px: args.resolution,
        height_px: args.resolution,
        budget_rays: args.budget,
        seed: args.seed,
        max_interactions: args.max_interactions,
        ..BakeParams::default()
    };
    let output = args.output.unwrap_or_else(|| default_output(&args.scene));
    run_bake(
        &args.scene,
        &output,
        &params,
        args.reference_factor,
        !args.no_self_check,
    )
}

/// `config/scenes/x.toml` -> `config/bakes/x.exr`.
fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_os_string())
        .unwrap_or_else(|| "bake".into());
    let dir = scene
        .parent()
        .and_then(Path::parent)
        .unwrap_or(Path::new("."));
    dir.join("bakes").join(stem).with_extension("exr")
}

fn progress_bar(label: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} rows {elapsed_precise}")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(label.to_owned());
    bar
}

/// Bakes `scene` with a progress bar; an error names the scene file and its `model`.
fn bake_with_bar(
    scene: &CausticScene,
    model: &Path,
    params: &BakeParams,
    label: &str,
) -> Result<BakeOutput> {
    let bar = progress_bar(label);
    let out = bake(scene, params, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })
    .with_context(|| {
        format!(
            "baking caustics for {} (object.model {})",
            scene.source.display(),
            model.display()
        )
    })?;
    bar.finish_and_clear();
    Ok(out)
}

fn run_bake(
    scene_path: &Path,
    output: &Path,
    params: &BakeParams,
    reference_factor: Option<u64>,
    self_check: bool,
) -> Result<()> {
    let scene = vitreous_scene::load_scene(scene_path)
        .with_context(|| format!("loading scene {}", scene_path.display()))?;
    let model = scene.object.model_path.clone();
    let scene = CausticScene::from_scene(&scene);
    let out = bake_with_bar(&scene, &model, params, "bake")?;
    let write_start = Instant::now();
    write_bake(output, &out.bake)?;
    let write_s = write_start.elapsed().as_secs_f64();

    let l = &out.ledger;
    let pct = |x: f64| 100.0 * x / l.emitted;
    println!("baked {} -> {}", scene_path.display(), output.display());
    println!(
        "  {} x {} texels, {} grid rays ({} x {} cells), seed {}",
        params.width_px,
        params.height_px,
        (params.grid_cells() as u64 + 1).pow(2),
        params.grid_cells(),
        params.grid_cells(),
        params.seed
    );
    println!(
        "  flux in the cone: direct {:.2} %, to the floor {:.2} %, reflected away {:.2} %, \
         transmitted away {:.2} %, interaction limit {:.4} %, pruned {:.4} % (sum {:.9} %)",
        pct(l.direct),
        pct(l.floor),
        pct(l.reflected_away),
        pct(l.transmitted_away),
        pct(l.interaction_limit),
        pct(l.pruned),
        pct(l.accounted())
    );
    let peak = out.bake.gain.iter().copied().fold(0.0f32, f32::max);
    let region = out
        .bake
        .gain
        .iter()
        .filter(|&&g| g > crate::bake::CAUSTIC_REGION_GAIN)
        .count();
    println!(
        "  peak gain {peak:.2}, {region} texels with G > {}",
        crate::bake::CAUSTIC_REGION_GAIN
    );
    println!(
        "  bake time {:.2} s (+ {:.2} s writing the EXR)",
        out.elapsed.as_secs_f64(),
        write_s
    );

    if self_check {
        let quarter = BakeParams {
            budget_rays: (params.budget_rays / 4).max(9),
            ..*params
        };
        let q = bake_with_bar(&scene, &model, &quarter, "self-check")?;
        let c = compare(
            &q.bake.gain,
            &out.bake.gain,
            crate::bake::CAUSTIC_REGION_GAIN,
        )
        .expect("same size");
        println!(
            "  self-check: a quarter-budget bake differs by {:.2} % relative RMS ({:.2} % per \
             texel) over {} caustic texels; since 4x the budget cuts the error 2-4x, this is \
             an upper estimate of this bake's error against a 16x reference [{:.2} s]",
            c.rel_rms * 100.0,
            c.rel_rms_per_texel * 100.0,
            c.region_texels,
            q.elapsed.as_secs_f64()
        );
    }
    if let Some(factor) = reference_factor {
        let reference = BakeParams {
            budget_rays: params.budget_rays.saturating_mul(factor.max(1)),
            ..*params
        };
        let r = bake_with_bar(&scene, &model, &reference, "reference")?;
        let c = compare(
            &out.bake.gain,
            &r.bake.gain,
            crate::bake::CAUSTIC_REGION_GAIN,
        )
        .expect("same size");
        println!(
            "  against a {factor}x-budget reference: relative RMS {:.3} %, per-texel relative \
             RMS {:.3} %, over {} caustic texels (G_ref > {}) [reference took {:.2} s]",
            c.rel_rms * 100.0,
            c.rel_rms_per_texel * 100.0,
            c.region_texels,
            crate::bake::CAUSTIC_REGION_GAIN,
            r.elapsed.as_secs_f64()
        );
    }
    Ok(())
}
