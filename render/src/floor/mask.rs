//! The shadow mask (eq. 1, shaders/inducer_mask.wgsl): the object projected from the point
//! light onto the floor plane and rasterised straight into floor space, once per pose.
//!
//! A convex object's shadow is the convex hull of its projected vertices. For such a mesh the
//! CPU finds that polygon for each pose ([`vitreous_optics::convex::hull_2d`]) and the pass
//! draws it as a fan of triangles, written into the command buffer with the draw: the glass
//! sphere's shadow becomes about a hundred triangles instead of the 4512 facing the light, which
//! the rasteriser of a CPU device (lavapipe) would set up one by one after every move. The
//! texels covered are the same: the hull's edges are the mesh's silhouette. Other meshes, and
//! poses where part of the mesh is at or above the light's height (its shadow is then
//! unbounded and the rasteriser clips it), draw the mesh.

use ash::vk;
use glam::{Mat4, Vec2, Vec3};
use gpu_allocator::MemoryLocation;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::{Buffer, memory_barrier};
use crate::owned::Owned;
use crate::pipeline::{
    self, Blend, Depth, MESH_POSITION_ATTRIBUTE, MESH_POSITION_BINDING, PipelineSpec,
};
use crate::scene::{GpuScene, MeshRef};
use crate::shaders;

/// Bytes the hull's triangles may take: what one `vkCmdUpdateBuffer` writes at most (a hull
/// of up to 1822 corners; larger ones draw the mesh).
const HULL_BYTES: u64 = 65536;

/// One hull vertex: clip-space x, y and depth 0, drawn with the identity as projection.
type HullVertex = [f32; 3];

/// The vertex input of the hull's triangles: three floats per vertex.
const HULL_BINDING: vk::VertexInputBindingDescription = vk::VertexInputBindingDescription {
    binding: 0,
    stride: size_of::<HullVertex>() as u32,
    input_rate: vk::VertexInputRate::VERTEX,
};

/// The mask's pipelines, the buffer of the hull's triangles and what the current pose draws;
/// freed on drop.
pub(super) struct MaskPass {
    /// Draws the mesh with the projection as push constant.
    mesh_pipeline: Owned<vk::Pipeline>,
    /// Draws the hull's triangles, given in clip space.
    hull_pipeline: Owned<vk::Pipeline>,
    /// Layout of both: a 4x4 matrix as push constant for the vertex stage.
    layout: Owned<vk::PipelineLayout>,
    /// The hull's triangles, rewritten by each computation that draws them.
    hull_buffer: Buffer,
    /// Whether the mesh bounds one convex body ([`vitreous_optics::convex::is_convex`]).
    convex: bool,
    /// Indices of the mesh's triangles.
    index_count: u32,
    /// Model space to the mask's clip space for the current pose; `None` when the light is
    /// not above the floor (nothing is drawn).
    clip_from_model: Option<Mat4>,
    /// The current pose's hull as a triangle list; empty when the mesh is drawn instead.
    hull: Vec<HullVertex>,
}

