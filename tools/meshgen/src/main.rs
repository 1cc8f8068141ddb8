//! `vitreous-meshgen`: writes the procedural glass models vitreous ships with as binary glTF.
//!
//! ```text
//! cargo run -p vitreous-meshgen -- sphere  -o config/models/sphere.glb
//! cargo run -p vitreous-meshgen -- diamond -o config/models/diamond.glb
//! cargo run -p vitreous-meshgen -- torus   -o config/models/torus.glb
//! cargo run -p vitreous-meshgen -- goblet  -o config/models/goblet.glb
//! ```
//!
//! Every model is 1.0 across its largest extent (the scene's `diameter_m` scales it; the
//! goblet's largest extent is its height), centred on the origin with +y up, and carries one
//! glass material (`KHR_materials_transmission` 1.0 plus `KHR_materials_ior`).

mod diamond;
mod glb;
mod goblet;
mod mesh;
mod sphere;
mod torus;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use glb::GlassMaterial;
use mesh::Mesh;
use std::path::{Path, PathBuf};

/// Command line.
#[derive(Debug, Parser)]
#[command(name = "vitreous-meshgen", version, about)]
struct Cli {
    /// Which model to write.
    #[command(subcommand)]
    shape: Shape,
}

/// The models this tool can generate.
#[derive(Debug, Subcommand)]
enum Shape {
    /// Glass sphere of unit diameter (UV sphere, smooth normals, equirectangular UVs).
    Sphere(SphereArgs),
    /// Round brilliant diamond of unit girdle diameter (57 facets, flat shading).
    Diamond(DiamondArgs),
    /// Glass torus of unit outer diameter lying flat (axis +y).
    Torus(TorusArgs),
    /// Glass goblet of unit height standing on +y: bowl with a wall, rounded rim, solid stem,
    /// foot (not convex, not star-shaped).
    Goblet(GobletArgs),
}

/// Options of `sphere`.
#[derive(Debug, Args)]
struct SphereArgs {
    /// Output .glb path.
    #[arg(short, long)]
    output: PathBuf,
    /// Index of refraction.
    #[arg(long, default_value_t = 1.51)]
    ior: f32,
    /// Segments around the vertical axis.
    #[arg(long, default_value_t = 96)]
    segments: u32,
    /// Rings from pole to pole.
    #[arg(long, default_value_t = 48)]
    rings: u32,
}

/// Options of `diamond`; lengths are fractions of the girdle diameter.
#[derive(Debug, Args)]
struct DiamondArgs {
    /// Output .glb path.
    #[arg(short, long)]
    output: PathBuf,
    /// Index of refraction.
    #[arg(long, default_value_t = 2.42)]
    ior: f32,
    /// Table width, corner to corner of the octagon.
    #[arg(long, default_value_t = diamond::Proportions::default().table)]
    table: f64,
    /// Bezel angle to the girdle plane, degrees.
    #[arg(long, default_value_t = diamond::Proportions::default().crown_angle_deg)]
    crown_angle_deg: f64,
    /// Pavilion main angle to the girdle plane, degrees.
    #[arg(long, default_value_t = diamond::Proportions::default().pavilion_angle_deg)]
    pavilion_angle_deg: f64,
    /// Girdle band height.
    #[arg(long, default_value_t = diamond::Proportions::default().girdle)]
    girdle: f64,
    /// Star length, table edge towards girdle.
    #[arg(long, default_value_t = diamond::Proportions::default().star)]
    star: f64,
    /// Lower-girdle length, girdle towards culet.
    #[arg(long, default_value_t = diamond::Proportions::default().lower_girdle)]
    lower_girdle: f64,
}

/// Options of `torus`.
#[derive(Debug, Args)]
struct TorusArgs {
    /// Output .glb path.
    #[arg(short, long)]
    output: PathBuf,
    /// Index of refraction.
    #[arg(long, default_value_t = 1.51)]
    ior: f32,
    /// Tube radius; the ring radius is 0.5 minus this.
    #[arg(long, default_value_t = torus::DEFAULT_MINOR_RADIUS)]
    minor_radius: f64,
    /// Segments around the vertical axis.
    #[arg(long, default_value_t = 96)]
    major_segments: u32,
    /// Segments around the tube.
    #[arg(long, default_value_t = 48)]
    minor_segments: u32,
}

