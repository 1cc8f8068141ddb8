//! The shadow inducer (METHOD.md section 1, paper Sec. 3.1.1, eq. 1-5).
//!
//! An additive display cannot darken the real floor where the virtual object's shadow falls,
//! so the floor AROUND the shadow is brightened by a ramp that fades out over a width D; the
//! eye then reads the untouched shadow region as darker than its surround.
//!
//! Everything below lives in floor space: square textures of `resolution_px` texels over the
//! floor photo's area (the unit square of [`crate::PlaneDesc::world_from_plane`], texel
//! (0, 0) at the photo's top-left, so texture uv equals photo uv). Once per pose of the object
//! and the light (on the first frame that asks for the inducer after a move, or on
//! [`crate::Renderer::inducer_fields`]) these passes run, each drawing only the region that
//! can change (the overlay's rectangle, and where the last computation drew):
//!
//! 1. **Shadow mask** (eq. 1, mask.rs; shaders/inducer_mask.wgsl): the mesh projected from the
//!    point light onto the floor plane by a homogeneous planar projection ([`planar_shadow`]
//!    in geometry.rs) and rasterised straight into floor space; covered texels are in shadow.
//!    For an opaque occluder this equals a conventional shadow-map lookup at each floor
//!    texel, without the map's resolution and depth-bias artefacts. A closed mesh is drawn
//!    from the triangles facing one way only (the same texels, half the triangles); a convex
//!    one as the convex hull of its projected vertices, found on the CPU (the same texels,
//!    a fan of a few hundred triangles at most).
//! 2. **Nearest shadow texel** (distance_transform.rs; shaders/inducer_distance.wgsl): an
//!    exact Euclidean distance transform of the mask in two compute passes (per column, then
//!    per row), nearest in metres.
//! 3. **Gain** (eq. 2 and 4): k alpha(d) in one R16F channel, the texture the overlay
//!    filters, with d, the distance in metres from a lit texel to the shadow edge
//!    ([`edge_distance_m`]), from its nearest shadow texel: computed by the transform's row
//!    pass as half floats and copied into the texture.
//! 4. **Distance to the edge** (`fs_distance`): d itself for every texel, -1 inside the
//!    shadow, into its own field, drawn only when the fields are read back (nothing else
//!    reads it).
//!
//! Per eye, the floor overlay (overlay.rs; shaders/floor_overlay.wgsl) is a world-anchored
//! rectangle on the floor plane covering only the shadow plus the ramp (bounded on the CPU
//! from the mesh's projected vertices, [`overlay_rect`]); it adds L_s = k alpha(d) L_r (eq. 3) with blend
//! (ONE, ONE), discarding texels without inducer light before it reads the photo: at most two
//! texture fetches per covered pixel. With the caustics on it adds G L_r (eq. 6) in the same
//! draw, G filtered from the caustic map (four more loads). The see-through preview then shows
//! L_o = (1 + k alpha(d)) L_r (eq. 5).
//!
//! # Synchronisation
//! Each floor-space render pass's subpass dependencies order it after the previous pass's
//! colour writes and fragment reads and make its writes visible to fragment shaders and
//! transfers; its image ends in SHADER_READ_ONLY_OPTIMAL. The compute passes and the gain's
//! copy are ordered by pipeline barriers the same way (distance_transform.rs), the gain image
//! moved to TRANSFER_DST_OPTIMAL for the copy and back. A recomputation recorded in a frame's
//! command buffer therefore also waits for earlier frames' overlay reads.
//!
//! # Modules
//! - `geometry`: the floor's frame, the shadow projection (eq. 1) and the overlay's rectangles;
//! - eq. 2-5 and the exact distance field on the CPU are `vitreous_optics::floor`;
//! - `fields`: the floor-space images, the push constants and the fields read back;
//! - `mask`: the shadow mask's pipelines, and the hull of a convex mesh's shadow;
//! - `distance_transform`: the nearest shadow texel of every texel (compute);
//! - `overlay`: the per-eye overlay pipeline;
//! - `live`: the caustic gain map computed per pose on the GPU (photon splatting, then
//!   smoothing), instead of a bake; `live_mesh`: what its photons read of the mesh;
//!   `triangle_grid`: the grid of triangle lists they walk; `smoothing`: which smoothing passes run for a radius, and the map's row layout;
//! - `pass`: the pass that builds all of it and records it once per pose;
//! - `progress`: whether that computation has really run (set only after its fence);
//! - `readback`: copying the fields back to the CPU.
//!
//! The scene limits checked before any of this is built (`validate_inducer`,
//! `validate_caustics`) live with the descriptions they check, in [`crate::scene`].

mod distance_transform;
mod fields;
mod geometry;
mod live;
mod live_mesh;
mod mask;
mod overlay;
mod pass;
mod progress;
mod readback;
mod smoothing;
mod triangle_grid;

pub use crate::scene::{
    MAX_CAUSTIC_GAIN, MAX_K, MAX_RAMP_WIDTH_M, MAX_RESOLUTION_PX, MIN_RESOLUTION_PX,
    validate_caustics, validate_inducer as validate,
};
pub use fields::{FIELD_STAMPS, FieldPassesMs, InducerFields};
pub(crate) use fields::{FieldTarget, Stamps};
pub use geometry::{caustic_rect, overlay_rect, planar_shadow};
pub(crate) use pass::InducerPass;
pub(crate) use progress::Prepared;