impl MaskPass {
    /// The pipelines in `render_pass` (the mask's) for `mesh`, with `convex` as
    /// [`vitreous_optics::convex::is_convex`] says of it and `closed` as
    /// [`vitreous_optics::convex::is_closed`].
    pub fn new(
        ctx: &GpuContext,
        render_pass: vk::RenderPass,
        mesh: &MeshRef,
        convex: bool,
        closed: bool,
    ) -> Result<MaskPass> {
        let layout = pipeline::layout(
            ctx,
            None,
            vk::ShaderStageFlags::VERTEX,
            size_of::<[f32; 16]>() as u32,
        )?;
        let spec = |bindings, cull| PipelineSpec {
            render_pass,
            layout: layout.raw(),
            vertex: (shaders::MASK_VS, c"vs_main"),
            fragment: (shaders::MASK_FS, c"fs_main"),
            bindings,
            attributes: &[MESH_POSITION_ATTRIBUTE],
            cull,
            depth: Depth::Off,
            blend: Blend::Replace,
        };
        // A closed mesh's shadow is drawn whole by the triangles facing either way alone, so
        // one kind is culled: half the triangles the rasteriser sets up after every move.
        let cull = if closed {
            vk::CullModeFlags::BACK
        } else {
            vk::CullModeFlags::NONE
        };
        let mesh_pipeline = pipeline::create(ctx, &spec(&[MESH_POSITION_BINDING], cull))?;
        let hull_pipeline = pipeline::create(ctx, &spec(&[HULL_BINDING], vk::CullModeFlags::NONE))?;
        let hull_buffer = Buffer::new(
            ctx,
            "shadow hull",
            HULL_BYTES,
            vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        tracing::debug!(
            convex,
            closed,
            "shadow mask drawn from {}",
            if convex {
                "the hull of the projected mesh"
            } else {
                "the mesh"
            }
        );
        Ok(MaskPass {
            mesh_pipeline,
            hull_pipeline,
            layout,
            hull_buffer,
            convex,
            index_count: mesh.indices.len() as u32,
            clip_from_model: None,
            hull: Vec::new(),
        })
    }

    /// Sets what the next computations draw: the mesh (model-space `positions`) through
    /// `clip_from_model`, or nothing without one; the hull of its projection when the mesh
    /// is convex and lies below the light.
    pub fn set_pose(&mut self, clip_from_model: Option<Mat4>, positions: &[Vec3]) {
        self.clip_from_model = clip_from_model;
        self.hull = match clip_from_model {
            Some(m) if self.convex => hull_triangles(m, positions).unwrap_or_default(),
            _ => Vec::new(),
        };
    }

    /// Whether the mesh bounds one convex body.
    pub fn convex(&self) -> bool {
        self.convex
    }

    /// Whether the current pose draws anything.
    pub fn draws(&self) -> bool {
        self.clip_from_model.is_some()
    }

    /// Records the upload of the hull's triangles, if the pose draws them, ordered after
    /// earlier draws' reads of the buffer and before the next draw's.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; `self` must outlive its execution.
    pub unsafe fn record_upload(&self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        if self.hull.is_empty() || !self.draws() {
            return;
        }
        let d = &ctx.device;
        let data: &[u8] = bytemuck::cast_slice(&self.hull);
        ctx.work.upload(data.len());
        let input = (
            vk::PipelineStageFlags::VERTEX_INPUT,
            vk::AccessFlags::VERTEX_ATTRIBUTE_READ,
        );
        let transfer = (
            vk::PipelineStageFlags::TRANSFER,
            vk::AccessFlags::TRANSFER_WRITE,
        );
        // SAFETY: the caller's contract (outside a render pass); the data is a multiple of 4
        // bytes and at most HULL_BYTES (`hull_triangles`), the buffer's size, which allows
        // transfers into it; the barriers order the write after earlier draws' reads and
        // before later ones.
        unsafe {
            memory_barrier(d, cmd, (input.0, vk::AccessFlags::empty()), transfer);
            d.cmd_update_buffer(cmd, self.hull_buffer.buffer, 0, data);
            memory_barrier(d, cmd, transfer, input);
        }
    }

    /// Records the mask's draw for the current pose (nothing when the light is not above the
    /// floor): the hull's triangles uploaded by [`MaskPass::record_upload`], or the mesh.
    ///
    /// # Safety
    /// `cmd` must be recording inside the mask's render pass, after `record_upload` in the
    /// same command buffer; `self` and `scene` (the scene the pass was made for) must outlive
    /// its execution.
    pub unsafe fn record_draw(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, scene: &GpuScene) {
        let Some(clip_from_model) = self.clip_from_model else {
            return;
        };
        let d = &ctx.device;
        // The push constant: one matrix.
        ctx.work.upload(std::mem::size_of::<[f32; 16]>());
        let (pipeline, projection) = if self.hull.is_empty() {
            (&self.mesh_pipeline, clip_from_model)
        } else {
            (&self.hull_pipeline, Mat4::IDENTITY)
        };
        // SAFETY: the caller's contract; the pipeline and layout are this pass's, the buffers
        // the scene's or this pass's.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.raw());
            d.cmd_push_constants(
                cmd,
                self.layout.raw(),
                vk::ShaderStageFlags::VERTEX,
                0,
                bytemuck::bytes_of(&projection.to_cols_array()),
            );
            if self.hull.is_empty() {
                d.cmd_bind_vertex_buffers(cmd, 0, &[scene.vertices.buffer], &[0]);
                d.cmd_bind_index_buffer(cmd, scene.indices.buffer, 0, vk::IndexType::UINT32);
                d.cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
                ctx.work.draw(self.index_count);
            } else {
                d.cmd_bind_vertex_buffers(cmd, 0, &[self.hull_buffer.buffer], &[0]);
                d.cmd_draw(cmd, self.hull.len() as u32, 1, 0, 0);
                ctx.work.draw(self.hull.len() as u32);
            }
        }
    }
}

