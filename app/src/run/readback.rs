//! The readback check of `vitreous run --readback-check`: one submitted swapchain image read
//! back and the object's projected disc searched for lit pixels, so a run proves it drew the
//! object where the headset looks.

use serde::Serialize;
use vitreous_xr::FrameInput;

/// What the readback of a submitted swapchain image showed.
#[derive(Clone, Debug, Serialize)]
pub struct ReadbackCheck {
    /// Index of the frame read back.
    pub frame: u64,
    /// Pixels (both eyes) inside the object's projected disc.
    pub region_px: u64,
    /// Of those, pixels where the submitted image differs from the real world alone (or from
    /// black, on a see-through display) by more than [`LIT_THRESHOLD`] in some channel.
    pub object_px: u64,
    /// `object_px / region_px`.
    pub object_fraction: f64,
    /// Mean sRGB value (0-255) of the submitted image inside the region.
    pub mean_value: f64,
    /// Whether the check passed (`object_fraction >= MIN_OBJECT_FRACTION`).
    pub passed: bool,
}

/// How different (sRGB steps) a pixel must be to count as the object's.
pub const LIT_THRESHOLD: u8 = 8;
/// Share of the object's region that must show it.
pub const MIN_OBJECT_FRACTION: f64 = 0.2;

/// Counts the object's pixels in a readback of both eyes (see [`ReadbackCheck`]).
pub(super) fn check_readback(
    input: &FrameInput,
    rb: &vitreous_render::Readback,
    center_m: glam::Vec3,
    radius_m: f32,
    world_behind: bool,
) -> ReadbackCheck {
    let (w, h) = (rb.width as usize, rb.height as usize);
    let (mut region, mut object, mut sum) = (0u64, 0u64, 0f64);
    for eye in 0..2 {
        let view = &input.views[eye];
        // The object's centre in the eye frame, projected with the eye's (asymmetric) fov.
        let p = view.pose.orientation.conjugate() * (center_m - view.pose.position);
        if p.z >= -1e-4 {
            continue;
        }
        let (l, r) = (
            view.fov.angle_left_rad.tan(),
            view.fov.angle_right_rad.tan(),
        );
        let (d, u) = (view.fov.angle_down_rad.tan(), view.fov.angle_up_rad.tan());
        let (x, y) = (p.x / -p.z, p.y / -p.z);
        let px = (x - l) / (r - l) * w as f32;
        let py = (u - y) / (u - d) * h as f32;
        let rad = (radius_m / p.length()).min(1.0).asin().tan();
        let (rx, ry) = (rad / (r - l) * w as f32, rad / (u - d) * h as f32);
        let image = &rb.eyes[eye];
        let world = rb.world.as_ref().map(|wv| &wv[eye]);
        for row in 0..h {
            for col in 0..w {
                let dx = (col as f32 + 0.5 - px) / rx;
                let dy = (row as f32 + 0.5 - py) / ry;
                if dx * dx + dy * dy > 1.0 {
                    continue;
                }
                region += 1;
                let i = (row * w + col) * 4;
                let got = &image[i..i + 3];
                sum += got.iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0;
                let lit = match (world_behind, world) {
                    (true, Some(wv)) => got
                        .iter()
                        .zip(&wv[i..i + 3])
                        .any(|(&a, &b)| a.abs_diff(b) > LIT_THRESHOLD),
                    _ => got.iter().any(|&a| a > LIT_THRESHOLD),
                };
                if lit {
                    object += 1;
                }
            }
        }
    }
    let fraction = if region == 0 {
        0.0
    } else {
        object as f64 / region as f64
    };
    ReadbackCheck {
        frame: input.index,
        region_px: region,
        object_px: object,
        object_fraction: fraction,
        mean_value: if region == 0 {
            0.0
        } else {
            sum / region as f64
        },
        passed: region > 0 && fraction >= MIN_OBJECT_FRACTION,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::test_frame as frame;

    #[test]
    fn readback_check_counts_lit_pixels_in_the_object_disc() {
        let (w, h) = (32u32, 32u32);
        let mut lit = vec![0u8; (w * h * 4) as usize];
        for px in lit.chunks_exact_mut(4) {
            px.copy_from_slice(&[200, 200, 200, 255]);
        }
        let dark = vec![0u8; (w * h * 4) as usize];
        let rb = |eyes: [Vec<u8>; 2]| vitreous_render::Readback {
            width: w,
            height: h,
            eyes,
            world: None,
        };
        let center = glam::Vec3::new(0.0, 0.0, -1.0);
        let c = check_readback(&frame(), &rb([lit.clone(), lit]), center, 0.1, false);
        assert!(
            c.passed && c.region_px > 0 && c.object_px == c.region_px,
            "{c:?}"
        );
        let c = check_readback(&frame(), &rb([dark.clone(), dark]), center, 0.1, false);
        assert!(!c.passed && c.object_px == 0);
        // Behind the viewer: no region, no pass.
        let c = check_readback(
            &frame(),
            &rb([vec![0; (w * h * 4) as usize], vec![0; (w * h * 4) as usize]]),
            glam::Vec3::new(0.0, 0.0, 1.0),
            0.1,
            false,
        );
        assert!(!c.passed && c.region_px == 0);
    }
}
