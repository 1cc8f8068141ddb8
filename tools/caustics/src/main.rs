//! `vitreous-caustics`: bakes a scene's caustic gain map (paper eq. 6) to an EXR (as `vitreous
//! bake`, through the same `command::bake_command`), and compares bakes.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use vitreous_caustics::bake_file::read_bake_unchecked;
use vitreous_caustics::command::{BakeArgs, bake_command};
use vitreous_caustics::compare;

#[derive(Parser)]
#[command(
    name = "vitreous-caustics",
    version,
    about = "Bakes the caustics a virtual glass object throws onto the real floor"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bake a scene's caustic gain map G (docs/caustics.md).
    Bake(BakeArgs),
    /// Print the RMS difference of a bake against a reference bake.
    Compare {
        /// The bake to judge.
        test: PathBuf,
        /// The reference (for example baked with 16x the budget).
        reference: PathBuf,
        /// Caustic region: texels where the reference gain exceeds this.
        #[arg(long, default_value_t = vitreous_caustics::bake::CAUSTIC_REGION_GAIN)]
        threshold: f32,
        /// Also write both gain maps as raw little-endian f32 files into this folder.
        #[arg(long, hide = true)]
        dump_raw: Option<PathBuf>,
    },
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Bake(args) => bake_command(args),
        Command::Compare {
            test,
            reference,
            threshold,
            dump_raw,
        } => {
            let t = read_bake_unchecked(&test)?;
            let r = read_bake_unchecked(&reference)?;
            if (t.width_px, t.height_px) != (r.width_px, r.height_px) {
                bail!(
                    "{} is {} x {} texels but {} is {} x {}",
                    test.display(),
                    t.width_px,
                    t.height_px,
                    reference.display(),
                    r.width_px,
                    r.height_px
                );
            }
            if let Some(dir) = dump_raw {
                let raw = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
                vitreous_trace::atomic_file::write(dir.join("test.f32"), &raw(&t.gain))
                    .with_context(|| format!("writing {}", dir.join("test.f32").display()))?;
                vitreous_trace::atomic_file::write(dir.join("reference.f32"), &raw(&r.gain))
                    .with_context(|| format!("writing {}", dir.join("reference.f32").display()))?;
            }
            if t.inputs_hash != r.inputs_hash {
                eprintln!(
                    "warning: the two bakes were made for different objects, lights or floors"
                );
            }
            let c = compare(&t.gain, &r.gain, threshold).expect("sizes checked");
            println!(
                "caustic region (reference G > {threshold}): {} texels; relative RMS {:.3} %, \
                 per-texel relative RMS {:.3} %",
                c.region_texels,
                c.rel_rms * 100.0,
                c.rel_rms_per_texel * 100.0
            );
            Ok(())
        }
    }
}
