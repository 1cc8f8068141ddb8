//! Binary glTF 2.0 (.glb) writer: one mesh, one node, one scene and one glass material.
//!
//! Layout (glTF 2.0 spec, "GLB File Format Specification"): a 12-byte header, a JSON chunk
//! padded with spaces and a BIN chunk padded with zeros, each chunk 4-byte aligned. The BIN
//! chunk holds positions, normals, texture coordinates and u32 indices back to back, one
//! tightly packed buffer view each; every element is 4 bytes, so each view stays aligned.

use crate::mesh::Mesh;
use anyhow::{Context, Result, ensure};
use glam::Vec3;
use serde_json::{Value, json};
use std::path::Path;

/// "glTF" read as a little-endian u32.
pub const MAGIC: u32 = 0x4654_6C67;
/// Container version written in the header.
pub const VERSION: u32 = 2;
/// Chunk type of the JSON chunk ("JSON").
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk ("BIN\0").
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// glTF component type for 32-bit floats.
const FLOAT: u32 = 5126;
/// glTF component type for 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// Buffer view target for vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// Buffer view target for indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Primitive mode for triangle lists.
const TRIANGLES: u32 = 4;

/// Clear, smooth, fully transmissive dielectric: white base colour, metallic 0,
/// roughness 0.05, `KHR_materials_transmission` 1.0 and `KHR_materials_ior`.
#[derive(Debug, Clone, PartialEq)]
pub struct GlassMaterial {
    /// Material name in the file.
    pub name: String,
    /// Index of refraction (glass 1.51, diamond 2.42).
    pub ior: f32,
}

/// A float as JSON in its shortest decimal form that reads back as the same `f32`.
fn json_f32(value: f32) -> Value {
    let shortest: f64 = value.to_string().parse().expect("f32 prints as a number");
    json!(shortest)
}

/// A vector as a JSON array of three shortest-form floats.
fn vec3_json(v: Vec3) -> Value {
    Value::Array(v.to_array().into_iter().map(json_f32).collect())
}

/// Floats as little-endian bytes, the only byte order glTF allows.
fn le_bytes(values: impl Iterator<Item = f32>) -> Vec<u8> {
    values.flat_map(f32::to_le_bytes).collect()
}

/// Pads a chunk to the 4-byte boundary the GLB container requires.
fn pad_to_4(bytes: &mut Vec<u8>, fill: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(fill);
    }
}

/// Encodes `mesh` as a complete .glb file named `name` with `material`.
pub fn encode(mesh: &Mesh, name: &str, material: &GlassMaterial) -> Result<Vec<u8>> {
    let vertex_count = mesh.vertex_count();
    ensure!(vertex_count > 0, "mesh {name} has no vertices");
    ensure!(
        mesh.normals.len() == vertex_count && mesh.uvs.len() == vertex_count,
        "mesh {name}: attribute counts differ"
    );
    ensure!(
        mesh.indices.len().is_multiple_of(3),
        "mesh {name}: index count not a multiple of 3"
    );
    ensure!(
        mesh.indices.iter().all(|&i| (i as usize) < vertex_count),
        "mesh {name}: index out of range"
    );
    ensure!(
        material.ior >= 1.0,
        "ior must be at least 1, got {}",
        material.ior
    );

    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut add_view = |bytes: Vec<u8>, target: u32| {
        views.push(json!({
            "buffer": 0,
            "byteOffset": bin.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        bin.extend_from_slice(&bytes);
        views.len() - 1
    };
    let positions = add_view(
        le_bytes(mesh.positions.iter().flat_map(|p| p.to_array())),
        ARRAY_BUFFER,
    );
    let normals = add_view(
        le_bytes(mesh.normals.iter().flat_map(|n| n.to_array())),
        ARRAY_BUFFER,
    );
    let uvs = add_view(
        le_bytes(mesh.uvs.iter().flat_map(|t| t.to_array())),
        ARRAY_BUFFER,
    );
    let indices = add_view(
        mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
        ELEMENT_ARRAY_BUFFER,
    );
    pad_to_4(&mut bin, 0);

    let (min, max) = mesh.bounds();
    let document = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("vitreous-meshgen ", env!("CARGO_PKG_VERSION")),
        },
        "extensionsUsed": ["KHR_materials_ior", "KHR_materials_transmission"],
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": name, "mesh": 0 }],
        "meshes": [{
            "name": name,
            "primitives": [{
                "attributes": { "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2 },
                "indices": 3,
                "material": 0,
                "mode": TRIANGLES,
            }],
        }],
        "materials": [{
            "name": material.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": json_f32(0.05),
            },
            "extensions": {
                "KHR_materials_ior": { "ior": json_f32(material.ior) },
                "KHR_materials_transmission": { "transmissionFactor": 1.0 },
            },
        }],
        "accessors": [
            {
                "bufferView": positions, "componentType": FLOAT, "count": vertex_count,
                "type": "VEC3", "min": vec3_json(min), "max": vec3_json(max),
            },
            { "bufferView": normals, "componentType": FLOAT, "count": vertex_count, "type": "VEC3" },
            { "bufferView": uvs, "componentType": FLOAT, "count": vertex_count, "type": "VEC2" },
            {
                "bufferView": indices, "componentType": UNSIGNED_INT,
                "count": mesh.indices.len(), "type": "SCALAR",
            },
        ],
        "bufferViews": views,
        "buffers": [{ "byteLength": bin.len() }],
    });
    let mut json_chunk = serde_json::to_vec(&document).context("serialising glTF JSON")?;
    pad_to_4(&mut json_chunk, b' ');

    let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
    let total = u32::try_from(total).context("glb larger than 4 GiB")?;
    let mut out = Vec::with_capacity(total as usize);
    for word in [MAGIC, VERSION, total] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    for (kind, chunk) in [(CHUNK_JSON, &json_chunk), (CHUNK_BIN, &bin)] {
        out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(chunk);
    }
    Ok(out)
}

