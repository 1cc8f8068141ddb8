//! What the live caustics' photons read of the mesh on the GPU (shaders/caustics_live.wgsl),
//! built once when live caustics are enabled (the mesh never moves in model space): the grid
//! of triangle lists and the triangles as a corner and two edges ([`super::triangle_grid`]
//! builds them on the CPU), each triangle's vertex normals, the shell every surface point
//! lies in, whether the mesh bounds one convex body, and a convex flat-faceted body's facet
//! planes. Freed on drop.

use ash::vk;
use glam::Vec3;

use super::triangle_grid::{Grid, behind_every_plane, corner_and_edges, inner_radius};
use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Buffer;
use crate::scene::MeshRef;

/// The mesh's buffers and shape.
pub(super) struct LiveMesh {
    /// Per triangle its vertex normals, the grid's cells, their triangles, and per triangle
    /// its corner and edges: the trace's bindings 1, 2, 3 and 8.
    pub buffers: [Buffer; 4],
    /// The facet planes of a convex flat-faceted mesh
    /// ([`vitreous_optics::convex::facet_planes`]; one unused entry for any other mesh):
    /// binding 13.
    pub facets: Buffer,
    /// The grid's placement, model units.
    pub grid_origin: Vec3,
    /// Its cell side.
    pub grid_side: f32,
    /// Its cells per axis.
    pub grid_dims: [u32; 3],
    /// Centre of the mesh's bounding box, model units.
    pub center: Vec3,
    /// Largest distance of a vertex from it, model units.
    pub radius: f32,
    /// Smallest distance from it to a triangle's plane, model units: no surface point lies
    /// nearer the centre.
    pub inner_radius: f32,
    /// Whether the mesh bounds one convex body ([`vitreous_optics::convex::is_convex`]): a photon
    /// leaving it outward then meets no more of it.
    pub convex: bool,
    /// Whether, besides, the shell's inner ball lies inside that body
    /// ([`behind_every_plane`]): a photon inside it then meets no surface before it has
    /// passed the ball.
    pub inner_ball_inside: bool,
    /// How many facet planes a ray inside the body is tested against instead of walking the
    /// grid (0: it walks the grid).
    pub facet_count: u32,
}

impl LiveMesh {
    /// The buffers and shape of `mesh` (model units, outward normals, closed), which bounds
    /// one convex body when `convex` ([`vitreous_optics::convex::is_convex`]).
    pub fn new(ctx: &GpuContext, mesh: &MeshRef, convex: bool) -> Result<LiveMesh> {
        let grid = Grid::new(mesh.positions, mesh.indices);
        let lo = mesh
            .positions
            .iter()
            .copied()
            .fold(Vec3::INFINITY, Vec3::min);
        let hi = mesh
            .positions
            .iter()
            .copied()
            .fold(Vec3::NEG_INFINITY, Vec3::max);
        let model_center = (lo + hi) / 2.0;
        let model_radius = mesh
            .positions
            .iter()
            .map(|p| p.distance(model_center))
            .fold(0.0f32, f32::max);
        let model_inner_radius = inner_radius(mesh.positions, mesh.indices, model_center);
        // A ray inside a convex body with flat facets leaves through the nearest facet plane
        // ahead of it: every lane tests the same planes in turn (one load each for all of
        // them), where walking the grid through the body's empty middle loads per lane.
        let planes = convex
            .then(|| {
                vitreous_optics::convex::facet_planes(
                    mesh.positions,
                    mesh.normals,
                    mesh.indices,
                    model_center,
                )
            })
            .flatten()
            .unwrap_or_default();
        let facets = Buffer::with_data(
            ctx,
            "caustics facet planes",
            bytemuck::cast_slice(
                &planes
                    .iter()
                    .map(|p| p.to_array())
                    // One entry at least, read by no ray.
                    .chain(planes.is_empty().then_some([0.0; 4]))
                    .collect::<Vec<_>>(),
            ),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let inner_ball_inside =
            convex && behind_every_plane(mesh.positions, mesh.indices, model_center);
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let vec4s =
            |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.extend(0.0).to_array()).collect() };
        let cells: Vec<u32> = grid.cells.iter().flatten().copied().collect();
        // Each triangle's three vertex normals, so that a hit reads them without its indices.
        let vertex_normals: Vec<Vec3> = mesh
            .indices
            .iter()
            .map(|&i| mesh.normals[i as usize])
            .collect();
        let mesh_buffers = [
            Buffer::with_data(
                ctx,
                "caustics vertex normals",
                bytemuck::cast_slice(&vec4s(&vertex_normals)),
                storage,
            )?,
            Buffer::with_data(
                ctx,
                "caustics grid cells",
                bytemuck::cast_slice(&cells),
                storage,
            )?,
            Buffer::with_data(
                ctx,
                "caustics grid triangles",
                bytemuck::cast_slice(&grid.triangles),
                storage,
            )?,
            Buffer::with_data(
                ctx,
                "caustics triangle corners",
                bytemuck::cast_slice(&vec4s(&corner_and_edges(mesh.positions, mesh.indices))),
                storage,
            )?,
        ];
        Ok(LiveMesh {
            buffers: mesh_buffers,
            facets,
            grid_origin: grid.origin,
            grid_side: grid.side,
            grid_dims: grid.dims,
            center: model_center,
            radius: model_radius,
            inner_radius: model_inner_radius,
            convex,
            inner_ball_inside,
            facet_count: planes.len() as u32,
        })
    }
}
