//! The wearer's view of what the app submitted (`VITREOUS_SIM_WORLD`): the session's last frame
//! over a picture of the real world, as the wearer would see it (`wearer-left.png`,
//! `wearer-right.png`): on `ALPHA_BLEND` the world dimmed by a segmented dimmer panel
//! ([`crate::config::SimPanel`]: each cell takes away the mean alpha of its pixels, seen through
//! a Gaussian blur) and the image's premultiplied light added; on `ADDITIVE` the light added to
//! the world; on `OPAQUE` the image alone. With a registration error
//! (`VITREOUS_SIM_REGISTRATION`) the light and the panel land that far from the world, and the
//! view as it would be without one is written beside it.

use std::io;
use std::path::{Path, PathBuf};

use openxr::sys;

use crate::config::SimPanel;
use crate::images::{ViewImage, srgb_to_linear};

fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The share of the world's light the panel takes away at each pixel of a `view`-sized image:
/// each cell's mean alpha, blurred by a Gaussian of the panel's blur over the cells, read
/// between cell centres.
pub fn panel_darkening(view: &ViewImage, panel: &SimPanel) -> Vec<f32> {
    let (w, h) = (view.size.0 as usize, view.size.1 as usize);
    let [cx, cy] = panel.cells.map(|c| c as usize);
    let mut cells = vec![0f32; cx * cy];
    let mut counts = vec![0u32; cx * cy];
    for y in 0..h {
        for x in 0..w {
            let c = (y * cy / h) * cx + x * cx / w;
            cells[c] += view.linear(x, y).1;
            counts[c] += 1;
        }
    }
    for (v, n) in cells.iter_mut().zip(&counts) {
        *v /= (*n).max(1) as f32;
    }
    // The blur in cells, across and down.
    let sigma = [0, 1].map(|a| panel.blur_deg * panel.cells[a] as f32 / view.fov_deg[a].max(1e-3));
    let blur = |values: &[f32], along_x: bool| -> Vec<f32> {
        let (n_along, n_other, s) = if along_x {
            (cx, cy, sigma[0])
        } else {
            (cy, cx, sigma[1])
        };
        if s < 1e-3 {
            return values.to_vec();
        }
        let reach = (3.0 * s).ceil() as isize;
        let weights: Vec<f32> = (-reach..=reach)
            .map(|k| (-(k as f32).powi(2) / (2.0 * s * s)).exp())
            .collect();
        let mut out = vec![0f32; values.len()];
        for o in 0..n_other {
            for i in 0..n_along {
                let (mut sum, mut total) = (0f32, 0f32);
                for (k, wgt) in (-reach..=reach).zip(&weights) {
                    let j = i as isize + k;
                    if j < 0 || j >= n_along as isize {
                        continue;
                    }
                    let idx = if along_x {
                        o * cx + j as usize
                    } else {
                        j as usize * cx + o
                    };
                    sum += values[idx] * wgt;
                    total += wgt;
                }
                let idx = if along_x { o * cx + i } else { i * cx + o };
                out[idx] = sum / total;
            }
        }
        out
    };
    let cells = blur(&blur(&cells, true), false);
    let at = |x: isize, y: isize| {
        cells[y.clamp(0, cy as isize - 1) as usize * cx + x.clamp(0, cx as isize - 1) as usize]
    };
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let fy = (y as f32 + 0.5) * cy as f32 / h as f32 - 0.5;
        let (y0, ty) = (fy.floor() as isize, fy - fy.floor());
        for x in 0..w {
            let fx = (x as f32 + 0.5) * cx as f32 / w as f32 - 0.5;
            let (x0, tx) = (fx.floor() as isize, fx - fx.floor());
            let top = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
            let bottom = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
            out.push(top * (1.0 - ty) + bottom * ty);
        }
    }
    out
}

