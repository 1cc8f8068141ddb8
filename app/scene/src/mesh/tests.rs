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

/// The pieces of a glTF buffer: each view's bytes, 4-byte aligned, and accessors over them.
#[derive(Default)]
struct BufferBuilder {
    bytes: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl BufferBuilder {
    /// Adds float vectors of `kind` (`VEC3`) as a view and an accessor; returns the accessor.
    fn floats(&mut self, kind: &str, values: &[f32], extra: &str) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let components = if kind == "VEC3" { 3 } else { 1 };
        self.accessor(&bytes, 5126, kind, values.len() / components, extra)
    }

    /// Adds u16 indices as a view and an accessor; returns the accessor.
    fn indices(&mut self, values: &[u16]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, 5123, "SCALAR", values.len(), "")
    }

    fn accessor(
        &mut self,
        bytes: &[u8],
        component: u32,
        kind: &str,
        count: usize,
        extra: &str,
    ) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(bytes);
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{}}}"#,
            bytes.len()
        ));
        self.accessors.push(format!(
            r#"{{"bufferView":{},"componentType":{component},"count":{count},"type":"{kind}"{extra}}}"#,
            self.views.len() - 1
        ));
        self.accessors.len() - 1
    }

    /// `"buffers"`, `"bufferViews"` and `"accessors"` as JSON members.
    fn json(&self) -> String {
        format!(
            r#""buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
            "bufferViews":[{}],"accessors":[{}]"#,
            self.bytes.len(),
            base64_encode(&self.bytes),
            self.views.join(","),
            self.accessors.join(",")
        )
    }
}

/// A model laid out as Blender's glTF exporter writes one: a parent node (turned and moved)
/// over two mesh nodes (one scaled unevenly, one turned and scaled), a mesh of two primitives
/// with their own materials, and a non-indexed primitive; `metal` is the second material's
/// JSON. The glass material carries transmission, volume and IOR.
fn blender_like_gltf(metal: &str) -> String {
    let mut b = BufferBuilder::default();
    let n = std::f32::consts::FRAC_1_SQRT_2;
    // A triangle in the plane x + y = 1, its normals along (1, 1, 0).
    let bowl_positions = b.floats(
        "VEC3",
        &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0],
        r#","min":[0,0,0],"max":[1,1,1]"#,
    );
    let bowl_normals = b.floats("VEC3", &[n, n, 0.0, n, n, 0.0, n, n, 0.0], "");
    let bowl_indices = b.indices(&[0, 1, 2]);
    // Two triangles without indices (a quad in the z = 0 plane facing +z).
    let stem_positions = b.floats(
        "VEC3",
        &[
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0,
            0.0,
        ],
        r#","min":[0,0,0],"max":[1,1,0]"#,
    );
    let stem_normals = b.floats("VEC3", &[0.0, 0.0, 1.0].repeat(6), "");
    format!(
        r#"{{"asset":{{"version":"2.0","generator":"Khronos glTF Blender I/O"}},
        "extensionsUsed":["KHR_materials_transmission","KHR_materials_volume","KHR_materials_ior"],
        "scene":0,"scenes":[{{"name":"Scene","nodes":[0]}}],
        "nodes":[
          {{"name":"Goblet","children":[1,2],"translation":[0,0.5,0],
            "rotation":[0,{n},0,{n}]}},
          {{"name":"Bowl","mesh":0,"translation":[1,0,0],"scale":[2,1,0.5]}},
          {{"name":"Stem","mesh":1,"translation":[0,-1,0],"rotation":[1,0,0,0],
            "scale":[0.5,0.5,0.5]}}],
        "materials":[
          {{"name":"Glass","extensions":{{
            "KHR_materials_transmission":{{"transmissionFactor":1}},
            "KHR_materials_volume":{{"thicknessFactor":0.02,"attenuationDistance":0.5,
              "attenuationColor":[0.8,0.9,1.0]}},
            "KHR_materials_ior":{{"ior":1.45}}}}}},
          {metal}],
        "meshes":[
          {{"name":"Bowl","primitives":[
            {{"attributes":{{"POSITION":{bowl_positions},"NORMAL":{bowl_normals}}},
              "indices":{bowl_indices},"material":0}},
            {{"attributes":{{"POSITION":{bowl_positions},"NORMAL":{bowl_normals}}},
              "indices":{bowl_indices},"material":1}}]}},
          {{"name":"Stem","primitives":[
            {{"attributes":{{"POSITION":{stem_positions},"NORMAL":{stem_normals}}},
              "material":0}}]}}],
        {}}}"#,
        b.json()
    )
}