/// Options of `goblet`.
#[derive(Debug, Args)]
struct GobletArgs {
    /// Output .glb path.
    #[arg(short, long)]
    output: PathBuf,
    /// Index of refraction.
    #[arg(long, default_value_t = 1.5)]
    ior: f32,
    /// Segments around the vertical axis.
    #[arg(long, default_value_t = goblet::DEFAULT_SEGMENTS)]
    segments: u32,
}

/// Writes `mesh` as `name` with a glass material and prints what was written.
fn save(output: &Path, mesh: &Mesh, name: &str, ior: f32) -> Result<()> {
    let material = GlassMaterial {
        name: format!("{name}_glass"),
        ior,
    };
    let bytes = glb::write(output, mesh, name, &material)?;
    let (min, max) = mesh.bounds();
    let size = max - min;
    println!(
        "wrote {}: {} bytes, {} vertices, {} triangles, size {:.4} x {:.4} x {:.4}, \
         volume {:.5}, ior {ior}",
        output.display(),
        bytes,
        mesh.vertex_count(),
        mesh.triangle_count(),
        size.x,
        size.y,
        size.z,
        mesh.signed_volume(),
    );
    Ok(())
}

fn main() -> Result<()> {
    match Cli::parse().shape {
        Shape::Sphere(a) => save(
            &a.output,
            &sphere::mesh(a.segments, a.rings)?,
            "sphere",
            a.ior,
        ),
        Shape::Diamond(a) => {
            let cut = diamond::Proportions {
                table: a.table,
                crown_angle_deg: a.crown_angle_deg,
                pavilion_angle_deg: a.pavilion_angle_deg,
                girdle: a.girdle,
                star: a.star,
                lower_girdle: a.lower_girdle,
            };
            let mesh = diamond::mesh(&cut)?;
            println!(
                "round brilliant: table {:.1}%, crown {:.2} deg ({:.1}% high), pavilion {:.2} deg \
                 ({:.1}% deep), girdle {:.1}%, total depth {:.1}%, star {:.0}%, lower girdle {:.0}%",
                cut.table * 100.0,
                cut.crown_angle_deg,
                cut.crown_height() * 100.0,
                cut.pavilion_angle_deg,
                cut.pavilion_depth() * 100.0,
                cut.girdle * 100.0,
                cut.total_depth() * 100.0,
                cut.star * 100.0,
                cut.lower_girdle * 100.0,
            );
            save(&a.output, &mesh, "diamond", a.ior)
        }
        Shape::Torus(a) => {
            let mesh = torus::mesh(a.minor_radius, a.major_segments, a.minor_segments)?;
            save(&a.output, &mesh, "torus", a.ior)
        }
        Shape::Goblet(a) => {
            let mesh = goblet::mesh(&goblet::Proportions::default(), a.segments)?;
            save(&a.output, &mesh, "goblet", a.ior)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn command_line_is_well_formed() {
        Cli::command().debug_assert();
    }

    #[test]
    fn ior_defaults_follow_the_material() {
        let parse = |args: &[&str]| Cli::try_parse_from(args).unwrap().shape;
        match parse(&["meshgen", "diamond", "-o", "d.glb"]) {
            Shape::Diamond(a) => assert_eq!(a.ior, 2.42),
            other => panic!("{other:?}"),
        }
        match parse(&["meshgen", "sphere", "-o", "s.glb"]) {
            Shape::Sphere(a) => assert_eq!((a.ior, a.segments, a.rings), (1.51, 96, 48)),
            other => panic!("{other:?}"),
        }
        match parse(&["meshgen", "torus", "-o", "t.glb", "--minor-radius", "0.1"]) {
            Shape::Torus(a) => assert_eq!((a.ior, a.minor_radius), (1.51, 0.1)),
            other => panic!("{other:?}"),
        }
        match parse(&["meshgen", "goblet", "-o", "g.glb"]) {
            Shape::Goblet(a) => assert_eq!((a.ior, a.segments), (1.5, 48)),
            other => panic!("{other:?}"),
        }
    }
}