/// The convex hull of the model-space `positions` projected by `clip_from_model`, in clip
/// space (x, y after the perspective division, depth 0), as a fan of triangles; `None` when
/// a vertex lies at or beyond the light's height (w <= 0: the shadow is unbounded) or the
/// triangles would take more than [`HULL_BYTES`]. No triangles when the hull has no area.
pub(super) fn hull_triangles(clip_from_model: Mat4, positions: &[Vec3]) -> Option<Vec<HullVertex>> {
    let mut projected = Vec::with_capacity(positions.len());
    for p in positions {
        let clip = clip_from_model * p.extend(1.0);
        // Also refuses NaN.
        if clip.w.is_nan() || clip.w <= 1e-6 {
            return None;
        }
        projected.push(Vec2::new(clip.x, clip.y) / clip.w);
    }
    let corners = vitreous_optics::convex::hull_2d(&projected);
    let triangles = corners.len().saturating_sub(2);
    if (triangles * 3 * size_of::<HullVertex>()) as u64 > HULL_BYTES {
        return None;
    }
    let vertex = |p: Vec2| [p.x, p.y, 0.0];
    Some(
        (1..=triangles)
            .flat_map(|i| [corners[0], corners[i], corners[i + 1]].map(vertex))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec4Swizzles};

    use super::*;
    use crate::floor::geometry::{Floor, mask_clip_from_model, planar_shadow};

    /// A UV sphere of radius 1 about the origin.
    fn sphere(segments: u32, rings: u32) -> (Vec<Vec3>, Vec<u32>) {
        let mut positions = Vec::new();
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                positions.push(Vec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    theta.sin() * phi.cos(),
                ));
            }
        }
        let row = segments + 1;
        let mut indices = Vec::new();
        for r in 0..rings {
            for s in 0..segments {
                let a = r * row + s;
                indices.extend([a, a + row, a + row + 1, a, a + row + 1, a + 1]);
            }
        }
        (positions, indices)
    }

    /// The shipped floor: 1 m, facing up, 0.30 m below the eyes and 1.5 m ahead.
    fn floor() -> Floor {
        Floor::new(Mat4::from_rotation_translation(
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, -0.3, -1.5),
        ))
    }

    /// Whether clip-space `p` lies in the triangle `t` (either winding, edges included).
    fn in_triangle(p: Vec2, t: [Vec2; 3]) -> bool {
        let side = |a: Vec2, b: Vec2| (b - a).perp_dot(p - a);
        let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
        s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0)
    }

    /// Distance from `p` to the nearest edge of the triangles' outline (any edge, clip units).
    fn to_edges(p: Vec2, triangles: &[[Vec2; 3]]) -> f32 {
        let segment = |a: Vec2, b: Vec2| {
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a))
        };
        triangles
            .iter()
            .flat_map(|t| {
                [
                    segment(t[0], t[1]),
                    segment(t[1], t[2]),
                    segment(t[2], t[0]),
                ]
            })
            .fold(f32::INFINITY, f32::min)
    }

    /// The hull's triangles cover the texel centres of a 512 x 512 mask that the mesh's own
    /// projected triangles cover, but for centres within 1e-4 of an edge (a texel is 4e-3).
    fn check_same_cover(positions: &[Vec3], indices: &[u32], world_from_model: Mat4, light: Vec3) {
        let floor = floor();
        let shadow = planar_shadow(floor.center_m, floor.normal, light).expect("light above");
        let clip_from_model = mask_clip_from_model(&floor, shadow, world_from_model);
        let hull = hull_triangles(clip_from_model, positions).expect("below the light");
        assert!(!hull.is_empty() && hull.len().is_multiple_of(3));
        let fan: Vec<[Vec2; 3]> = hull
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|k| Vec2::new(t[k][0], t[k][1])))
            .collect();
        let project = |i: u32| {
            let c = clip_from_model * positions[i as usize].extend(1.0);
            c.xy() / c.w
        };
        let mesh: Vec<[Vec2; 3]> = indices
            .chunks_exact(3)
            .map(|t| [project(t[0]), project(t[1]), project(t[2])])
            .collect();
        let n = 512;
        // The texels about the shadow's bounding box (clip -1..1 over n texels).
        let points = mesh.iter().flatten();
        let lo = points.clone().fold(Vec2::INFINITY, |a, &b| a.min(b));
        let hi = points.fold(Vec2::NEG_INFINITY, |a, &b| a.max(b));
        let texel = |v: f32| ((v + 1.0) / 2.0 * n as f32).clamp(0.0, n as f32) as u32;
        let (mut covered, mut near_edge) = (0, 0);
        for y in texel(lo.y).saturating_sub(2)..(texel(hi.y) + 2).min(n) {
            for x in texel(lo.x).saturating_sub(2)..(texel(hi.x) + 2).min(n) {
                let p = (Vec2::new(x as f32, y as f32) + 0.5) / n as f32 * 2.0 - 1.0;
                let by_hull = fan.iter().any(|&t| in_triangle(p, t));
                let by_mesh = mesh.iter().any(|&t| in_triangle(p, t));
                covered += usize::from(by_mesh);
                if by_hull != by_mesh {
                    near_edge += 1;
                    assert!(to_edges(p, &fan) < 1e-4, "texel ({x}, {y}): hull {by_hull}");
                }
            }
        }
        assert!(covered > 500, "a shadow of {covered} texels");
        assert!(near_edge <= 2, "{near_edge} texels differ");
    }

    #[test]
    fn a_convex_meshs_hull_covers_what_its_triangles_cover() {
        let (ball, ball_indices) = sphere(32, 16);
        let resting = Mat4::from_scale_rotation_translation(
            Vec3::splat(0.04),
            Quat::from_rotation_y(0.3),
            Vec3::new(0.0, -0.26, -1.5),
        );
        for light in [Vec3::new(0.0, 0.7, -2.5), Vec3::new(0.6, 0.1, -1.2)] {
            check_same_cover(&ball, &ball_indices, resting, light);
        }
        // A cube on one corner, turned: its hull's corners are six of its eight.
        let (cube, _, cube_indices) = vitreous_optics::solid::flat_cube(0.03);
        let tilted = Mat4::from_rotation_translation(
            Quat::from_rotation_x(0.6) * Quat::from_rotation_z(0.7),
            Vec3::new(0.05, -0.24, -1.45),
        );
        check_same_cover(&cube, &cube_indices, tilted, Vec3::new(-0.3, 0.8, -1.9));
    }

    #[test]
    fn the_hull_of_a_sphere_is_a_few_hundred_triangles_and_none_above_the_light() {
        let (ball, _) = sphere(96, 48);
        let floor = floor();
        let model = Mat4::from_scale_rotation_translation(
            Vec3::splat(0.04),
            Quat::IDENTITY,
            Vec3::new(0.0, -0.26, -1.5),
        );
        let clip = |light| {
            let shadow = planar_shadow(floor.center_m, floor.normal, light).unwrap();
            mask_clip_from_model(&floor, shadow, model)
        };
        let hull = hull_triangles(clip(Vec3::new(0.0, 0.7, -2.5)), &ball).unwrap();
        assert!(hull.len() / 3 < 300, "{} triangles", hull.len() / 3);
        // The light between the floor and the top of the ball: the shadow is unbounded.
        assert!(hull_triangles(clip(Vec3::new(0.5, -0.25, -1.5)), &ball).is_none());
    }
}
