//! glTF 2.0 (`.gltf` + buffers, or `.glb`) to one flat triangle mesh, checking every
//! accessor against its buffer so that broken files become errors, not panics.
//!
//! Over 600 lines only with its tests (about 500 without): the reading and the checks of one
//! file format belong together.

use std::collections::HashSet;
use std::path::Path;

use super::accessor::{read_floats, read_indices};
use glam::{Mat3, Mat4, Vec2, Vec3};

/// A triangle mesh in model units: every triangle primitive of every mesh node of the
/// glTF scene, node transforms applied, flattened into one vertex/index list.
#[derive(Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, model units (metres by glTF convention before scene scaling).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals; flat (per-face) where the file has none.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (`TEXCOORD_0`), zero where the file has none.
    pub uvs: Vec<Vec2>,
    /// Triangle list, counter-clockwise front faces, three indices per triangle, each less
    /// than `positions.len()`.
    pub indices: Vec<u32>,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (lo, hi) = self.bounds();
        f.debug_struct("Mesh")
            .field("vertices", &self.positions.len())
            .field("triangles", &self.triangle_count())
            .field("bounds", &(lo, hi))
            .finish()
    }
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Axis-aligned bounds `(min, max)` of the positions (zero for an empty mesh).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.positions.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }
}

/// A loaded model: the mesh, the first KHR_materials_ior and KHR_materials_volume found, and
/// the buffer bytes (for the scene hash).
pub(crate) struct LoadedModel {
    pub mesh: Mesh,
    pub ior: Option<f32>,
    pub volume: Option<VolumeAttenuation>,
    pub buffers: Vec<Vec<u8>>,
}

/// A material's `KHR_materials_volume` attenuation, checked: white light travelling
/// `distance` inside turns into `color`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VolumeAttenuation {
    /// `attenuationColor`: linear RGB, each in 0..=1.
    pub color: Vec3,
    /// `attenuationDistance`: model units after the node transforms (glTF's metres), > 0;
    /// infinite (the extension's default) absorbs nothing.
    pub distance: f32,
}

/// Largest vertex coordinate accepted, model units: far beyond any real model in metres,
/// millimetres or inches, and small enough that extents and centres stay finite in f32.
const MAX_MODEL_COORD: f32 = 1.0e6;
/// Deepest node hierarchy accepted.
const MAX_NODE_DEPTH: usize = 64;
/// Most node visits accepted (a node shared by several parents is visited once per path).
const MAX_NODE_VISITS: usize = 100_000;

/// Loads a glTF or GLB file's bytes into one checked [`Mesh`] and the first
/// `KHR_materials_ior` found; external buffers are read relative to `base`. The error names
/// what is wrong with the file (no panic on any input).
pub fn load_mesh(bytes: &[u8], base: &Path) -> Result<(Mesh, Option<f32>), String> {
    load_gltf(bytes, base).map(|model| (model.mesh, model.ior))
}

/// Loads a glTF or GLB file's bytes; external buffers are read relative to `base`.
pub(crate) fn load_gltf(bytes: &[u8], base: &Path) -> Result<LoadedModel, String> {
    // Third-party decoders must not take the process down on hostile input; our own checks
    // below are meant to make this unreachable.
    std::panic::catch_unwind(|| load_gltf_inner(bytes, base))
        .unwrap_or_else(|_| Err("the glTF decoder failed on this file (internal panic)".into()))
}

fn load_gltf_inner(bytes: &[u8], base: &Path) -> Result<LoadedModel, String> {
    let invalid = |e: gltf::Error| {
        let e = e.to_string();
        if e.starts_with("invalid glTF") {
            e
        } else {
            format!("invalid glTF: {e}")
        }
    };
    check_glb_length(bytes)?;
    let gltf::Gltf { document, mut blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    // gltf-json's own validation indexes the POSITION accessor before checking that it
    // exists, so that is checked first.
    check_position_accessors(document.as_json())?;
    check_buffer_uris(document.as_json())?;
    let document = gltf::Document::from_json(document.into_json()).map_err(invalid)?;

    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let name = match buffer.source() {
            gltf::buffer::Source::Bin => "GLB binary chunk".to_owned(),
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => "data URI".to_owned(),
            gltf::buffer::Source::Uri(uri) => uri.to_owned(),
        };
        let data = gltf::buffer::Data::from_source_and_blob(buffer.source(), Some(base), &mut blob)
            .map_err(|e| format!("buffer {} ({name}): {}", buffer.index(), describe(&e)))?;
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} ({name}): holds {} bytes, the file declares {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data.0);
    }

    let roots: Vec<gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            let children: HashSet<usize> = document
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()))
                .collect();
            document
                .nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };

    let mut out = Builder {
        buffers: &buffers,
        mesh: Mesh::default(),
        ior: None,
        volume: None,
        visits: 0,
    };
    let mut ancestors = Vec::new();
    for root in roots {
        out.visit(root, Mat4::IDENTITY, &mut ancestors)?;
    }
    if out.mesh.indices.is_empty() {
        return Err("the scene has no triangles (no mesh nodes, or only empty meshes)".into());
    }
    Ok(LoadedModel {
        mesh: out.mesh,
        ior: out.ior,
        volume: out.volume,
        buffers,
    })
}

