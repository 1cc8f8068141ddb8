//! The object's triangles for the glass shader's search (two-surface refraction through a mesh
//! that is neither a ball nor a convex gem: shaders/glass.wgsl `mesh_hit`): the closed solid the
//! CPU tracers check and trace, about the object's centre in model units, its bounding-volume
//! hierarchy (optics/src/solid/bvh.rs) and triangles flattened into one storage buffer.

use ash::vk;
use glam::{Vec3, Vec4};
use vitreous_optics::solid::Solid;
use vitreous_optics::solid::bvh::Bvh;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::memory::Buffer;
use crate::scene::MeshRef;

/// Depth of the shader's search stack (glass.wgsl `MESH_STACK`): a deeper hierarchy is refused.
const SEARCH_STACK: usize = 32;

/// Triangles per leaf the shader tests (glass.wgsl `visit`, without a loop) at most.
const LEAF_TRIANGLES: u32 = 4;

/// Elements (`vec4<f32>`) per triangle: corner 0, edge 1, edge 2, the corners' normals.
const TRIANGLE_ELEMENTS: usize = 6;

/// The buffer's elements: the header, the nodes, the triangles in the hierarchy's order, laid
/// out as glass.wgsl's `mesh` describes. `center` is the origin of the frame (model units).
pub(super) fn elements(mesh: &MeshRef, center: Vec3) -> Result<Vec<Vec4>> {
    let local: Vec<Vec3> = mesh.positions.iter().map(|&p| p - center).collect();
    let solid = Solid::new(&local, mesh.normals, mesh.indices).map_err(|e| {
        RenderError::InvalidInput(format!("two-surface refraction needs a closed mesh: {e}"))
    })?;
    let bvh = Bvh::new(&solid.triangles_m);
    if bvh.depth() > SEARCH_STACK {
        return Err(RenderError::InvalidInput(format!(
            "two-surface refraction: the object's bounding-volume hierarchy is {} levels deep; \
             the shader searches {SEARCH_STACK} at most",
            bvh.depth()
        )));
    }
    let (nodes, order) = bvh.flat();
    if let Some(leaf) = nodes.iter().find(|n| n.count > LEAF_TRIANGLES) {
        return Err(RenderError::InvalidInput(format!(
            "two-surface refraction: a leaf of the object's bounding-volume hierarchy holds {} \
             triangles; the shader tests {LEAF_TRIANGLES} at most",
            leaf.count
        )));
    }
    let first_triangle = 1 + 2 * nodes.len();
    let bits = |u: u32| f32::from_bits(u);
    let mut out = Vec::with_capacity(first_triangle + TRIANGLE_ELEMENTS * order.len());
    out.push(Vec4::new(
        bits(first_triangle as u32),
        bits(nodes.len() as u32),
        0.0,
        0.0,
    ));
    for n in &nodes {
        out.push(n.lo.extend(bits(n.first)));
        out.push(n.hi.extend(bits(n.count)));
    }
    for &t in &order {
        let [a, b, c] = solid.triangles_m[t as usize];
        let normals = solid.corner_normals[t as usize];
        out.extend([a, b - a, c - a].map(|v| v.extend(0.0)));
        out.extend(normals.map(|n| n.extend(0.0)));
    }
    Ok(out)
}

