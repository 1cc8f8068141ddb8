//! The object as the glass's exit sees it: its centre and radius (a ball's sphere), the facet
//! planes of a convex faceted object, and the triangles searched through any other closed
//! mesh.

use ash::vk;
use glam::Vec4;
use vitreous_optics::convex;
use vitreous_optics::refraction::Refraction;
use vitreous_optics::solid::mesh_center;

use super::mesh;
use crate::context::GpuContext;
use crate::coverage;
use crate::error::Result;
use crate::memory::Buffer;
use crate::scene::SceneDesc;

/// World metres per model unit of the object's uniform scale (the shader measures the path
/// inside in model units).
pub(super) fn metres_per_model_unit(desc: &SceneDesc) -> f32 {
    glam::Mat3::from_mat4(desc.world_from_model)
        .determinant()
        .abs()
        .cbrt()
}

/// The object's frame for the exit: its centre (model units, its bounding box's) and the largest
/// distance of a vertex from it (a ball's radius) as the shader's `radial` vector, and whether
/// the object is a ball about it (`coverage::ball`: the shader then takes the sphere).
pub(super) fn object_frame(desc: &SceneDesc) -> ([f32; 4], bool) {
    match coverage::ball(&desc.mesh) {
        Some((center, radius)) => (center.extend(radius).to_array(), true),
        None => {
            let center = mesh_center(desc.mesh.positions);
            let radius = desc
                .mesh
                .positions
                .iter()
                .map(|&p| (p - center).length())
                .fold(0.0f32, f32::max);
            (
                center.extend(radius.max(f32::MIN_POSITIVE)).to_array(),
                false,
            )
        }
    }
}

/// The elements of the mesh the shader searches (`mesh.rs`), where two-surface refraction
/// leaves the object through its triangles: an object that is not `analytic` (a ball or a convex
/// faceted object).
pub(super) fn searched_mesh(
    desc: &SceneDesc,
    radial: [f32; 4],
    analytic: bool,
) -> Result<Option<Vec<Vec4>>> {
    if desc.refraction != Refraction::TwoSurface || analytic {
        return Ok(None);
    }
    let center = glam::Vec3::new(radial[0], radial[1], radial[2]);
    let elements = mesh::elements(&desc.mesh, center)?;
    tracing::debug!(
        "two-surface refraction: the exit searched among the object's triangles ({} buffer \
         elements)",
        elements.len()
    );
    Ok(Some(elements))
}

/// Uploads the facet planes of a flat-shaded convex object about the radial map's centre
/// (`radial`'s xyz) for two-surface refraction, and whether there are any: otherwise one
/// plane that no pipeline reads.
pub(super) fn upload_facet_planes(
    ctx: &GpuContext,
    desc: &SceneDesc,
    radial: [f32; 4],
) -> Result<(Buffer, bool)> {
    let m = desc.mesh;
    let center = glam::Vec3::new(radial[0], radial[1], radial[2]);
    let planes = (desc.refraction == Refraction::TwoSurface)
        .then(|| convex::facet_planes(m.positions, m.normals, m.indices, center))
        .flatten();
    if let Some(p) = &planes {
        tracing::debug!(
            "two-surface refraction: a convex object of {} facet planes",
            p.len()
        );
    }
    let convex = planes.is_some();
    let planes = convex::in_eights(planes.unwrap_or_default());
    let buffer = Buffer::with_data(
        ctx,
        "facet planes",
        bytemuck::cast_slice(&planes),
        vk::BufferUsageFlags::STORAGE_BUFFER,
    )?;
    Ok((buffer, convex))
}