/// Size of the GLB file header: magic, version, total length.
const GLB_HEADER_LEN: u32 = 12;

/// A GLB's declared total length covers at least its header (the gltf crate subtracts the
/// header size from it unchecked).
fn check_glb_length(bytes: &[u8]) -> Result<(), String> {
    let declared = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes);
    match declared {
        Some(length) if length < GLB_HEADER_LEN => Err(format!(
            "invalid glTF: the GLB header declares a total length of {length} bytes, less than \
             the {GLB_HEADER_LEN}-byte header itself"
        )),
        _ => Ok(()),
    }
}

/// Every relative buffer URI percent-decodes to UTF-8 text (the gltf crate unwraps that
/// decoding).
fn check_buffer_uris(root: &gltf::json::Root) -> Result<(), String> {
    for (i, buffer) in root.buffers.iter().enumerate() {
        let Some(uri) = buffer.uri.as_deref() else {
            continue;
        };
        if uri.contains(':') {
            continue; // data: and file: URIs are not percent-decoded
        }
        if std::str::from_utf8(&percent_decode(uri)).is_err() {
            return Err(format!(
                "invalid glTF: buffers[{i}].uri: its percent-escapes decode to bytes that are not \
                 UTF-8 text"
            ));
        }
    }
    Ok(())
}

/// `%XX` escapes replaced by their bytes; anything else kept as it is.
fn percent_decode(text: &str) -> Vec<u8> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    out
}