/// Uploads `elements` (or one unused element where there are none) as the glass's `mesh`
/// storage buffer.
pub(super) fn upload(ctx: &GpuContext, elements: Option<Vec<Vec4>>) -> Result<Buffer> {
    let elements = elements.unwrap_or_else(|| vec![Vec4::ZERO]);
    Buffer::with_data(
        ctx,
        "glass mesh hierarchy",
        bytemuck::cast_slice(&elements),
        vk::BufferUsageFlags::STORAGE_BUFFER,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest triangle along a ray as the shader's search finds it in `elements`: a
    /// line-by-line twin of glass.wgsl `mesh_hit` (without its stack limit), so that the layout
    /// the buffer is written in is checked against the CPU tracer's answer.
    fn search(elements: &[Vec4], p: Vec3, d: Vec3) -> Option<(f32, Vec3)> {
        let u = |x: f32| x.to_bits();
        let base = u(elements[0].x) as usize;
        let inv = d.recip();
        let entry = |n: usize| {
            let (lo, hi) = (
                elements[1 + 2 * n].truncate(),
                elements[2 + 2 * n].truncate(),
            );
            let (t0, t1) = ((lo - p) * inv, (hi - p) * inv);
            let near = t0.min(t1).max_element().max(0.0);
            let far = t0.max(t1).min_element();
            if near <= far { near } else { f32::INFINITY }
        };
        let mut best: Option<(f32, usize, f32, f32)> = None;
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            if entry(n) >= best.map_or(f32::INFINITY, |b| b.0) {
                continue;
            }
            let (first, count) = (u(elements[1 + 2 * n].w), u(elements[2 + 2 * n].w));
            if count == 0 {
                stack.extend([first as usize + 1, first as usize]);
                continue;
            }
            for k in first..first + count {
                let at = base + TRIANGLE_ELEMENTS * k as usize;
                let [p0, e1, e2] = [0, 1, 2].map(|i| elements[at + i].truncate());
                let q = d.cross(e2);
                let det = e1.dot(q);
                let s = p - p0;
                let (bu, r) = (s.dot(q) / det, s.cross(e1));
                let (bv, t) = (d.dot(r) / det, e2.dot(r) / det);
                if det != 0.0
                    && bu >= 0.0
                    && bv >= 0.0
                    && bu + bv <= 1.0
                    && t > 0.0
                    && best.is_none_or(|b| t < b.0)
                {
                    best = Some((t, at, bu, bv));
                }
            }
        }
        best.map(|(t, at, bu, bv)| {
            let n = elements[at + 3].truncate() * (1.0 - bu - bv)
                + elements[at + 4].truncate() * bu
                + elements[at + 5].truncate() * bv;
            (t, n.normalize())
        })
    }

    #[test]
    fn the_buffer_finds_the_triangles_the_cpu_tracer_finds() {
        use vitreous_optics::two_surface::{Body, MeshBody};
        let (positions, normals, indices) = vitreous_optics::solid::flat_cube(0.5);
        let center = Vec3::new(0.25, -0.5, 0.125);
        let moved: Vec<Vec3> = positions.iter().map(|&p| p + center).collect();
        let mesh = MeshRef {
            positions: &moved,
            normals: &normals,
            uvs: &[],
            indices: &indices,
        };
        let elements = elements(&mesh, center).unwrap();
        let body = MeshBody::new(&positions, &normals, &indices).unwrap();
        let mut found = 0;
        for i in 0..200u32 {
            let a = i as f32 * 0.7;
            let d = Vec3::new(a.sin() * (a * 0.3).cos(), (a * 0.3).sin(), a.cos()).normalize();
            let p = Vec3::new((a * 1.3).sin(), (a * 0.9).cos(), (a * 2.1).sin()) * 0.3;
            let cpu = body.leave(p, d).map(|(t, n)| (t - 1e-6, n));
            let gpu = search(&elements, p + d * 1e-6, d);
            match (cpu, gpu) {
                (Some((tc, nc)), Some((tg, ng))) => {
                    assert!((tc - tg).abs() < 1e-5, "ray {i}: {tc} against {tg}");
                    assert!(nc.abs_diff_eq(ng, 1e-5), "ray {i}: {nc} against {ng}");
                    found += 1;
                }
                (c, g) => panic!("ray {i}: CPU {c:?}, buffer {g:?}"),
            }
        }
        assert_eq!(found, 200);
    }

    #[test]
    fn an_open_mesh_is_refused_with_what_to_do() {
        let (positions, normals, indices) = vitreous_optics::solid::flat_cube(0.5);
        let mesh = MeshRef {
            positions: &positions,
            normals: &normals,
            uvs: &[],
            indices: &indices[..indices.len() - 6],
        };
        let message = elements(&mesh, Vec3::ZERO).unwrap_err().to_string();
        assert!(message.contains("needs a closed mesh"), "{message}");
        assert!(message.contains("does not enclose a volume"), "{message}");
    }
}