/// What the wearer sees of `view` over `world` (8-bit sRGB RGB, any size, scaled to the
/// view's) with the view's light and panel landing `registration_deg` (right, down; to the
/// nearest pixel) from where the world is: 8-bit sRGB RGB of the view's size.
pub fn wearer_view(
    view: &ViewImage,
    blend: sys::EnvironmentBlendMode,
    world: &image::RgbImage,
    panel: &SimPanel,
    registration_deg: [f32; 2],
) -> Vec<u8> {
    let (w, h) = (view.size.0 as usize, view.size.1 as usize);
    let darkening =
        (blend == sys::EnvironmentBlendMode::ALPHA_BLEND).then(|| panel_darkening(view, panel));
    let keeps_world = blend != sys::EnvironmentBlendMode::OPAQUE;
    let (ww, wh) = world.dimensions();
    // The view's pixel that lands on each of the world's, or none beyond the view's edge.
    let shift = [0, 1].map(|a| {
        (registration_deg[a] * [w, h][a] as f32 / view.fov_deg[a].max(1e-3)).round() as i64
    });
    let from = |x: usize, y: usize| {
        let (sx, sy) = (x as i64 - shift[0], y as i64 - shift[1]);
        (sx >= 0 && sy >= 0 && sx < w as i64 && sy < h as i64).then_some((sx as usize, sy as usize))
    };
    let mut out = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let source = from(x, y);
            let light = source.map_or([0.0; 3], |(sx, sy)| view.linear(sx, sy).0);
            let seen = if keeps_world {
                let p = world.get_pixel(
                    ((x * ww as usize) / w) as u32,
                    ((y * wh as usize) / h) as u32,
                );
                let kept = match (&darkening, source) {
                    (Some(d), Some((sx, sy))) => 1.0 - d[sy * w + sx],
                    _ => 1.0,
                };
                p.0.map(|v| srgb_to_linear(f32::from(v) / 255.0) * kept)
            } else {
                [0.0; 3]
            };
            for c in 0..3 {
                out.push((linear_to_srgb(seen[c] + light[c]) * 255.0 + 0.5) as u8);
            }
        }
    }
    out
}

/// Writes each of the last frame's views as the wearer sees it over `world` into `dir`
/// (`wearer-left.png`, `wearer-right.png`, then `wearer-view2.png`, ...), each whole or not at
/// all.
pub fn write_wearer_views(
    dir: &Path,
    world: &Path,
    views: &[ViewImage],
    blend: sys::EnvironmentBlendMode,
    panel: &SimPanel,
    registration_deg: [f32; 2],
) -> Result<Vec<PathBuf>, String> {
    let world = image::open(world)
        .map_err(|e| format!("reading the world picture {}: {e}", world.display()))?
        .to_rgb8();
    let mut written = Vec::new();
    // With a registration error, also the view as it would be without one, beside it.
    let errors: &[([f32; 2], &str)] = if registration_deg == [0.0, 0.0] {
        &[([0.0, 0.0], "")]
    } else {
        &[(registration_deg, ""), ([0.0, 0.0], "-registered")]
    };
    for (i, view) in views.iter().enumerate() {
        for &(error, suffix) in errors {
            written.push(write_wearer_view(
                dir, i, suffix, view, blend, &world, panel, error,
            )?);
        }
    }
    Ok(written)
}

