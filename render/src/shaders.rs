//! SPIR-V compiled from `shaders/*.wgsl` by build.rs, one constant per entry point.

/// SPIR-V bytes of one entry point, named `<file>.<entry>`.
macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

pub const GLASS_VS: &[u8] = spirv!("glass.vs_main");
pub const GLASS_FS: &[u8] = spirv!("glass.fs_main");
pub const GLASS_TWO_SURFACE_FS: &[u8] = spirv!("glass.fs_two_surface");
/// `fs_two_surface` with `ABSORBING` set: the glass absorbs (Beer-Lambert).
pub const GLASS_TWO_SURFACE_ABSORBING_FS: &[u8] = spirv!("glass.fs_two_surface.absorbing");
pub const WORLD_VS: &[u8] = spirv!("world.vs_main");
pub const WORLD_FS: &[u8] = spirv!("world.fs_main");
pub const MASK_VS: &[u8] = spirv!("inducer_mask.vs_main");
pub const MASK_FS: &[u8] = spirv!("inducer_mask.fs_main");
pub const FIELD_VS: &[u8] = spirv!("inducer_field.vs_main");
pub const SEED_FS: &[u8] = spirv!("inducer_field.fs_seed");
pub const JUMP_FS: &[u8] = spirv!("inducer_field.fs_jump");
pub const DISTANCE_FS: &[u8] = spirv!("inducer_field.fs_distance");
pub const RAMP_FS: &[u8] = spirv!("inducer_field.fs_ramp");
pub const COMBINE_FS: &[u8] = spirv!("inducer_field.fs_combine");
pub const OVERLAY_VS: &[u8] = spirv!("floor_overlay.vs_main");
pub const OVERLAY_FS: &[u8] = spirv!("floor_overlay.fs_main");
pub const CAUSTICS_TRACE_CS: &[u8] = spirv!("caustics_live.cs_trace");
pub const CAUSTICS_RESOLVE_CS: &[u8] = spirv!("caustics_live.cs_resolve");

/// Reinterprets SPIR-V bytes as words (include_bytes gives no alignment guarantee).
pub fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}