/// Encodes `mesh` and writes it to `path`, creating the parent folder; returns the byte count.
pub fn write(path: &Path, mesh: &Mesh, name: &str, material: &GlassMaterial) -> Result<usize> {
    let bytes = encode(mesh, name, material)?;
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating folder {}", parent.display()))?;
    }
    // Beside the target, renamed into place once whole: an interrupted run leaves the old
    // model or a `.partial` file, never a truncated model under the shipped name.
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    let partial = std::path::PathBuf::from(partial);
    std::fs::write(&partial, &bytes).with_context(|| format!("writing {}", partial.display()))?;
    std::fs::rename(&partial, path).with_context(|| format!("writing {}", path.display()))?;
    Ok(bytes.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{diamond, goblet, sphere, torus};
    use glam::Vec2;

    /// Minimal .glb reader: checks the container and returns the JSON and the BIN chunk.
    fn parse(bytes: &[u8]) -> (Value, &[u8]) {
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        assert_eq!(word(0), MAGIC);
        assert_eq!(word(4), 2);
        assert_eq!(word(8) as usize, bytes.len());
        let json_len = word(12) as usize;
        assert_eq!(word(16), CHUNK_JSON);
        assert_eq!(json_len % 4, 0);
        let json_bytes = &bytes[20..20 + json_len];
        let bin_at = 20 + json_len;
        let bin_len = word(bin_at) as usize;
        assert_eq!(word(bin_at + 4), CHUNK_BIN);
        assert_eq!(bin_len % 4, 0);
        assert_eq!(bin_at + 8 + bin_len, bytes.len());
        let json = serde_json::from_slice(json_bytes).expect("JSON chunk parses");
        (json, &bytes[bin_at + 8..])
    }

    /// Reads accessor `index` as raw 4-byte little-endian words.
    fn accessor_words(json: &Value, bin: &[u8], index: usize) -> Vec<[u8; 4]> {
        let accessor = &json["accessors"][index];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        let length = view["byteLength"].as_u64().unwrap() as usize;
        let components = match accessor["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            other => panic!("unexpected accessor type {other}"),
        };
        let count = accessor["count"].as_u64().unwrap() as usize;
        assert_eq!(offset % 4, 0);
        assert_eq!(length, count * components * 4);
        bin[offset..offset + length]
            .chunks_exact(4)
            .map(|w| w.try_into().unwrap())
            .collect()
    }

    fn floats(words: &[[u8; 4]]) -> Vec<f32> {
        words.iter().map(|&w| f32::from_le_bytes(w)).collect()
    }

    fn glass(ior: f32) -> GlassMaterial {
        GlassMaterial {
            name: "glass".into(),
            ior,
        }
    }

    fn round_trip(mesh: &Mesh, ior: f32) {
        let bytes = encode(mesh, "shape", &glass(ior)).unwrap();
        let (json, bin) = parse(&bytes);
        assert_eq!(json["asset"]["version"], "2.0");
        assert_eq!(
            json["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
            bin.len()
        );
        let used: Vec<&str> = json["extensionsUsed"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        assert!(used.contains(&"KHR_materials_ior"));
        assert!(used.contains(&"KHR_materials_transmission"));
        let material = &json["materials"][0];
        assert_eq!(
            material["extensions"]["KHR_materials_ior"]["ior"]
                .as_f64()
                .unwrap() as f32,
            ior
        );
        assert_eq!(
            material["extensions"]["KHR_materials_transmission"]["transmissionFactor"],
            1.0
        );
        let pbr = &material["pbrMetallicRoughness"];
        assert_eq!(pbr["baseColorFactor"], json!([1.0, 1.0, 1.0, 1.0]));
        assert_eq!(pbr["metallicFactor"], 0.0);
        assert_eq!(pbr["roughnessFactor"].as_f64().unwrap() as f32, 0.05);
        assert_eq!(json["nodes"].as_array().unwrap().len(), 1);
        assert_eq!(json["scenes"][0]["nodes"], json!([0]));

        let primitive = &json["meshes"][0]["primitives"][0];
        let attribute = |name: &str| primitive["attributes"][name].as_u64().unwrap() as usize;
        let positions: Vec<Vec3> = floats(&accessor_words(&json, bin, attribute("POSITION")))
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        let normals: Vec<Vec3> = floats(&accessor_words(&json, bin, attribute("NORMAL")))
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        let uvs: Vec<Vec2> = floats(&accessor_words(&json, bin, attribute("TEXCOORD_0")))
            .chunks_exact(2)
            .map(Vec2::from_slice)
            .collect();
        let index_accessor = primitive["indices"].as_u64().unwrap() as usize;
        assert_eq!(
            json["accessors"][index_accessor]["componentType"],
            UNSIGNED_INT
        );
        let indices: Vec<u32> = accessor_words(&json, bin, index_accessor)
            .into_iter()
            .map(u32::from_le_bytes)
            .collect();
        let read = Mesh {
            positions,
            normals,
            uvs,
            indices,
        };
        assert_eq!(&read, mesh);

        let accessor = &json["accessors"][attribute("POSITION")];
        let bound = |key: &str| {
            let v: Vec<f32> = accessor[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect();
            Vec3::from_slice(&v)
        };
        let (min, max) = mesh.bounds();
        assert_eq!((bound("min"), bound("max")), (min, max));

        for view in json["bufferViews"].as_array().unwrap() {
            let target = view["target"].as_u64().unwrap() as u32;
            assert!(target == ARRAY_BUFFER || target == ELEMENT_ARRAY_BUFFER);
        }
        assert_eq!(
            json["bufferViews"][json["accessors"][index_accessor]["bufferView"]
                .as_u64()
                .unwrap() as usize]["target"],
            ELEMENT_ARRAY_BUFFER
        );
    }

    #[test]
    fn sphere_glb_reads_back_identically() {
        round_trip(&sphere::mesh(96, 48).unwrap(), 1.51);
    }

    #[test]
    fn diamond_glb_reads_back_identically() {
        round_trip(
            &diamond::mesh(&diamond::Proportions::default()).unwrap(),
            2.42,
        );
    }

    #[test]
    fn torus_glb_reads_back_identically() {
        round_trip(
            &torus::mesh(torus::DEFAULT_MINOR_RADIUS, 96, 48).unwrap(),
            1.51,
        );
    }

    #[test]
    fn goblet_glb_reads_back_identically() {
        round_trip(
            &goblet::mesh(&goblet::Proportions::default(), goblet::DEFAULT_SEGMENTS).unwrap(),
            1.5,
        );
    }

    #[test]
    fn odd_sized_json_is_padded_with_spaces() {
        let mesh = sphere::mesh(3, 2).unwrap();
        for name in ["a", "ab", "abc", "abcd"] {
            let bytes = encode(&mesh, name, &glass(1.5)).unwrap();
            let (json, _) = parse(&bytes);
            assert_eq!(json["meshes"][0]["name"], name);
            let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            let chunk = &bytes[20..20 + json_len];
            let end = chunk.iter().rposition(|&b| b == b'}').unwrap();
            assert!(chunk[end + 1..].iter().all(|&b| b == b' '));
        }
    }

    #[test]
    fn shortest_float_text_reads_back_as_the_same_f32() {
        for x in [0.05f32, 0.5, -0.35, 1.51, 2.42, 0.123_456_79] {
            assert_eq!(json_f32(x).as_f64().unwrap() as f32, x);
        }
    }
}
