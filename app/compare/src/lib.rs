//! vitreous-compare: how far an image is from a reference, as ꟻLIP (NVIDIA's perceptual
//! difference evaluator, through the `nv-flip` crate behind the `flip` feature) and PSNR, over
//! the whole view and region by region of a scene; used by `vitreous compare` and by
//! `vitreous replay --compare-reference`.
//!
//! | module | what it is |
//! |---|---|
//! | [`figures`] | the figures per region, the additive limit, a frame measured against the physical reference, the reports |
//! | [`regions`] | where in an eye image the object's disc, the shadow and caustic, the inducer's ramp and the rest lie, and the ring around the disc |
//! | [`listed`] | which frame and eye a reference image is, from the `reference.json` beside it |
//! | [`images`] | the PNG images compared, read with every error naming the file |
//! | [`flip`] | ꟻLIP itself, and its colour map for the error map |

pub mod figures;
pub mod flip;
pub mod images;
pub mod listed;
pub mod regions;

pub use figures::{
    Against, Comparison, ReferenceFigures, RegionFigures, ShiftedFigures, additive_limit,
    against_reference, compare, rgb_of, scene_pixels_per_degree,
};
pub use images::Png;
pub use listed::{Listed, REFERENCE_JSON, frame_for_scene, frame_of_image, reference_json_beside};
pub use regions::{Eye, Labels, RING_DEG, Region, neutral_camera, regions, regions_of, ring_of};
