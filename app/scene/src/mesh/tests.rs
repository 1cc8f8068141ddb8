//! Tests of `mesh`.

use super::*;

/// A minimal glTF with one triangle in an embedded base64 buffer.
fn triangle_gltf(indices: &str, extra_node: &str) -> String {
    // Three VEC3 float positions (36 bytes) then three u16 indices (6 bytes + 2 pad).
    let mut bytes = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices.split(',').map(|s| s.trim().parse::<u16>().unwrap()) {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes.extend_from_slice(&[0, 0]);
    let b64 = base64_encode(&bytes);
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0{extra_node}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,{b64}"}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},
                       {{"buffer":0,"byteOffset":36,"byteLength":6}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                       "min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#
    )
}

fn base64_encode(bytes: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn triangle_without_normals_gets_flat_normal_and_zero_uvs() {
    let model = load_gltf(triangle_gltf("0,1,2", "").as_bytes(), Path::new(".")).unwrap();
    assert_eq!(model.mesh.triangle_count(), 1);
    assert_eq!(model.mesh.normals, vec![Vec3::Z; 3]);
    assert_eq!(model.mesh.uvs, vec![Vec2::ZERO; 3]);
    assert_eq!(model.ior, None);
}

#[test]
fn node_transform_is_applied_and_mirror_keeps_winding() {
    let gltf = triangle_gltf("0,1,2", r#","scale":[-2,2,2],"translation":[0,0,-1]"#);
    let model = load_gltf(gltf.as_bytes(), Path::new(".")).unwrap();
    let (lo, hi) = model.mesh.bounds();
    assert_eq!(lo, Vec3::new(-2.0, 0.0, -1.0));
    assert_eq!(hi, Vec3::new(0.0, 2.0, -1.0));
    // The mirrored triangle still faces +z after the winding flip.
    assert!(model.mesh.normals.iter().all(|n| *n == Vec3::Z));
}

#[test]
fn out_of_range_index_is_an_error() {
    let err = load_gltf(triangle_gltf("0,1,7", "").as_bytes(), Path::new("."))
        .err()
        .unwrap();
    assert!(err.contains("out of range for 3 vertices"), "{err}");
}

#[test]
fn vertices_far_beyond_any_model_are_refused_by_position_not_as_zero_size() {
    let gltf = triangle_gltf("0,1,2", r#","translation":[3e38,0,0]"#);
    let err = load_gltf(gltf.as_bytes(), Path::new(".")).err().unwrap();
    assert!(
        err.contains("vertex 0") && err.contains("model units"),
        "{err}"
    );
    let gltf = triangle_gltf("0,1,2", r#","scale":[3e38,3e38,3e38]"#);
    let err = load_gltf(gltf.as_bytes(), Path::new(".")).err().unwrap();
    assert!(err.contains("overflows"), "{err}");
}

#[test]
fn missing_position_accessor_is_an_error_not_a_panic() {
    let gltf = triangle_gltf("0,1,2", "").replace(r#""POSITION":0"#, r#""POSITION":7"#);
    let err = load_gltf_inner(gltf.as_bytes(), Path::new("."))
        .err()
        .unwrap();
    assert!(err.contains("POSITION: accessor 7 does not exist"), "{err}");
}

#[test]
fn glb_length_shorter_than_its_header_is_an_error_not_a_panic() {
    let mut glb = b"glTF\x02\0\0\0\x03\0\0\0".to_vec();
    glb.extend_from_slice(&[0; 16]);
    let err = load_gltf_inner(&glb, Path::new(".")).err().unwrap();
    assert!(err.contains("total length of 3 bytes"), "{err}");
}

#[test]
fn buffer_uri_escaping_to_non_utf8_is_an_error_not_a_panic() {
    let gltf = triangle_gltf("0,1,2", "").replace(
        "data:application/octet-stream;base64,",
        "data%AAapplication/octet-stream;base64,",
    );
    let err = load_gltf_inner(gltf.as_bytes(), Path::new("."))
        .err()
        .unwrap();
    assert!(err.contains("buffers[0].uri"), "{err}");
    assert_eq!(percent_decode("a%20b%zz%4"), b"a b%zz%4");
}

/// The triangle with a material carrying `KHR_materials_volume` = `volume` (JSON).
fn triangle_with_volume(volume: &str) -> String {
    triangle_gltf("0,1,2", "")
        .replace(r#""indices":1}"#, r#""indices":1,"material":0}"#)
        .replace(
            r#""buffers""#,
            &format!(
                r#""extensionsUsed":["KHR_materials_volume"],
                "materials":[{{"extensions":{{"KHR_materials_volume":{volume}}}}}],
                "buffers""#
            ),
        )
}

#[test]
fn volume_attenuation_is_read_from_the_material() {
    let gltf = triangle_with_volume(
        r#"{"thicknessFactor":0.3,"attenuationDistance":0.2,
            "attenuationColor":[0.9,0.5,0.25]}"#,
    );
    let model = load_gltf(gltf.as_bytes(), Path::new(".")).unwrap();
    assert_eq!(
        model.volume,
        Some(VolumeAttenuation {
            color: Vec3::new(0.9, 0.5, 0.25),
            distance: 0.2,
        })
    );
    // The extension's defaults: white at an infinite distance (nothing absorbed).
    let model = load_gltf(triangle_with_volume("{}").as_bytes(), Path::new(".")).unwrap();
    let volume = model.volume.unwrap();
    assert_eq!(volume.color, Vec3::ONE);
    assert_eq!(volume.distance, f32::INFINITY);
    let plain = load_gltf(triangle_gltf("0,1,2", "").as_bytes(), Path::new(".")).unwrap();
    assert_eq!(plain.volume, None);
}

#[test]
fn bad_volume_attenuation_names_the_field() {
    for (volume, field) in [
        (r#"{"attenuationDistance":0}"#, "attenuationDistance"),
        (r#"{"attenuationDistance":-0.5}"#, "attenuationDistance"),
        (
            r#"{"attenuationDistance":1,"attenuationColor":[1.5,0,0]}"#,
            "attenuationColor",
        ),
        (r#"{"attenuationColor":[0.5,-0.1,0]}"#, "attenuationColor"),
    ] {
        let err = load_gltf(triangle_with_volume(volume).as_bytes(), Path::new("."))
            .err()
            .unwrap_or_else(|| panic!("{volume} should be refused"));
        assert!(
            err.contains(&format!(
                "materials[0].extensions.KHR_materials_volume.{field}"
            )),
            "{volume}: {err}"
        );
    }
}

#[test]
fn garbage_is_an_error() {
    assert!(load_gltf(b"{not json", Path::new(".")).is_err());
    assert!(load_gltf(b"glTF\x02\0\0\0\xff\xff\xff\xff", Path::new(".")).is_err());
}
