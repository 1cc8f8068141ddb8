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
    ($model:literal, $suffix:literal) => {
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
    ($model:literal, $suffix:literal) => {
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

/// One glass fragment entry point: its SPIR-V and its name.
macro_rules! glass_entry {
    ($model:literal, $look:literal, $suffix:literal) => {
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

pub const GLASS_VS: &[u8] = spirv!("glass.vs_main");
/// The glass pass's fragment entry points: `[model][variant]`, the model paper (0),
/// two-surface (1), two-surface through absorbing glass (2: compiled with `ABSORBING` set),
/// two-surface through a ball (3: `BALL`, no radial-map fetch) and through an absorbing ball
/// (4: both), through a convex faceted object (5: `CONVEX`, the exit from its facet planes)
/// and through an absorbing one (6: both), the variant as `glass::GlassVariant::index`
/// numbers it; rows 7 to 13 are the same models with the room as the glass's target (`ROOM`),
/// rows 14 to 27 rows 0 to 13 again over several positions per pixel (`SUPERSAMPLED`).
pub const GLASS_FS: [[(&[u8], &std::ffi::CStr); 4]; 4 * GLASS_MODELS] = [
    glass_row!("paper", ""),
    glass_row!("two_surface", ""),
    glass_row!("two_surface", ".absorbing"),
    glass_row!("two_surface", ".ball"),
    glass_row!("two_surface", ".absorbing.ball"),
    glass_row!("two_surface", ".convex"),
    glass_row!("two_surface", ".absorbing.convex"),
    glass_row!("paper", ".room"),
    glass_row!("two_surface", ".room"),
    glass_row!("two_surface", ".absorbing.room"),
    glass_row!("two_surface", ".ball.room"),
    glass_row!("two_surface", ".absorbing.ball.room"),
    glass_row!("two_surface", ".convex.room"),
    glass_row!("two_surface", ".absorbing.convex.room"),
    glass_row!("paper", ".supersampled"),
    glass_row!("two_surface", ".supersampled"),
    glass_row!("two_surface", ".absorbing.supersampled"),
    glass_row!("two_surface", ".ball.supersampled"),
    glass_row!("two_surface", ".absorbing.ball.supersampled"),
    glass_row!("two_surface", ".convex.supersampled"),
    glass_row!("two_surface", ".absorbing.convex.supersampled"),
    glass_row!("paper", ".room.supersampled"),
    glass_row!("two_surface", ".room.supersampled"),
    glass_row!("two_surface", ".absorbing.room.supersampled"),
    glass_row!("two_surface", ".ball.room.supersampled"),
    glass_row!("two_surface", ".absorbing.ball.room.supersampled"),
    glass_row!("two_surface", ".convex.room.supersampled"),
    glass_row!("two_surface", ".absorbing.convex.room.supersampled"),
];
/// Glass models without the room; the same again with it (`ROOM`) follow them, then all of
/// those over several positions per pixel (`SUPERSAMPLED`).
pub const GLASS_MODELS: usize = 7;
/// The static cost of one invocation of each of [`GLASS_FS`]'s entry points.
pub const GLASS_FS_COST: [[ShaderCost; 4]; 4 * GLASS_MODELS] = [
    glass_cost_row!("paper", ""),
    glass_cost_row!("two_surface", ""),
    glass_cost_row!("two_surface", ".absorbing"),
    glass_cost_row!("two_surface", ".ball"),
    glass_cost_row!("two_surface", ".absorbing.ball"),
    glass_cost_row!("two_surface", ".convex"),
    glass_cost_row!("two_surface", ".absorbing.convex"),
    glass_cost_row!("paper", ".room"),
    glass_cost_row!("two_surface", ".room"),
    glass_cost_row!("two_surface", ".absorbing.room"),
    glass_cost_row!("two_surface", ".ball.room"),
    glass_cost_row!("two_surface", ".absorbing.ball.room"),
    glass_cost_row!("two_surface", ".convex.room"),
    glass_cost_row!("two_surface", ".absorbing.convex.room"),
    glass_cost_row!("paper", ".supersampled"),
    glass_cost_row!("two_surface", ".supersampled"),
    glass_cost_row!("two_surface", ".absorbing.supersampled"),
    glass_cost_row!("two_surface", ".ball.supersampled"),
    glass_cost_row!("two_surface", ".absorbing.ball.supersampled"),
    glass_cost_row!("two_surface", ".convex.supersampled"),
    glass_cost_row!("two_surface", ".absorbing.convex.supersampled"),
    glass_cost_row!("paper", ".room.supersampled"),
    glass_cost_row!("two_surface", ".room.supersampled"),
    glass_cost_row!("two_surface", ".absorbing.room.supersampled"),
    glass_cost_row!("two_surface", ".ball.room.supersampled"),
    glass_cost_row!("two_surface", ".absorbing.ball.room.supersampled"),
    glass_cost_row!("two_surface", ".convex.room.supersampled"),
    glass_cost_row!("two_surface", ".absorbing.convex.room.supersampled"),
];
pub const WORLD_VS: &[u8] = spirv!("world.vs_main");
pub const BLUR_BLEND_VS: &[u8] = spirv!("blur_blend.vs_main");
pub const BLUR_BLEND_FS: &[u8] = spirv!("blur_blend.fs_main");
pub const WORLD_FS: &[u8] = spirv!("world.fs_main");
/// Eq. 6 over the glass: the full-screen triangle at the far plane (shaders/compensation.wgsl).
pub const COMPENSATION_VS: &[u8] = spirv!("compensation.vs_main");
/// Eq. 6 over the glass: the real floor or background the eye sees, to take away; at the
/// pixel's centre, and over the pixel's footprint from the photos' ripmaps (`FOOTPRINT`).
pub const COMPENSATION_FS: [&[u8]; 2] = [
    spirv!("compensation.fs_main"),
    spirv!("compensation.fs_main.footprint"),
];
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_compensation_fetches_once_per_pixel_at_the_centre_and_over_the_footprint() {
        // Eq. 6 over the glass costs one more texture fetch per covered pixel than the frame
        // without it, also where B is the photo over the pixel's footprint (its ripmaps).
        let centre: ShaderCost = cost!("compensation.fs_main");
        let footprint: ShaderCost = cost!("compensation.fs_main.footprint");
        assert_eq!((centre.fetches, footprint.fetches), (1, 1));
        assert!(footprint.instructions > centre.instructions);
    }
}
