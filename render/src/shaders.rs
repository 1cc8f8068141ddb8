//! SPIR-V compiled from `shaders/*.wgsl` by build.rs, one constant per entry point.

/// SPIR-V bytes of one entry point, named `<file>.<entry>`.
macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

pub const GLASS_VS: &[u8] = spirv!("glass.vs_main");
/// The glass pass's fragment entry points: `[model][variant]`, the model paper (0),
/// two-surface (1), two-surface through absorbing glass (2: compiled with `ABSORBING` set),
/// two-surface through a ball (3: `BALL`, no radial-map fetch) and through an absorbing ball
/// (4: both), the variant as `glass::GlassVariant::index` numbers it.
pub const GLASS_FS: [[(&[u8], &std::ffi::CStr); 4]; 5] = [
    [
        (
            spirv!("glass.fs_paper_environment_fresnel"),
            c"fs_paper_environment_fresnel",
        ),
        (
            spirv!("glass.fs_paper_environment_phong"),
            c"fs_paper_environment_phong",
        ),
        (
            spirv!("glass.fs_paper_background_fresnel"),
            c"fs_paper_background_fresnel",
        ),
        (
            spirv!("glass.fs_paper_background_phong"),
            c"fs_paper_background_phong",
        ),
    ],
    [
        (
            spirv!("glass.fs_two_surface_environment_fresnel"),
            c"fs_two_surface_environment_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_environment_phong"),
            c"fs_two_surface_environment_phong",
        ),
        (
            spirv!("glass.fs_two_surface_background_fresnel"),
            c"fs_two_surface_background_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_background_phong"),
            c"fs_two_surface_background_phong",
        ),
    ],
    [
        (
            spirv!("glass.fs_two_surface_environment_fresnel.absorbing"),
            c"fs_two_surface_environment_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_environment_phong.absorbing"),
            c"fs_two_surface_environment_phong",
        ),
        (
            spirv!("glass.fs_two_surface_background_fresnel.absorbing"),
            c"fs_two_surface_background_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_background_phong.absorbing"),
            c"fs_two_surface_background_phong",
        ),
    ],
    [
        (
            spirv!("glass.fs_two_surface_environment_fresnel.ball"),
            c"fs_two_surface_environment_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_environment_phong.ball"),
            c"fs_two_surface_environment_phong",
        ),
        (
            spirv!("glass.fs_two_surface_background_fresnel.ball"),
            c"fs_two_surface_background_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_background_phong.ball"),
            c"fs_two_surface_background_phong",
        ),
    ],
    [
        (
            spirv!("glass.fs_two_surface_environment_fresnel.absorbing.ball"),
            c"fs_two_surface_environment_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_environment_phong.absorbing.ball"),
            c"fs_two_surface_environment_phong",
        ),
        (
            spirv!("glass.fs_two_surface_background_fresnel.absorbing.ball"),
            c"fs_two_surface_background_fresnel",
        ),
        (
            spirv!("glass.fs_two_surface_background_phong.absorbing.ball"),
            c"fs_two_surface_background_phong",
        ),
    ],
];
pub const WORLD_VS: &[u8] = spirv!("world.vs_main");
pub const WORLD_FS: &[u8] = spirv!("world.fs_main");
pub const MASK_VS: &[u8] = spirv!("inducer_mask.vs_main");
pub const MASK_FS: &[u8] = spirv!("inducer_mask.fs_main");
pub const FIELD_VS: &[u8] = spirv!("inducer_field.vs_main");
pub const COLUMNS_CS: &[u8] = spirv!("inducer_distance.cs_columns");
pub const ROWS_CS: &[u8] = spirv!("inducer_distance.cs_rows");
pub const DISTANCE_FS: &[u8] = spirv!("inducer_field.fs_distance");
pub const RAMP_FS: &[u8] = spirv!("inducer_field.fs_ramp");
pub const COMBINE_FS: &[u8] = spirv!("inducer_field.fs_combine");
pub const OVERLAY_VS: &[u8] = spirv!("floor_overlay.vs_main");
pub const OVERLAY_FS: &[u8] = spirv!("floor_overlay.fs_main");
pub const CAUSTICS_TRACE_CS: &[u8] = spirv!("caustics_live.cs_trace");
pub const CAUSTICS_SMOOTH_CS: &[u8] = spirv!("caustics_live.cs_smooth");

/// Reinterprets SPIR-V bytes as words (include_bytes gives no alignment guarantee).
pub fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}
