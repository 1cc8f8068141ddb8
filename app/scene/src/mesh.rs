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

/// A loaded model: the mesh, the first KHR_materials_ior and KHR_materials_volume found, the
/// buffer bytes (for the scene hash) and what the user should know about its materials.
pub(crate) struct LoadedModel {
    pub mesh: Mesh,
    pub ior: Option<f32>,
    pub volume: Option<VolumeAttenuation>,
    pub buffers: Vec<Vec<u8>>,
    /// Materials drawn as glass although the file says they are not ([`material_warnings`]).
    pub warnings: Vec<String>,
}

/// A material a triangle primitive uses: its name for messages and its
/// `KHR_materials_transmission` factor (None without the extension).
#[derive(Clone, Debug, PartialEq)]
struct UsedMaterial {
    /// `materials[i] 'name'`, or `the default material`.
    label: String,
    /// `transmissionFactor`, when the material has the extension.
    transmission: Option<f32>,
}

/// vitreous draws the whole model as one glass object. A material that lets no light through
/// (`transmissionFactor` 0), or one without the extension in a model whose other materials
/// are glass, is a part the user meant to be opaque (a metal stem, a label): it is drawn as
/// glass all the same, and the user is told so. A model with no transmission anywhere is
/// taken as glass without a word (most exporters write none unless asked).
fn material_warnings(used: &[UsedMaterial]) -> Vec<String> {
    let glass = used
        .iter()
        .find(|m| m.transmission.is_some_and(|t| t > 0.0));
    used.iter()
        .filter_map(|m| match (m.transmission, glass) {
            (Some(t), _) if t <= 0.0 => Some(format!(
                "{} has KHR_materials_transmission transmissionFactor {t} (opaque), but the \
                 whole model is drawn as one glass object, so its triangles are glass too; give \
                 it transmission 1 (Blender: Transmission Weight 1), or leave its faces out of \
                 the model",
                m.label
            )),
            (None, Some(glass)) => Some(format!(
                "{} has no KHR_materials_transmission while {} is glass, but the whole model \
                 is drawn as one glass object, so its triangles are glass too; give it \
                 transmission 1 (Blender: Transmission Weight 1), or leave its faces out of the \
                 model",
                m.label, glass.label
            )),
            _ => None,
        })
        .collect()
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
        materials: Vec::new(),
        visits: 0,
    };
    let mut ancestors = Vec::new();
    for root in roots {
        out.visit(root, Mat4::IDENTITY, &mut ancestors)?;
    }
    if out.mesh.indices.is_empty() {
        return Err("the scene has no triangles (no mesh nodes, or only empty meshes)".into());
    }
    let warnings = material_warnings(&out.materials);
    Ok(LoadedModel {
        mesh: out.mesh,
        ior: out.ior,
        volume: out.volume,
        buffers,
        warnings,
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
    /// Every material a triangle primitive uses, once each, in the order first met.
    materials: Vec<UsedMaterial>,
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
        let material = primitive.material();
        let label = match (material.index(), material.name()) {
            (Some(i), Some(name)) => format!("material {i} '{name}'"),
            (Some(i), None) => format!("material {i}"),
            (None, _) => "the default material".to_owned(),
        };
        if !self.materials.iter().any(|m| m.label == label) {
            self.materials.push(UsedMaterial {
                label,
                transmission: material.transmission().map(|t| t.transmission_factor()),
            });
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
mod tests;
