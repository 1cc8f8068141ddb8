//! An eye image of the real world: each pixel the mean radiance over a stratified grid of
//! positions inside it (a box filter, as a camera's pixel integrates its area).

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use vitreous_optics::camera::EyeParams;

use crate::world::World;

/// A rectangle of pixels: `x..x + width`, `y..y + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// Linear RGB of a window of an eye image, row by row.
#[derive(Clone, Debug)]
pub struct EyeImage {
    /// The pixels the image covers.
    pub window: Window,
    /// Linear RGB per pixel, row by row.
    pub rgb: Vec<Vec3>,
}

impl EyeImage {
    /// The pixel `(x, y)` of the whole eye image (which must lie in the window).
    pub fn at(&self, x: u32, y: u32) -> Vec3 {
        let w = self.window;
        self.rgb[((y - w.y) * w.width + (x - w.x)) as usize]
    }
}

/// Renders `window` of a `size` eye image of `camera` (`size` pixels, x right, y down), each
/// pixel averaged over `samples_per_side` squared positions on a regular grid inside it.
pub fn render_eye(
    world: &World,
    camera: &EyeParams,
    size: (u32, u32),
    window: Window,
    samples_per_side: u32,
) -> EyeImage {
    let n = samples_per_side.max(1);
    let rays = camera.pixel_rays(Vec2::new(size.0 as f32, size.1 as f32));
    let rows: Vec<Vec<Vec3>> = (window.y..window.y + window.height)
        .into_par_iter()
        .map(|y| {
            (window.x..window.x + window.width)
                .map(|x| {
                    let mut sum = Vec3::ZERO;
                    for j in 0..n {
                        for i in 0..n {
                            let offset =
                                Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                            let pixel = Vec2::new(x as f32, y as f32) + offset;
                            let dir = rays.direction(pixel);
                            sum += world.radiance(camera.position_m, dir);
                        }
                    }
                    sum / (n * n) as f32
                })
                .collect()
        })
        .collect();
    EyeImage {
        window,
        rgb: rows.into_iter().flatten().collect(),
    }
}