#[test]
fn blender_like_hierarchy_is_merged_with_transforms_and_materials() {
    let metal = r#"{"name":"Metal","extensions":{"KHR_materials_transmission":
        {"transmissionFactor":0}}}"#;
    let model = load_gltf(blender_like_gltf(metal).as_bytes(), Path::new(".")).unwrap();
    let mesh = &model.mesh;
    // Two bowl primitives (3 vertices each) and the non-indexed stem (6): 4 triangles.
    assert_eq!(mesh.positions.len(), 12);
    assert_eq!(mesh.triangle_count(), 4);
    assert_eq!(mesh.indices, (0..12).collect::<Vec<u32>>());

    // The parent turns +x into -z (90 degrees about +y) and lifts by 0.5.
    let turn = |v: Vec3| Vec3::new(v.z, v.y, -v.x);
    let bowl = |p: Vec3| turn(p * Vec3::new(2.0, 1.0, 0.5) + Vec3::X) + Vec3::Y * 0.5;
    let stem = |p: Vec3| turn(Vec3::new(p.x, -p.y, -p.z) * 0.5 - Vec3::Y) + Vec3::Y * 0.5;
    let bowl_local = [Vec3::X, Vec3::Y, Vec3::new(1.0, 0.0, 1.0)];
    let stem_local = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::ZERO,
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::Y,
    ];
    let expected: Vec<Vec3> = bowl_local
        .iter()
        .chain(&bowl_local)
        .map(|&p| bowl(p))
        .chain(stem_local.iter().map(|&p| stem(p)))
        .collect();
    for (i, (got, want)) in mesh.positions.iter().zip(&expected).enumerate() {
        assert!(got.abs_diff_eq(*want, 1e-6), "vertex {i}: {got} != {want}");
    }

    // Normals by the inverse transpose: the plane x + y = 1 scaled by (2, 1, 0.5) is
    // x / 2 + y = 1, whose normal is (1, 2, 0) / sqrt 5 (scaling the normal itself would
    // give (2, 1, 0) / sqrt 5), then turned.
    let bowl_normal = turn(Vec3::new(1.0, 2.0, 0.0) / 5f32.sqrt());
    for (i, got) in mesh.normals[..6].iter().enumerate() {
        assert!(
            got.abs_diff_eq(bowl_normal, 1e-6),
            "vertex {i}: {got} != {bowl_normal}"
        );
    }
    // The stem's +z turns to -z about x, then to -x about y; still unit length.
    for got in &mesh.normals[6..] {
        assert!(got.abs_diff_eq(Vec3::NEG_X, 1e-6), "{got}");
    }
    // Counter-clockwise about the normal after the transforms.
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
        assert!((b - a).cross(c - a).dot(mesh.normals[t[0] as usize]) > 0.0);
    }

    assert_eq!(model.ior, Some(1.45));
    assert_eq!(
        model.volume,
        Some(VolumeAttenuation {
            color: Vec3::new(0.8, 0.9, 1.0),
            distance: 0.5,
        })
    );
    // The opaque material is drawn as glass, and the user is told which one it is.
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let warning = &model.warnings[0];
    assert!(
        warning.contains("material 1 'Metal'") && warning.contains("transmissionFactor 0"),
        "{warning}"
    );
}

#[test]
fn a_material_without_transmission_beside_glass_is_named() {
    let model = load_gltf(
        blender_like_gltf(r#"{"name":"Label"}"#).as_bytes(),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let warning = &model.warnings[0];
    assert!(
        warning.contains("material 1 'Label' has no KHR_materials_transmission")
            && warning.contains("material 0 'Glass' is glass"),
        "{warning}"
    );
    // Both glass: nothing to say. A model with no transmission at all is glass too.
    let glass = r#"{"name":"Glass.001","extensions":{"KHR_materials_transmission":
        {"transmissionFactor":0.9}}}"#;
    let model = load_gltf(blender_like_gltf(glass).as_bytes(), Path::new(".")).unwrap();
    assert_eq!(model.warnings, Vec::<String>::new());
    let plain = load_gltf(triangle_gltf("0,1,2", "").as_bytes(), Path::new(".")).unwrap();
    assert_eq!(plain.warnings, Vec::<String>::new());
}

#[test]
fn material_warnings_name_each_opaque_material_once() {
    let used = |label: &str, transmission| UsedMaterial {
        label: label.into(),
        transmission,
    };
    let warnings = material_warnings(&[
        used("material 0 'Glass'", Some(1.0)),
        used("material 1 'Cap'", Some(0.0)),
        used("material 2 'Paint'", None),
    ]);
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(warnings[0].starts_with("material 1 'Cap'"));
    assert!(warnings[1].starts_with("material 2 'Paint'"));
    // Only opaque: said once, for the material that says so.
    let warnings = material_warnings(&[used("the default material", Some(0.0))]);
    assert_eq!(warnings.len(), 1);
    assert_eq!(material_warnings(&[used("material 0", None)]).len(), 0);
}