/// Every primitive's POSITION attribute names an accessor that exists.
fn check_position_accessors(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::Checked;

    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions))
                && index.value() >= root.accessors.len()
            {
                return Err(format!(
                    "invalid glTF: meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} \
                     does not exist (the file has {})",
                    index.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// The checked `KHR_materials_volume` attenuation of `material`, if it has the extension
/// (its `thicknessFactor` is not used: the renderer follows the ray through the mesh itself).
fn volume_attenuation(material: &gltf::Material) -> Result<Option<VolumeAttenuation>, String> {
    let Some(volume) = material.volume() else {
        return Ok(None);
    };
    let field = |name: &str| {
        format!(
            "materials[{}].extensions.KHR_materials_volume.{name}",
            material.index().map_or("default".into(), |i| i.to_string())
        )
    };
    let distance = volume.attenuation_distance();
    if distance.is_nan() || distance <= 0.0 {
        return Err(format!(
            "{}: expected a distance > 0 (model units), found {distance}",
            field("attenuationDistance")
        ));
    }
    let color = Vec3::from_array(volume.attenuation_color());
    if !color.cmpge(Vec3::ZERO).all() || !color.cmple(Vec3::ONE).all() {
        return Err(format!(
            "{}: expected linear RGB components in 0..=1, found {color}",
            field("attenuationColor")
        ));
    }
    Ok(Some(VolumeAttenuation { color, distance }))
}

fn describe(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Io(io) if io.kind() == std::io::ErrorKind::NotFound => {
            "file not found".to_owned()
        }
        other => other.to_string(),
    }
}

struct Builder<'a> {
    buffers: &'a [Vec<u8>],
    mesh: Mesh,
    ior: Option<f32>,
    volume: Option<VolumeAttenuation>,
    visits: usize,
}

impl Builder<'_> {
    fn visit(
        &mut self,
        node: gltf::Node,
        parent: Mat4,
        ancestors: &mut Vec<usize>,
    ) -> Result<(), String> {
        if ancestors.contains(&node.index()) {
            return Err(format!(
                "node {} is its own ancestor (recursive node hierarchy)",
                node.index()
            ));
        }
        if ancestors.len() >= MAX_NODE_DEPTH {
            return Err(format!(
                "node hierarchy deeper than {MAX_NODE_DEPTH} levels"
            ));
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            return Err(format!("more than {MAX_NODE_VISITS} node visits"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!("node {}: transform is not finite", node.index()));
        }
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                let label = format!(
                    "mesh {}{} primitive {}",
                    mesh.index(),
                    mesh.name().map(|n| format!(" '{n}'")).unwrap_or_default(),
                    primitive.index()
                );
                self.add_primitive(&primitive, world)
                    .map_err(|e| format!("{label}: {e}"))?;
            }
        }
        ancestors.push(node.index());
        for child in node.children() {
            self.visit(child, world, ancestors)?;
        }
        ancestors.pop();
        Ok(())
    }

    fn add_primitive(&mut self, primitive: &gltf::Primitive, world: Mat4) -> Result<(), String> {
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            return Err(format!(
                "mode {:?} is not supported; only triangle lists (mode 4) are",
                primitive.mode()
            ));
        }
        if self.ior.is_none() {
            self.ior = primitive.material().ior();
        }
        if self.volume.is_none() {
            self.volume = volume_attenuation(&primitive.material())?;
        }
        let position_acc = primitive
            .get(&gltf::Semantic::Positions)
            .ok_or("has no POSITION attribute")?;
        let positions = read_floats::<3>(&position_acc, self.buffers, false)
            .map_err(|e| format!("POSITION: {e}"))?;
        let count = positions.len();
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(acc) => Some(
                read_floats::<3>(&acc, self.buffers, false).map_err(|e| format!("NORMAL: {e}"))?,
            ),
            None => None,
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(acc) => Some(
                read_floats::<2>(&acc, self.buffers, true)
                    .map_err(|e| format!("TEXCOORD_0: {e}"))?,
            ),
            None => None,
        };
        for (name, len) in [
            ("NORMAL", normals.as_ref().map(Vec::len)),
            ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len
                && len != count
            {
                return Err(format!(
                    "{name} has {len} elements but POSITION has {count}"
                ));
            }
        }
        let indices: Vec<u32> = match primitive.indices() {
            Some(acc) => read_indices(&acc, self.buffers).map_err(|e| format!("indices: {e}"))?,
            None => (0..u32::try_from(count).map_err(|_| "too many vertices")?).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            return Err(format!(
                "{} indices is not a whole number of triangles",
                indices.len()
            ));
        }
        if let Some((i, &bad)) = indices
            .iter()
            .enumerate()
            .find(|&(_, &v)| v as usize >= count)
        {
            return Err(format!(
                "index {i} is {bad}, out of range for {count} vertices"
            ));
        }

        let normal_matrix = Mat3::from_mat4(world);
        let det = normal_matrix.determinant();
        if !det.is_finite() {
            return Err(format!(
                "node transform overflows (scale determinant {det})"
            ));
        }
        if det.abs() < 1e-12 {
            return Err("node transform is singular (zero scale)".into());
        }
        let normal_matrix = normal_matrix.inverse().transpose();
        let flip = det < 0.0;

        let base = self.mesh.positions.len();
        let world_positions: Vec<Vec3> = positions
            .iter()
            .map(|p| world.transform_point3(Vec3::from_array(*p)))
            .collect();
        if let Some(p) = world_positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("transformed position {p} is not finite"));
        }
        if let Some((i, p)) = world_positions
            .iter()
            .enumerate()
            .find(|(_, p)| p.abs().max_element() > MAX_MODEL_COORD)
        {
            return Err(format!(
                "vertex {i} is at {p} (after node transforms), outside the ±{MAX_MODEL_COORD:e} \
                 model units accepted"
            ));
        }
        let uv_at = |i: usize| uvs.as_ref().map_or(Vec2::ZERO, |u| Vec2::from_array(u[i]));

        match &normals {
            Some(normals) => {
                self.mesh.positions.extend_from_slice(&world_positions);
                self.mesh.normals.extend(
                    normals
                        .iter()
                        .map(|n| (normal_matrix * Vec3::from_array(*n)).normalize_or_zero()),
                );
                self.mesh.uvs.extend((0..count).map(uv_at));
                for tri in indices.chunks_exact(3) {
                    let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize + base);
                    let (b, c) = if flip { (c, b) } else { (b, c) };
                    self.mesh.indices.extend(
                        [a, b, c]
                            .into_iter()
                            .map(|i| u32::try_from(i).map_err(|_| "too many vertices"))
                            .collect::<Result<Vec<_>, _>>()?,
                    );
                }
            }
            None => {
                // No normals: one vertex per triangle corner so each face gets its own normal.
                for tri in indices.chunks_exact(3) {
                    let mut corners = [tri[0], tri[1], tri[2]].map(|i| i as usize);
                    if flip {
                        corners.swap(1, 2);
                    }
                    let [pa, pb, pc] = corners.map(|i| world_positions[i]);
                    let normal = (pb - pa).cross(pc - pa).normalize_or_zero();
                    for i in corners {
                        let index = u32::try_from(self.mesh.positions.len())
                            .map_err(|_| "too many vertices")?;
                        self.mesh.positions.push(world_positions[i]);
                        self.mesh.normals.push(normal);
                        self.mesh.uvs.push(uv_at(i));
                        self.mesh.indices.push(index);
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
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
}
