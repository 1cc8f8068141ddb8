//! The room's light in `vitreous run`: when the runtime estimates it (XR_ML_light_estimation,
//! Magic Leap 2; `RunSink::follow_room_light` in `sink.rs`), the scene's point light turns about the object, at its distance, to shine
//! the way the room's main light does, so the shadow inducer, the caustics and the dimmed
//! shadow follow the real light, and the light's share of the floor's light (`[light] share`)
//! becomes the estimate's: the main light's irradiance on the floor over all the light's. Each
//! change is an edit of the recording (`light-estimate`, carrying the share), which a replay
//! repeats.
//!
//! With `--readback-check` the run also reads back, at its end, where the shadow and the
//! caustic lie on the floor ([`FloorCentroids`]), for a check against an independent
//! computation of both.

use anyhow::Result;
use glam::{DVec2, Vec3};
use serde::Serialize;
use vitreous_render::Renderer;

/// What the room's light estimates did in a session.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RoomLight {
    /// Estimates the app received.
    pub estimates: u64,
    /// Times the scene's light moved or its share changed to follow one (the rest were within
    /// `vitreous_trace::light::MIN_TURN_DEG` of where it shone, and within
    /// `MIN_SHARE_STEP` of its share).
    pub light_moves: u64,
    /// The way the newest estimate's main light travels, in the scene frame.
    pub direction: Option<[f32; 3]>,
    /// The newest estimate's share of the floor's light: the main light's irradiance on the
    /// floor over all the light's (ambient spherical harmonics included), by luminance.
    pub floor_share: Option<f32>,
    /// The share the renderer uses after the newest estimate (to a thousandth).
    pub light_share: Option<f32>,
}

/// Where the shadow and the caustic lie on the floor, from the renderer's fields.
#[derive(Clone, Debug, Serialize)]
pub struct FloorCentroids {
    /// The corner of the floor's texel grids (its texel (0, 0)'s outer corner), metres.
    pub origin_m: [f32; 3],
    /// The grids' full width along their x, metres (a world vector).
    pub u_m: [f32; 3],
    /// The grids' full height along their y, metres (a world vector).
    pub v_m: [f32; 3],
    /// Side of the shadow inducer's grid, texels.
    pub shadow_resolution_px: u32,
    /// Texels in the shadow.
    pub shadow_texels: u64,
    /// The shadow's centroid, texels from the corner (`null`: no shadow).
    pub shadow_centroid_px: Option<[f64; 2]>,
    /// Side of the caustic map, texels (`null`: no caustics computed live).
    pub caustic_resolution_px: Option<u32>,
    /// The caustic gain's centroid, texels from the corner, weighted by the gain.
    pub caustic_centroid_px: Option<[f64; 2]>,
    /// The light's position the fields were computed for, metres.
    pub light_position_m: [f32; 3],
    /// The object's centre, metres.
    pub object_center_m: [f32; 3],
    /// The object's bounding-sphere radius, metres.
    pub object_radius_m: f32,
}

/// The weighted centroid of a square grid of side `n` (texel centres at `i + 0.5`).
fn centroid(n: u32, weight: impl Fn(usize) -> f64) -> Option<DVec2> {
    let mut sum = DVec2::ZERO;
    let mut total = 0.0;
    for y in 0..n {
        for x in 0..n {
            let w = weight((y * n + x) as usize);
            if w > 0.0 {
                sum += DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5) * w;
                total += w;
            }
        }
    }
    (total > 0.0).then(|| sum / total)
}

/// Reads back the shadow inducer's fields and the live caustic map (the last computed) and
/// finds their centroids; the floor's grid from `world_from_plane`.
pub fn floor_centroids(
    renderer: &mut Renderer,
    world_from_plane: glam::Mat4,
    light_position_m: Vec3,
    object_center_m: Vec3,
    object_radius_m: f32,
) -> Result<FloorCentroids> {
    let fields = renderer.inducer_fields()?;
    let n = fields.resolution_px;
    let shadow = centroid(n, |i| f64::from(fields.mask[i]));
    let caustic = renderer.live_caustic_gain()?.and_then(|gain| {
        let side = (gain.len() as f64).sqrt().round() as u32;
        (side * side == gain.len() as u32 && side > 0)
            .then(|| (side, centroid(side, |i| f64::from(gain[i]).max(0.0))))
    });
    // Texel (x, y) of an n-grid is at plane-local (u - 0.5, 0.5 - v).
    let origin = world_from_plane.transform_point3(Vec3::new(-0.5, 0.5, 0.0));
    let u = world_from_plane.transform_vector3(Vec3::X);
    let v = world_from_plane.transform_vector3(Vec3::NEG_Y);
    Ok(FloorCentroids {
        origin_m: origin.to_array(),
        u_m: u.to_array(),
        v_m: v.to_array(),
        shadow_resolution_px: n,
        shadow_texels: fields.mask.iter().filter(|&&m| m == 1).count() as u64,
        shadow_centroid_px: shadow.map(|c| c.to_array()),
        caustic_resolution_px: caustic.map(|(side, _)| side),
        caustic_centroid_px: caustic.and_then(|(_, c)| c).map(|c| c.to_array()),
        light_position_m: light_position_m.to_array(),
        object_center_m: object_center_m.to_array(),
        object_radius_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centroid_weighs_texel_centres() {
        // Two texels of a 4-grid: (1, 2) with weight 1 and (3, 2) with weight 3.
        let c = centroid(4, |i| match i {
            9 => 1.0,
            11 => 3.0,
            _ => 0.0,
        })
        .unwrap();
        assert!((c - DVec2::new(3.0, 2.5)).length() < 1e-12, "{c}");
        assert_eq!(centroid(4, |_| 0.0), None);
    }
}
