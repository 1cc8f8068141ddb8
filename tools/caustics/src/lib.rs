//! vitreous-caustics: bakes the caustics a virtual glass object would throw onto the real
//! floor (paper Sec. 3.1.2, eq. 6; `docs/caustics.md`).
//!
//! The bake is a light-wavefront (beam) tracer. A regular grid of rays covers the cone from
//! the point light that just contains the object's bounding sphere, with cells of equal solid
//! angle. Every grid ray is traced through the triangle mesh with deterministic Fresnel
//! splitting (both the reflected and the refracted branch, weighted by the exact unpolarised
//! reflectance; total internal reflection keeps one branch), up to an interaction limit.
//! Each grid triangle then carries its flux to the floor along every light path that all
//! three of its corner rays share (same reflect/refract sequence through the same smooth
//! patches), spread evenly over the floor triangle the three rays land on. Flux that the
//! corners do not share lands at the corners. Irradiance is flux per texel area, so focusing
//! (tiny floor triangles) needs no division by a vanishing area and has no noise floor.
//!
//! The stored quantity is the relative caustic gain G = max(0, E_with / E_without - 1) per
//! floor texel, where E_with = E_without - E_blocked + E_through (see [`gain`]). Then eq. 6's
//! corrected caustics are L'_c = max(0, L_c - L_r) = G * L_r for a Lambertian floor with
//! recorded luminance L_r.
//!
//! Accumulation is in 64-bit fixed point with atomic adds, which commute, so a bake is
//! bit-identical for a given input whatever the thread count or scheduling.
//!
//! The closed-mesh tracer (`vitreous_optics::solid` and its BVH) and the interface optics
//! (Snell, mirror reflection, the exact Fresnel reflectance) are `vitreous-optics`', shared with
//! the two-surface refraction reference.
//!
//! [`command`] is `vitreous bake SCENE` (and this crate's own `vitreous-caustics bake`): the
//! options, the default output, progress, the printed figures and the self-check.

pub mod bake;
pub mod bake_file;
pub mod command;
pub mod emission;
mod splat;
mod trace;

use std::path::PathBuf;

use glam::{Mat4, Vec3};
use thiserror::Error;
use vitreous_optics::solid::SolidError;

pub use bake::{BakeOutput, BakeParams, Comparison, FluxLedger, bake, compare, gain};
pub use bake_file::{
    Bake, BakeError, MAX_BAKE_SIDE_PX, decode_bake, read_bake, read_bake_unchecked, write_bake,
};

/// Everything the baker needs from a scene, as plain data in world coordinates.
#[derive(Clone, Debug)]
pub struct CausticScene {
    /// Vertex positions, world metres.
    pub positions_m: Vec<Vec3>,
    /// Unit vertex normals, world (same length as `positions_m`; empty for flat shading).
    pub normals: Vec<Vec3>,
    /// Triangle list, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
    /// Refractive index of the object relative to air.
    pub ior: f32,
    /// Point light position, world metres.
    pub light_position_m: Vec3,
    /// Floor: maps the unit square `[-0.5, 0.5]^2` (z = 0, local +y = photo top) onto the
    /// floor in the world; its local +z side is the visible side.
    pub world_from_floor: Mat4,
    /// The hash of the inputs above ([`vitreous_scene::Scene::caustic_inputs_hash`]), stored
    /// in the bake.
    pub inputs_hash: String,
    /// Where the scene came from, for messages.
    pub source: PathBuf,
}

impl CausticScene {
    /// Takes the object (mesh placed in the world), light and floor from a loaded scene.
    pub fn from_scene(scene: &vitreous_scene::Scene) -> Self {
        let m = scene.object.world_from_model;
        let normal_matrix = glam::Mat3::from_mat4(m).inverse().transpose();
        let mesh = &scene.object.mesh;
        CausticScene {
            positions_m: mesh
                .positions
                .iter()
                .map(|&p| m.transform_point3(p))
                .collect(),
            normals: mesh
                .normals
                .iter()
                .map(|&n| (normal_matrix * n).normalize_or_zero())
                .collect(),
            indices: mesh.indices.clone(),
            ior: scene.object.ior,
            light_position_m: scene.light.position_m,
            world_from_floor: scene.floor.world_from_plane(),
            inputs_hash: scene.caustic_inputs_hash(),
            source: scene.path.clone(),
        }
    }
}

/// Why a scene cannot be baked.
#[derive(Debug, Error)]
pub enum InputError {
    /// The mesh is not a closed solid (the caustics trace light through its volume).
    #[error(transparent)]
    Mesh(#[from] SolidError),
    /// The light is inside the glass.
    #[error(
        "the light at {light_m} m (world) is inside the object; a caustic bake needs the light \
         outside the glass"
    )]
    LightInsideObject {
        /// Light position, world metres.
        light_m: Vec3,
    },
    /// The floor has no area.
    #[error("the floor has zero area ({area_m2} m^2); give it a positive width and height")]
    ZeroAreaFloor {
        /// Area of the floor rectangle, square metres.
        area_m2: f32,
    },
    /// The light does not light the visible side of the floor.
    #[error(
        "the light is {height_m} m from the floor's visible side; it must be above it \
         (positive), or the floor receives no direct light to compare with"
    )]
    LightBelowFloor {
        /// Signed distance of the light from the floor plane along its normal, metres.
        height_m: f32,
    },
    /// A number is out of range.
    #[error("{0}")]
    BadValue(String),
}