/// Writes view `i` as the wearer sees it with the registration error `error_deg`, named
/// `wearer-left{suffix}.png`, `wearer-right{suffix}.png`, `wearer-view2{suffix}.png`, ....
#[allow(clippy::too_many_arguments)]
fn write_wearer_view(
    dir: &Path,
    i: usize,
    suffix: &str,
    view: &ViewImage,
    blend: sys::EnvironmentBlendMode,
    world: &image::RgbImage,
    panel: &SimPanel,
    error_deg: [f32; 2],
) -> Result<PathBuf, String> {
    {
        let name = match i {
            0 => format!("wearer-left{suffix}.png"),
            1 => format!("wearer-right{suffix}.png"),
            n => format!("wearer-view{n}{suffix}.png"),
        };
        let rgb = wearer_view(view, blend, world, panel, error_deg);
        let picture = image::RgbImage::from_raw(view.size.0, view.size.1, rgb)
            .ok_or("a wearer's view of the wrong size")?;
        let mut png = Vec::new();
        picture
            .write_to(&mut io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| format!("encoding {name}: {e}"))?;
        let path = dir.join(&name);
        vitreous_trace::atomic_file::write(&path, &png)
            .map_err(|e| format!("writing {}: {e}", path.display()))?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sharp_panel_takes_away_each_cells_mean_alpha() {
        // One alpha-1 pixel per 2 x 2 cell of a 32 x 24 panel: every cell a quarter.
        let v = ViewImage::test_view(|x, y| if x % 2 == 0 && y % 2 == 0 { 255 } else { 0 }, 0);
        let sharp = SimPanel {
            cells: [32, 24],
            blur_deg: 0.0,
        };
        for d in panel_darkening(&v, &sharp) {
            assert!((d - 0.25).abs() < 1e-6, "{d}");
        }
    }

    #[test]
    fn a_blurred_panel_spreads_the_darkening_and_keeps_its_total() {
        let v = ViewImage::test_view(|x, y| if x == 32 && y == 24 { 255 } else { 0 }, 0);
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        let soft = SimPanel {
            cells: [64, 48],
            blur_deg: 2.0,
        };
        let (a, b) = (panel_darkening(&v, &sharp), panel_darkening(&v, &soft));
        let (sa, sb): (f32, f32) = (a.iter().sum(), b.iter().sum());
        assert!(
            (sa - 1.0).abs() < 1e-4 && (sb - 1.0).abs() < 0.02,
            "{sa} {sb}"
        );
        // Spread: a neighbour 3 cells away gets some, less than the centre.
        let at = |d: &[f32], x: usize, y: usize| d[y * 64 + x];
        assert_eq!(at(&a, 35, 24), 0.0);
        assert!(at(&b, 35, 24) > 0.0 && at(&b, 35, 24) < at(&b, 32, 24));
    }

    #[test]
    fn the_wearer_sees_the_world_dimmed_where_the_alpha_asks_and_the_light_added() {
        let world = image::RgbImage::from_pixel(8, 8, image::Rgb([188, 188, 188]));
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        // Half the pixels alpha 1 with no light: black there on ALPHA_BLEND; the world
        // elsewhere; the world plus the light on ADDITIVE.
        let v = ViewImage::test_view(|x, _| if x < 32 { 255 } else { 0 }, 0);
        let seen = wearer_view(
            &v,
            sys::EnvironmentBlendMode::ALPHA_BLEND,
            &world,
            &sharp,
            [0.0; 2],
        );
        assert_eq!(seen[0], 0);
        assert_eq!(seen[(10 * 64 + 40) * 3], 188);
        let lit = ViewImage::test_view(|_, _| 0, 64);
        let added = wearer_view(
            &lit,
            sys::EnvironmentBlendMode::ADDITIVE,
            &world,
            &sharp,
            [0.0; 2],
        );
        assert!(added[0] > 188);
        // The image alone: linear 64/255 is sRGB 137.
        let opaque = wearer_view(
            &lit,
            sys::EnvironmentBlendMode::OPAQUE,
            &world,
            &sharp,
            [0.0; 2],
        );
        assert_eq!(opaque[0], 137);
    }

    #[test]
    fn a_registration_error_moves_the_dimmed_patch_with_the_light_and_leaves_the_world() {
        let world = image::RgbImage::from_pixel(64, 48, image::Rgb([188, 188, 188]));
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        // Alpha 1 over x 20..30: the panel's dark patch; 64 px over 40 degrees, so 5 degrees
        // right is 8 px.
        let v = ViewImage::test_view(|x, _| if (20..30).contains(&x) { 255 } else { 0 }, 0);
        let blend = sys::EnvironmentBlendMode::ALPHA_BLEND;
        let at = |img: &[u8], x: usize| img[(10 * 64 + x) * 3];
        let registered = wearer_view(&v, blend, &world, &sharp, [0.0; 2]);
        let shifted = wearer_view(&v, blend, &world, &sharp, [5.0, 0.0]);
        assert_eq!((at(&registered, 20), at(&registered, 29)), (0, 0));
        assert_eq!((at(&shifted, 20), at(&shifted, 27)), (188, 188));
        assert_eq!((at(&shifted, 28), at(&shifted, 37)), (0, 0));
        assert_eq!(at(&shifted, 38), 188);
        // Beyond the view's edge the display has nothing: the world as it is.
        assert_eq!(at(&shifted, 3), 188);
    }

    #[test]
    fn with_a_registration_error_the_registered_view_is_written_beside_it() {
        let dir = tempfile::tempdir().unwrap();
        let world = dir.path().join("world.png");
        image::RgbImage::from_pixel(8, 8, image::Rgb([188, 188, 188]))
            .save(&world)
            .unwrap();
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        let v = ViewImage::test_view(|x, _| if (20..30).contains(&x) { 255 } else { 0 }, 0);
        let blend = sys::EnvironmentBlendMode::ALPHA_BLEND;
        let names = |error| {
            write_wearer_views(
                dir.path(),
                &world,
                std::slice::from_ref(&v),
                blend,
                &sharp,
                error,
            )
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
        };
        assert_eq!(names([0.0, 0.0]), ["wearer-left.png"]);
        assert_eq!(
            names([5.0, 0.0]),
            ["wearer-left.png", "wearer-left-registered.png"]
        );
        let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
        assert_ne!(read("wearer-left.png"), read("wearer-left-registered.png"));
    }
}
