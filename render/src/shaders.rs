//! SPIR-V compiled from `shaders/*.wgsl` by build.rs, one constant per entry point, and the
//! static cost of an invocation of those whose work a frame counts (`work.rs`).

use crate::work::ShaderCost;

/// SPIR-V bytes of one entry point, named `<file>.<entry>`.
macro_rules! spirv {
    ($name:expr) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

/// The glass pass's four fragment entry points (`glass::GlassVariant::index` order) of one
/// model, `fs_<model>_*` compiled with the pipeline constants that `<suffix>` names
/// (build.rs `VARIANTS`).
macro_rules! glass_row {
    ($model:literal, $suffix:expr) => {
        [
            glass_entry!($model, "environment_fresnel", $suffix),
            glass_entry!($model, "environment_phong", $suffix),
            glass_entry!($model, "background_fresnel", $suffix),
            glass_entry!($model, "background_phong", $suffix),
        ]
    };
}

/// The static cost of one invocation of an entry point named `<file>.<entry>[.<suffix>]`
/// (build.rs).
macro_rules! cost {
    ($name:expr) => {
        include!(concat!(env!("OUT_DIR"), "/", $name, ".cost.rs"))
    };
}

/// The costs of [`glass_row!`]'s entry points.
macro_rules! glass_cost_row {
    ($model:literal, $suffix:expr) => {
        [
            cost!(concat!(
                "glass.fs_",
                $model,
                "_environment_fresnel",
                $suffix
            )),
            cost!(concat!("glass.fs_", $model, "_environment_phong", $suffix)),
            cost!(concat!("glass.fs_", $model, "_background_fresnel", $suffix)),
            cost!(concat!("glass.fs_", $model, "_background_phong", $suffix)),
        ]
    };
}

/// Every row of a glass table ([`GLASS_FS`] or its costs), `$row` ([`glass_row!`] or
/// [`glass_cost_row!`]) of each model, with the room, over several positions, and both, the
/// suffixes ending in `$tail`.
macro_rules! glass_rows {
    ($row:ident, $tail:literal) => {
        [
            $row!("paper", concat!("", $tail)),
            $row!("two_surface", concat!("", $tail)),
            $row!("two_surface", concat!(".absorbing", $tail)),
            $row!("two_surface", concat!(".ball", $tail)),
            $row!("two_surface", concat!(".absorbing.ball", $tail)),
            $row!("two_surface", concat!(".convex", $tail)),
            $row!("two_surface", concat!(".absorbing.convex", $tail)),
            $row!("paper", concat!(".room", $tail)),
            $row!("two_surface", concat!(".room", $tail)),
            $row!("two_surface", concat!(".absorbing.room", $tail)),
            $row!("two_surface", concat!(".ball.room", $tail)),
            $row!("two_surface", concat!(".absorbing.ball.room", $tail)),
            $row!("two_surface", concat!(".convex.room", $tail)),
            $row!("two_surface", concat!(".absorbing.convex.room", $tail)),
            $row!("paper", concat!(".supersampled", $tail)),
            $row!("two_surface", concat!(".supersampled", $tail)),
            $row!("two_surface", concat!(".absorbing.supersampled", $tail)),
            $row!("two_surface", concat!(".ball.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.ball.supersampled", $tail)
            ),
            $row!("two_surface", concat!(".convex.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.convex.supersampled", $tail)
            ),
            $row!("paper", concat!(".room.supersampled", $tail)),
            $row!("two_surface", concat!(".room.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.room.supersampled", $tail)
            ),
            $row!("two_surface", concat!(".ball.room.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.ball.room.supersampled", $tail)
            ),
            $row!("two_surface", concat!(".convex.room.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.convex.room.supersampled", $tail)
            ),
        ]
    };
}

/// The two background entry points of `fs_<model>_*` compiled with `COVERED` and the
/// constants `<suffix>` names.
macro_rules! covered_row {
    ($model:literal, $suffix:expr) => {
        [
            glass_entry!($model, "background_fresnel", $suffix),
            glass_entry!($model, "background_phong", $suffix),
        ]
    };
}

/// The costs of [`covered_row!`]'s entry points.
macro_rules! covered_cost_row {
    ($model:literal, $suffix:expr) => {
        [
            cost!(concat!("glass.fs_", $model, "_background_fresnel", $suffix)),
            cost!(concat!("glass.fs_", $model, "_background_phong", $suffix)),
        ]
    };
}

/// The rows of a covered table ([`GLASS_FS_COVERED`] or its costs), the suffixes ending in
/// `$tail`.
macro_rules! covered_rows {
    ($row:ident, $tail:literal) => {
        [
            $row!("paper", concat!(".covered", $tail)),
            $row!("two_surface", concat!(".ball.covered", $tail)),
            $row!("two_surface", concat!(".absorbing.ball.covered", $tail)),
            $row!("paper", concat!(".covered.supersampled", $tail)),
            $row!("two_surface", concat!(".ball.covered.supersampled", $tail)),
            $row!(
                "two_surface",
                concat!(".absorbing.ball.covered.supersampled", $tail)
            ),
        ]
    };
}

/// The environment looks of two surfaces compiled with the constants `<suffix>` names.
macro_rules! counted_row {
    ($suffix:expr) => {
        [
            glass_entry!("two_surface", "environment_fresnel", $suffix),
            glass_entry!("two_surface", "environment_phong", $suffix),
        ]
    };
}

/// The costs of [`counted_row!`]'s entry points.
macro_rules! counted_cost_row {
    ($suffix:expr) => {
        [
            cost!(concat!("glass.fs_two_surface_environment_fresnel", $suffix)),
            cost!(concat!("glass.fs_two_surface_environment_phong", $suffix)),
        ]
    };
}

/// Every look of two surfaces, in `glass::GlassVariant::index` order, compiled with the constants
/// `<suffix>` names.
macro_rules! mesh_counted_row {
    ($suffix:expr) => {
        [
            glass_entry!("two_surface", "environment_fresnel", $suffix),
            glass_entry!("two_surface", "environment_phong", $suffix),
            glass_entry!("two_surface", "background_fresnel", $suffix),
            glass_entry!("two_surface", "background_phong", $suffix),
        ]
    };
}

/// The costs of [`mesh_counted_row!`]'s entry points.
macro_rules! mesh_counted_cost_row {
    ($suffix:expr) => {
        [
            cost!(concat!("glass.fs_two_surface_environment_fresnel", $suffix)),
            cost!(concat!("glass.fs_two_surface_environment_phong", $suffix)),
            cost!(concat!("glass.fs_two_surface_background_fresnel", $suffix)),
            cost!(concat!("glass.fs_two_surface_background_phong", $suffix)),
        ]
    };
}

/// The rows of [`GLASS_FS_MESH_COUNTED`] or its costs, the suffixes ending in `$tail`.
macro_rules! mesh_counted_rows {
    ($row:ident, $tail:literal) => {
        [
            $row!(concat!($tail, ".counted")),
            $row!(concat!(".absorbing", $tail, ".counted")),
            $row!(concat!(".room", $tail, ".counted")),
            $row!(concat!(".absorbing.room", $tail, ".counted")),
            $row!(concat!(".supersampled", $tail, ".counted")),
            $row!(concat!(".absorbing.supersampled", $tail, ".counted")),
            $row!(concat!(".room.supersampled", $tail, ".counted")),
            $row!(concat!(".absorbing.room.supersampled", $tail, ".counted")),
        ]
    };
}

/// One glass fragment entry point: its SPIR-V and its name.
macro_rules! glass_entry {
    ($model:literal, $look:literal, $suffix:expr) => {
        (
            spirv!(concat!("glass.fs_", $model, "_", $look, $suffix)),
            match std::ffi::CStr::from_bytes_with_nul(
                concat!("fs_", $model, "_", $look, "\0").as_bytes(),
            ) {
                Ok(name) => name,
                Err(_) => panic!("an entry point name without NUL inside"),
            },
        )
    };
}

/// A glass fragment entry point: its SPIR-V and its name.
pub type GlassEntry = (&'static [u8], &'static std::ffi::CStr);

pub const GLASS_VS: &[u8] = spirv!("glass.vs_main");
/// The glass's vertex shader for a ball drawn on its proxy (render/src/glass/proxy.rs).
pub const GLASS_VS_BALL_PROXY: &[u8] = spirv!("glass.vs_ball_proxy");
/// The glass pass's fragment entry points: `[compensated][model][variant]`. The model paper (0),
/// two-surface (1), two-surface through absorbing glass (2: compiled with `ABSORBING` set),
/// two-surface through a ball (3: `BALL`, no radial-map fetch) and through an absorbing ball
/// (4: both), through a convex faceted object (5: `CONVEX`, the exit from its facet planes)
/// and through an absorbing one (6: both), the variant as `glass::GlassVariant::index`
/// numbers it; rows 7 to 13 are the same models with the room as the glass's target (`ROOM`),
/// rows 14 to 27 rows 0 to 13 again over several positions per pixel (`SUPERSAMPLED`). The
/// first index: as they are (0), or taking away what the eye already sees (1: `COMPENSATED`,
/// eq. 6 over the glass).
pub const GLASS_FS: [[[GlassEntry; 4]; 4 * GLASS_MODELS]; 2] = [
    glass_rows!(glass_row, ""),
    glass_rows!(glass_row, ".compensated"),
];
/// Glass models without the room; the same again with it (`ROOM`) follow them, then all of
/// those over several positions per pixel (`SUPERSAMPLED`).
pub const GLASS_MODELS: usize = 7;
/// The static cost of one invocation of each of [`GLASS_FS`]'s entry points.
pub const GLASS_FS_COST: [[[ShaderCost; 4]; 4 * GLASS_MODELS]; 2] = [
    glass_rows!(glass_cost_row, ""),
    glass_rows!(glass_cost_row, ".compensated"),
];
/// The background looks of the models whose refraction towards the background can be proved
/// to reach its photo (`coverage.rs`), compiled with `COVERED`: `[compensated][row][phong]`,
/// the rows (`covered_row`) the paper's model, two surfaces through a ball and through an
/// absorbing ball, then the same over several positions per pixel.
pub const GLASS_FS_COVERED: [[[GlassEntry; 2]; 6]; 2] = [
    covered_rows!(covered_row, ""),
    covered_rows!(covered_row, ".compensated"),
];
/// The static cost of one invocation of each of [`GLASS_FS_COVERED`]'s entry points.
pub const GLASS_FS_COVERED_COST: [[[ShaderCost; 2]; 6]; 2] = [
    covered_rows!(covered_cost_row, ""),
    covered_rows!(covered_cost_row, ".compensated"),
];

/// The environment looks (fresnel, Phong) of the rows of [`GLASS_FS`] that shade a ball's light
/// in the room in two parts, each over as many positions as it needs (two surfaces through a
/// clear ball and through an absorbing one, over several positions per pixel:
/// shaders/shared/glass_positions.wgsl), compiled with `COUNTED`: they count the positions they
/// shade, for the frames that count their work. `[compensated][row][phong]`.
pub const GLASS_FS_COUNTED: [[[GlassEntry; 2]; 2]; 2] = [
    [
        counted_row!(".ball.room.supersampled.counted"),
        counted_row!(".absorbing.ball.room.supersampled.counted"),
    ],
    [
        counted_row!(".ball.room.supersampled.compensated.counted"),
        counted_row!(".absorbing.ball.room.supersampled.compensated.counted"),
    ],
];
/// The static cost of one invocation of each of [`GLASS_FS_COUNTED`]'s entry points.
pub const GLASS_FS_COUNTED_COST: [[[ShaderCost; 2]; 2]; 2] = [
    [
        counted_cost_row!(".ball.room.supersampled.counted"),
        counted_cost_row!(".absorbing.ball.room.supersampled.counted"),
    ],
    [
        counted_cost_row!(".ball.room.supersampled.compensated.counted"),
        counted_cost_row!(".absorbing.ball.room.supersampled.compensated.counted"),
    ],
];

/// The static cost of one position of each part of a ball's light in the rows of
/// [`GLASS_FS_COUNTED`] (shaders/shared/glass_positions.wgsl), from the entry points that shade
/// one: `[row][part]`, the parts the first image, the rest in an environment-reflection look and
/// in a Phong look.
pub const GLASS_PART_COST: [[ShaderCost; 3]; 2] = [
    [
        cost!("glass.fs_two_surface_first_image.ball.room"),
        cost!("glass.fs_two_surface_rest_fresnel.ball.room"),
        cost!("glass.fs_two_surface_rest_phong.ball.room"),
    ],
    [
        cost!("glass.fs_two_surface_first_image.absorbing.ball.room"),
        cost!("glass.fs_two_surface_rest_fresnel.absorbing.ball.room"),
        cost!("glass.fs_two_surface_rest_phong.absorbing.ball.room"),
    ],
];

/// Every look of the rows of [`GLASS_FS`] of two surfaces through a mesh (neither a ball nor a
/// convex gem: clear, absorbing, each with and without the room, each over one position and
/// several), compiled with `COUNTED`: they count the nodes and triangles the mesh's searches
/// visit and test (shaders/glass.wgsl `mesh_hit`), for the frames that count their work.
/// `[compensated][row][variant]`.
pub const GLASS_FS_MESH_COUNTED: [[[GlassEntry; 4]; 8]; 2] = [
    mesh_counted_rows!(mesh_counted_row, ""),
    mesh_counted_rows!(mesh_counted_row, ".compensated"),
];
/// The static cost of one invocation of each of [`GLASS_FS_MESH_COUNTED`]'s entry points.
pub const GLASS_FS_MESH_COUNTED_COST: [[[ShaderCost; 4]; 8]; 2] = [
    mesh_counted_rows!(mesh_counted_cost_row, ""),
    mesh_counted_rows!(mesh_counted_cost_row, ".compensated"),
];
/// The static cost of one node a mesh's search visits and of one triangle it tests, from the
/// entry points that do one each (shaders/glass.wgsl `fs_two_surface_mesh_node`,
/// `fs_two_surface_mesh_triangle`).
pub const GLASS_MESH_COST: [ShaderCost; 2] = [
    cost!("glass.fs_two_surface_mesh_node"),
    cost!("glass.fs_two_surface_mesh_triangle"),
];

/// The row of [`GLASS_FS_MESH_COUNTED`] of the model in row `model` of [`GLASS_FS`], if it
/// leaves a mesh through its triangles.
pub const fn mesh_counted_row(model: usize) -> Option<usize> {
    // Two surfaces through a clear mesh (1) and an absorbing one (2), with the room (+7), over
    // several positions (+14).
    match model {
        1 => Some(0),
        2 => Some(1),
        8 => Some(2),
        9 => Some(3),
        15 => Some(4),
        16 => Some(5),
        22 => Some(6),
        23 => Some(7),
        _ => None,
    }
}

/// The row of [`GLASS_FS_COUNTED`] of the model in row `model` of [`GLASS_FS`], if it shades a
/// ball's light in the room in two parts.
pub const fn counted_row(model: usize) -> Option<usize> {
    // Two surfaces through a clear ball (3) and an absorbing one (4), with the room (+7), over
    // several positions (+14).
    match model {
        24 => Some(0),
        25 => Some(1),
        _ => None,
    }
}

/// The row of [`GLASS_FS_COVERED`] of the model in row `model` of [`GLASS_FS`], if it has
/// one.
pub const fn covered_row(model: usize) -> Option<usize> {
    let supersampled = model / (2 * GLASS_MODELS);
    let row = match model % (2 * GLASS_MODELS) {
        0 => 0,
        3 => 1,
        4 => 2,
        _ => return None,
    };
    Some(3 * supersampled + row)
}

pub const WORLD_VS: &[u8] = spirv!("world.vs_main");
pub const BLUR_BLEND_VS: &[u8] = spirv!("blur_blend.vs_main");
pub const BLUR_BLEND_FS: &[u8] = spirv!("blur_blend.fs_main");
pub const WORLD_FS: &[u8] = spirv!("world.fs_main");
/// The real world over each pixel's footprint, from the photos' ripmaps (shaders/world.wgsl).
pub const WORLD_FOOTPRINT_FS: &[u8] = spirv!("world.fs_footprint");
/// The segmented dimmer's panel: each cell's want, spread, softened (shaders/dimmer_panel.wgsl).
pub const DIMMER_WANT_CS: &[u8] = spirv!("dimmer_panel.want");
/// See [`DIMMER_WANT_CS`].
pub const DIMMER_SPREAD_CS: &[u8] = spirv!("dimmer_panel.spread");
/// See [`DIMMER_WANT_CS`].
pub const DIMMER_SOFTEN_CS: &[u8] = spirv!("dimmer_panel.soften");
/// The segmented dimmer's eye image: light and alpha (shaders/dimmer_resolve.wgsl).
pub const DIMMER_RESOLVE_VS: &[u8] = spirv!("dimmer_resolve.vs_main");
/// See [`DIMMER_RESOLVE_VS`].
pub const DIMMER_RESOLVE_FS: &[u8] = spirv!("dimmer_resolve.fs_main");
pub const MASK_VS: &[u8] = spirv!("inducer_mask.vs_main");
pub const MASK_FS: &[u8] = spirv!("inducer_mask.fs_main");
pub const FIELD_VS: &[u8] = spirv!("inducer_field.vs_main");
pub const COLUMNS_CS: &[u8] = spirv!("inducer_distance.cs_columns");
pub const ROWS_CS: &[u8] = spirv!("inducer_distance.cs_rows");
pub const DISTANCE_FS: &[u8] = spirv!("inducer_field.fs_distance");
pub const OVERLAY_VS: &[u8] = spirv!("floor_overlay.vs_main");
/// The floor overlay's fragment shader: the inducer's gain alone, with the caustic gain G
/// (`CAUSTICS`), and with G filtered by the sampler (`FILTERED_CAUSTICS`).
pub const OVERLAY_FS: [&[u8]; 6] = [
    spirv!("floor_overlay.fs_main"),
    spirv!("floor_overlay.fs_main.caustics"),
    spirv!("floor_overlay.fs_main.caustics.filtered"),
    spirv!("floor_overlay.fs_main.shadow"),
    spirv!("floor_overlay.fs_main.shadow.caustics"),
    spirv!("floor_overlay.fs_main.shadow.caustics.filtered"),
];
/// The static cost of one invocation of each of [`OVERLAY_FS`]'s entry points.
pub const OVERLAY_FS_COST: [ShaderCost; 6] = [
    cost!("floor_overlay.fs_main"),
    cost!("floor_overlay.fs_main.caustics"),
    cost!("floor_overlay.fs_main.caustics.filtered"),
    cost!("floor_overlay.fs_main.shadow"),
    cost!("floor_overlay.fs_main.shadow.caustics"),
    cost!("floor_overlay.fs_main.shadow.caustics.filtered"),
];
pub const CAUSTICS_TRACE_CS: &[u8] = spirv!("caustics_live.cs_trace");
/// The same, counting the photons it traces and the deposits they make (`COUNTED`).
pub const CAUSTICS_TRACE_COUNTED_CS: &[u8] = spirv!("caustics_live.cs_trace.counted");
/// The smoothing's passes: the short kernel along the rows and along the columns, the ring
/// buffers' pass for wider boxes, and the short kernel's tiles.
pub const CAUSTICS_SMOOTH_CS: [&[u8]; 4] = [
    spirv!("caustics_smooth.cs_smooth_rows"),
    spirv!("caustics_smooth.cs_smooth_columns"),
    spirv!("caustics_smooth.cs_smooth_wide"),
    spirv!("caustics_smooth.cs_smooth_tiles"),
];

/// Reinterprets SPIR-V bytes as words (include_bytes gives no alignment guarantee).
pub fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Every entry point's loops that end on values read only from uniform buffers and push
/// constants (build/uniform_loops.rs): the entry point (`<file>.<entry>[.<suffix>]`) and what
/// ends the loop. lavapipe compiles such a shader again at every bind of its pipeline where it
/// finds folding the values in worth it, and keeps every copy.
#[cfg(test)]
const UNIFORM_LOOPS: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/uniform_loops.rs"));

#[cfg(test)]
mod tests {
    use super::*;

    /// The descriptor sets an entry point's SPIR-V declares (its `DescriptorSet` decorations).
    fn descriptor_sets(bytes: &[u8]) -> std::collections::BTreeSet<u32> {
        const OP_DECORATE: u32 = 71;
        const DESCRIPTOR_SET: u32 = 34;
        let words = words(bytes);
        let mut sets = std::collections::BTreeSet::new();
        let mut at = 5;
        while at < words.len() {
            let (count, op) = ((words[at] >> 16) as usize, words[at] & 0xffff);
            if op == OP_DECORATE && words.get(at + 2) == Some(&DESCRIPTOR_SET) {
                sets.insert(words[at + 3]);
            }
            at += count.max(1);
        }
        sets
    }

    #[test]
    fn only_the_inducer_distance_passes_end_loops_on_uniform_values() {
        // The glass's grid of positions per pixel once ended on the side read from its uniform
        // buffer: lavapipe (Mesa 22.3) compiled glass-sphere-real's glass again at every bind
        // and kept every copy (7 MB a frame). A frame's draws bind their pipelines every frame,
        // so none of them may end a loop so. The distance transform's passes end theirs on the
        // region in their push constants; they run once per pose, and soaks of the moving
        // scenes, which run them at every frame that moves, stay flat (`vitreous soak`).
        let found: std::collections::BTreeSet<&str> =
            UNIFORM_LOOPS.iter().map(|&(entry, _)| entry).collect();
        let expected: std::collections::BTreeSet<&str> =
            ["inducer_distance.cs_columns", "inducer_distance.cs_rows"].into();
        assert_eq!(found, expected, "{UNIFORM_LOOPS:#?}");
    }

    #[test]
    fn only_the_compensated_glass_pipelines_declare_set_1() {
        // build.rs drops the branches `COMPENSATED` rules out, and what only they read: the
        // glass's pipelines without it must not name set 1, which their layout lacks.
        for (compensated, rows) in GLASS_FS.iter().enumerate() {
            for (row, entries) in rows.iter().enumerate() {
                for (variant, (spirv, _)) in entries.iter().enumerate() {
                    let expected: std::collections::BTreeSet<u32> =
                        (0..=compensated as u32).collect();
                    assert_eq!(
                        descriptor_sets(spirv),
                        expected,
                        "compensated {compensated} row {row} variant {variant}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_compensation_costs_the_glass_one_more_fetch_per_pixel() {
        // Eq. 6 over the glass costs one more texture fetch per covered pixel than the frame
        // without it, at the pixel's centre and over its footprint (the photos' ripmaps), in
        // every model and variant; and the pipelines without it hold none of its code.
        for (row, (plain, compensated)) in
            GLASS_FS_COST[0].iter().zip(&GLASS_FS_COST[1]).enumerate()
        {
            for (variant, (p, c)) in plain.iter().zip(compensated).enumerate() {
                assert_eq!(c.fetches, p.fetches + 1, "row {row} variant {variant}");
                assert_eq!(c.texels, p.texels + 4, "row {row} variant {variant}");
                assert!(
                    c.instructions > p.instructions,
                    "row {row} variant {variant}"
                );
            }
        }
    }
}
