//! What a caustic bake depends on, as the hash a bake stores ([`inputs_hash`]).

use glam::{Mat4, Vec3};
use sha2::{Digest, Sha256};

/// The hash of everything a caustic bake depends on: the object's mesh (model positions,
/// normals and triangles), where the model goes (`world_from_model`: size, place, turn), its
/// index of refraction, the light's position and the floor's rectangle in the world; exactly
/// what the baker reads (`vitreous_caustics::CausticScene::from_scene`). Hex SHA-256 over
/// the values' little-endian bytes, each part labelled. The photos, the environment, the
/// viewer, the display, the effects and the file's comments do not change a caustic and are
/// not in it: editing them keeps the bake.
pub fn inputs_hash(
    object: &crate::Object,
    light_position_m: Vec3,
    world_from_floor: Mat4,
) -> String {
    /// Little-endian bytes of f32 values.
    fn le(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
        values.into_iter().flat_map(f32::to_le_bytes).collect()
    }
    let mesh = &object.mesh;
    let parts: [(&str, Vec<u8>); 7] = [
        (
            "positions",
            le(mesh.positions.iter().flat_map(|p| p.to_array())),
        ),
        (
            "normals",
            le(mesh.normals.iter().flat_map(|n| n.to_array())),
        ),
        (
            "indices",
            mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
        ),
        (
            "world_from_model",
            le(object.world_from_model.to_cols_array()),
        ),
        ("ior", le([object.ior])),
        ("light", le(light_position_m.to_array())),
        ("world_from_floor", le(world_from_floor.to_cols_array())),
    ];
    let mut hasher = Sha256::new();
    for (label, bytes) in parts {
        hasher.update(label.as_bytes());
        hasher.update([0]);
        hasher.update((bytes.len() as u64).to_le_bytes());
        hasher.update(bytes);
    }
    hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}
