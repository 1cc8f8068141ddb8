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

/// How many positions each pixel of an eye image averages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// Positions along each side of a pixel the object cannot cover.
    pub per_side: u32,
    /// Where the object is, for pixels that need more positions.
    pub near_object: Option<NearObject>,
}

/// Pixels the object may cover take more positions: behind glass the light changes within a
/// pixel far faster than across a photo (a thin wall, a stem two pixels wide, an outline), and
/// a reference must be closer to the real object than anything it judges (the GPU's glass
/// averages up to 4 x 4 positions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearObject {
    /// The centre of a sphere holding the object, metres.
    pub center_m: Vec3,
    /// Its radius, metres.
    pub radius_m: f32,
    /// Positions along each side of a pixel whose view of that sphere (widened by the pixel's
    /// own width there) it touches.
    pub per_side: u32,
}

impl Sampling {
    /// `n` x `n` positions in every pixel.
    pub fn uniform(n: u32) -> Sampling {
        Sampling {
            per_side: n,
            near_object: None,
        }
    }
}

impl From<u32> for Sampling {
    fn from(n: u32) -> Sampling {
        Sampling::uniform(n)
    }
}

/// Renders `window` of a `size` eye image of `camera` (`size` pixels, x right, y down), each
/// pixel averaged over a regular grid of positions inside it: `sampling.per_side` squared, or
/// `near_object.per_side` squared where the object may lie in the pixel.
pub fn render_eye(
    world: &World,
    camera: &EyeParams,
    size: (u32, u32),
    window: Window,
    sampling: impl Into<Sampling>,
) -> EyeImage {
    let sampling = sampling.into();
    let rays = camera.pixel_rays(Vec2::new(size.0 as f32, size.1 as f32));
    let near = |x: u32, y: u32| {
        sampling.near_object.is_some_and(|o| {
            let centre = Vec2::new(x as f32, y as f32) + 0.5;
            let dir = rays.direction(centre);
            // The pixel's diagonal as an angle, times the distance: its width at the object.
            let across = (rays.direction(centre + 0.5) - rays.direction(centre - 0.5)).length();
            let to_centre = o.center_m - camera.position_m;
            let along = to_centre.dot(dir);
            let off = (to_centre - dir * along).length();
            along > -o.radius_m && off < o.radius_m + across * to_centre.length()
        })
    };
    let rows: Vec<Vec<Vec3>> = (window.y..window.y + window.height)
        .into_par_iter()
        .map(|y| {
            (window.x..window.x + window.width)
                .map(|x| {
                    let n = match sampling.near_object {
                        Some(o) if near(x, y) => o.per_side,
                        _ => sampling.per_side,
                    }
                    .max(1);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Glass, Picture};
    use glam::Quat;
    use vitreous_optics::absorption::Attenuation;
    use vitreous_optics::camera::Fov;

    #[test]
    fn pixels_the_object_may_cover_take_its_positions_and_the_rest_the_others() {
        // A ball before a striped environment (the stripes change within a pixel, so the
        // positions taken show in every pixel), seen by a 10-degree camera over 24 x 24 pixels.
        let center = Vec3::new(0.01, 0.0, -1.0);
        let world = World {
            floor: None,
            background: None,
            environment: Some(Picture::from_fn(512, 256, |x, _| {
                Vec3::splat(if x % 2 == 0 { 0.9 } else { 0.1 })
            })),
            glass: Some(Glass::ball(center, 0.03, 1.5, Attenuation::NONE)),
            light_m: Vec3::Y,
            light_share: 1.0,
            floor_light: None,
        };
        let half = 5f32.to_radians();
        let camera = EyeParams::new(
            Vec3::ZERO,
            Quat::IDENTITY,
            Fov {
                left_rad: -half,
                right_rad: half,
                up_rad: half,
                down_rad: -half,
            },
        );
        let size = (24, 24);
        let window = Window {
            x: 0,
            y: 0,
            width: 24,
            height: 24,
        };
        let sampling = Sampling {
            per_side: 1,
            near_object: Some(NearObject {
                center_m: center,
                radius_m: 0.03,
                per_side: 6,
            }),
        };
        let mixed = render_eye(&world, &camera, size, window, sampling);
        let fine = render_eye(&world, &camera, size, window, 6);
        let coarse = render_eye(&world, &camera, size, window, 1);
        let seen = render_eye(&world.without_object(), &camera, size, window, 6);
        let (mut near, mut away) = (0, 0);
        for y in 0..24 {
            for x in 0..24 {
                let m = mixed.at(x, y);
                // Every pixel the ball reaches at any of 6 x 6 positions is averaged as finely.
                if fine.at(x, y) != seen.at(x, y) {
                    assert_eq!(m, fine.at(x, y), "pixel ({x}, {y}) shows the ball");
                }
                if m == fine.at(x, y) && m != coarse.at(x, y) {
                    near += 1;
                } else {
                    assert_eq!(m, coarse.at(x, y), "pixel ({x}, {y})");
                    away += 1;
                }
            }
        }
        // The ball (3.4 degrees across) covers about a ninth of the view: the rest stays coarse.
        assert!(near > 40 && away > 400, "{near} pixels near, {away} away");
    }
}
