//! SPIR-V compiled from `shaders/*.wgsl` by build.rs.

/// SPIR-V bytes of one entry point, named `<file>.<entry>`.
macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

pub const GLASS_VS: &[u8] = spirv!("glass.vs_main");
pub const GLASS_FS: &[u8] = spirv!("glass.fs_main");
pub const WORLD_VS: &[u8] = spirv!("world.vs_main");
pub const WORLD_FS: &[u8] = spirv!("world.fs_main");

/// Reinterprets SPIR-V bytes as words (include_bytes gives no alignment guarantee).
pub fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}
