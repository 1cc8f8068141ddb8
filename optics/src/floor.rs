//! The floor passes' equations on the CPU (METHOD.md section 1, paper eq. 2-5): each in one
//! function, which the GPU passes mirror (shaders/shared/inducer_ramp.wgsl, floor_overlay.wgsl) and
//! are tested against, and which CPU code computing the same quantity calls. Eq. 1, the
//! shadow region, is the planar projection in `vitreous_render`'s `floor::geometry::planar_shadow`.

use glam::Vec2;

/// Distance stored for lit texels when the floor has no shadow at all, metres.
pub const FAR_M: f32 = 1.0e9;

/// eq. 2: the ramp alpha(d) = (D - d) / D for 0 <= d < D, 0 for d >= D and inside the shadow
/// (negative d). `d_m` is the distance from a lit floor point to the shadow edge, D is
/// `ramp_width_m`.
pub fn ramp(d_m: f32, ramp_width_m: f32) -> f32 {
    if d_m < 0.0 || d_m >= ramp_width_m {
        0.0
    } else {
        (ramp_width_m - d_m) / ramp_width_m
    }
}

/// eq. 4: the inducer's gain alpha'(d) = k alpha(d), relative to the floor's luminance (what
/// the overlay's gain texture holds, shaders/inducer_distance.wgsl `gain_of`).
pub fn inducer_gain(k: f32, alpha: f32) -> f32 {
    k * alpha
}

/// eq. 3: the inducer light L_s = alpha'(d) L_r (alpha' of eq. 4) for the floor's recorded
/// (linear) luminance L_r.
pub fn inducer_light(k: f32, alpha: f32, floor_luminance: f32) -> f32 {
    inducer_gain(k, alpha) * floor_luminance
}

/// eq. 5: what the wearer sees on the floor, L_o = L_r + L_s = (1 + alpha'(d)) L_r.
pub fn perceived_floor(k: f32, alpha: f32, floor_luminance: f32) -> f32 {
    floor_luminance + inducer_light(k, alpha, floor_luminance)
}

/// Distance from a lit texel to the shadow edge, metres, given the offset (in texels) from it
/// to its nearest shadow texel and the texel size in metres: the edge is taken halfway
/// between the shadow texel's centre and its lit neighbour's, half a texel short of the
/// shadow texel's centre along the offset. Same formula as `edge_distance_m` in
/// shaders/shared/inducer_ramp.wgsl.
pub fn edge_distance_m(offset_texels: Vec2, texel_m: Vec2) -> f32 {
    let texels = offset_texels.length();
    (offset_texels * texel_m).length() * (1.0 - 0.5 / texels)
}

/// CPU reference of the distance field: for every texel of a `size` x `size` mask (nonzero =
/// shadow), the exact Euclidean distance in metres to its nearest shadow texel (searched over
/// all shadow texels with a lit 4-neighbour, which include every lit texel's nearest),
/// converted to a distance to the edge by [`edge_distance_m`]; -1 inside the shadow and
/// [`FAR_M`] when there is no shadow. Brute force: for tests.
pub fn exact_edge_distances(mask: &[u8], size: u32, texel_m: Vec2) -> Vec<f32> {
    let n = size as i32;
    let at = |x: i32, y: i32| mask[(y * n + x) as usize] != 0;
    let mut boundary = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let lit_neighbour = [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|(dx, dy)| {
                let (qx, qy) = (x + dx, y + dy);
                (0..n).contains(&qx) && (0..n).contains(&qy) && !at(qx, qy)
            });
            if at(x, y) && lit_neighbour {
                boundary.push(Vec2::new(x as f32, y as f32));
            }
        }
    }
    let mut out = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            if at(x, y) {
                out.push(-1.0);
                continue;
            }
            let p = Vec2::new(x as f32, y as f32);
            let nearest = boundary.iter().min_by(|a, b| {
                (((**a - p) * texel_m).length_squared())
                    .total_cmp(&((**b - p) * texel_m).length_squared())
            });
            out.push(match nearest {
                Some(q) => edge_distance_m(*q - p, texel_m),
                None => FAR_M,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_follows_eq_2() {
        let d = 0.14;
        assert_eq!(ramp(-1.0, d), 0.0);
        assert_eq!(ramp(0.0, d), 1.0);
        assert!((ramp(0.07, d) - 0.5).abs() < 1e-6);
        assert_eq!(ramp(0.14, d), 0.0);
        assert_eq!(ramp(0.2, d), 0.0);
    }

    #[test]
    fn inducer_light_and_perceived_floor_follow_eq_3_to_5() {
        assert!((inducer_gain(0.3, 0.5) - 0.15).abs() < 1e-6);
        assert!((inducer_light(0.3, 0.5, 0.8) - 0.12).abs() < 1e-6);
        assert!((perceived_floor(0.3, 1.0, 0.5) - 0.65).abs() < 1e-6);
        // Inside the shadow (alpha 0) the floor is left as it is: an additive display cannot
        // darken it.
        assert_eq!(perceived_floor(0.3, ramp(-1.0, 0.14), 0.5), 0.5);
    }

    #[test]
    fn edge_distance_is_half_a_texel_short_of_the_shadow_texel() {
        let h = Vec2::splat(0.002);
        assert!((edge_distance_m(Vec2::new(1.0, 0.0), h) - 0.001).abs() < 1e-7);
        assert!((edge_distance_m(Vec2::new(0.0, -3.0), h) - 0.005).abs() < 1e-7);
        let diag = edge_distance_m(Vec2::new(3.0, 4.0), h);
        assert!((diag - 0.002 * 4.5).abs() < 1e-6);
    }

    #[test]
    fn exact_distances_of_a_single_shadow_texel() {
        let mut mask = vec![0u8; 16 * 16];
        mask[5 * 16 + 5] = 1;
        let d = exact_edge_distances(&mask, 16, Vec2::splat(1.0));
        assert_eq!(d[5 * 16 + 5], -1.0);
        assert!((d[5 * 16 + 9] - 3.5).abs() < 1e-6);
        assert!((d[9 * 16 + 8] - 4.5).abs() < 1e-6);
    }
}
