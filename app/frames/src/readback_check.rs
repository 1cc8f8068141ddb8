//! The readback check (`vitreous run --readback-check`): one submitted swapchain image read
//! back; the object's projected disc is searched for lit pixels (the run drew the object where
//! the headset looks), and the pixels away from it are checked against what the blend mode
//! needs there: black on ADDITIVE and ALPHA_BLEND (nothing added to the world), the scene's
//! real-world photos on OPAQUE; on ALPHA_BLEND every pixel's alpha must be 0 (premultiplied
//! colour over alpha 0, so the world shows through), unless the scene drives a segmented
//! dimmer: then the alpha must be above 0 where the object and its shadow are, and 0 (with
//! nothing drawn) away from both, past the panel's reach around them.
//!
//! At the run's end the check also reads back where the shadow and the caustic lie on the
//! floor ([`FloorCentroids`]), for a check against an independent computation of both.

use anyhow::Result;
use glam::{DVec2, Vec3};
use serde::Serialize;
use vitreous_render::Renderer;
use vitreous_trace::Blend;
use vitreous_trace::FrameInput;

/// What the readback of a submitted swapchain image showed.
#[derive(Clone, Debug, Serialize)]
pub struct ReadbackCheck {
    /// Index of the frame read back.
    pub frame: u64,
    /// The blend mode the image was composed for.
    pub blend: String,
    /// Pixels (both eyes) inside the object's projected disc.
    pub region_px: u64,
    /// Of those, pixels where the submitted image differs from the real world alone (or from
    /// black, on a see-through display) by more than [`LIT_THRESHOLD`] in some channel.
    pub object_px: u64,
    /// `object_px / region_px`.
    pub object_fraction: f64,
    /// Mean sRGB value (0-255) of the submitted image inside the region.
    pub mean_value: f64,
    /// Pixels (both eyes) away from the object: outside [`AWAY_RADII`] times its disc.
    pub away_px: u64,
    /// Share of those showing what the blend mode needs there (within [`LIT_THRESHOLD`]):
    /// black (ADDITIVE, ALPHA_BLEND) or the real-world photos (OPAQUE).
    pub away_fraction: f64,
    /// Pixels (both eyes) whose alpha is not 0 (must be none on ALPHA_BLEND without a dimmer).
    pub alpha_nonzero_px: u64,
    /// Of the pixels away from the object, those whose alpha is not 0 (must be none).
    pub alpha_away_px: u64,
    /// With a dimmer: the alpha (0-255) at each point that must be dimmed (the object's
    /// centre, then the centre of its shadow), left eye then right.
    pub dimmed_points_alpha: Vec<u8>,
    /// Whether the check passed: the object shows (`object_fraction >=
    /// MIN_OBJECT_FRACTION`), the pixels away from it are as the blend mode needs
    /// (`away_fraction >= MIN_AWAY_FRACTION`), and on ALPHA_BLEND no alpha is above 0.
    pub passed: bool,
}

impl ReadbackCheck {
    /// An error saying what the check found, unless it [`passed`](Self::passed); `blend` is
    /// the blend mode the image was composed for.
    pub fn verdict(&self, blend: Blend) -> anyhow::Result<()> {
        let c = self;
        if c.passed {
            return Ok(());
        }
        anyhow::bail!(
            "readback check failed ({} blend): frame {} shows the object in {:.1} % of its \
             region ({} of {} px; expected at least {:.0} %), {:.1} % of the pixels away \
             from it as the blend mode needs (expected at least {:.0} %: {}), {} px with \
             alpha above 0{}",
            c.blend,
            c.frame,
            c.object_fraction * 100.0,
            c.object_px,
            c.region_px,
            MIN_OBJECT_FRACTION * 100.0,
            c.away_fraction * 100.0,
            MIN_AWAY_FRACTION * 100.0,
            if blend.needs_world_behind() {
                "the real-world photos"
            } else {
                "black"
            },
            c.alpha_nonzero_px,
            match (blend.uses_source_alpha(), c.dimmed_points_alpha.is_empty()) {
                (true, true) => " (expected none)".to_owned(),
                (true, false) => format!(
                    " ({} of them away from it, expected none; the dimmer's alpha at the \
                     object's and its shadow's centres {:?}, expected above 0)",
                    c.alpha_away_px, c.dimmed_points_alpha
                ),
                (false, _) => String::new(),
            }
        )
    }
}

/// How different (sRGB steps) a pixel must be to count as the object's.
pub const LIT_THRESHOLD: u8 = 8;
/// Share of the object's region that must show it.
pub const MIN_OBJECT_FRACTION: f64 = 0.2;
/// Pixels farther than this many object radii from its projected centre are "away" from it.
pub const AWAY_RADII: f32 = 2.0;
/// Share of the pixels away from the object that must show what the blend mode needs (the
/// rest: the light the shadow inducer and the caustics add to the floor around the object).
pub const MIN_AWAY_FRACTION: f64 = 0.8;

/// What a segmented dimmer must darken: world points (the object's centre, its shadow's), and
/// the panel.
#[derive(Clone, Debug)]
pub struct Dimmed {
    /// The points.
    pub points: Vec<glam::Vec3>,
    /// The panel.
    pub panel: vitreous_optics::display::dimmer::DimmerDesc,
}

/// Checks a readback of both eyes (see [`ReadbackCheck`]); `rb.world` (the real world alone)
/// is what OPAQUE must show away from the object. `dimmed` is what a segmented dimmer must
/// darken (the scene has one; it counts only on ALPHA_BLEND): then a pixel is away when it lies
/// outside the rectangle of [`AWAY_RADII`] object radii and the panel's reach (with a cell)
/// around every point.
pub fn check_readback(
    input: &FrameInput,
    rb: &vitreous_render::Readback,
    center_m: glam::Vec3,
    radius_m: f32,
    blend: Blend,
    dimmed: Option<&Dimmed>,
) -> ReadbackCheck {
    let world_behind = blend.needs_world_behind();
    let dimmed = dimmed.filter(|_| blend.uses_source_alpha());
    let mut alpha_away = 0u64;
    let mut dimmed_points_alpha = Vec::new();
    let (w, h) = (rb.width as usize, rb.height as usize);
    let (mut region, mut object, mut sum) = (0u64, 0u64, 0f64);
    let (mut away, mut away_ok, mut alpha_nonzero) = (0u64, 0u64, 0u64);
    for eye in 0..2 {
        let view = &input.views[eye];
        let image = &rb.eyes[eye];
        let world = rb.world.as_ref().map(|wv| &wv[eye]);
        let (l, r) = (
            view.fov.angle_left_rad.tan(),
            view.fov.angle_right_rad.tan(),
        );
        let (d, u) = (view.fov.angle_down_rad.tan(), view.fov.angle_up_rad.tan());
        // A world point in the eye frame, projected with the eye's (asymmetric) fov: its
        // pixel coordinates and distance; none behind the eye.
        let project = |world: glam::Vec3| {
            let p = view.pose.orientation.conjugate() * (world - view.pose.position);
            (p.z < -1e-4).then(|| {
                let (x, y) = (p.x / -p.z, p.y / -p.z);
                (
                    (x - l) / (r - l) * w as f32,
                    (u - y) / (u - d) * h as f32,
                    p.length(),
                )
            })
        };
        // The object's disc; behind the eye there is none and every pixel is away from it.
        let disc = project(center_m).map(|(px, py, dist)| {
            let rad = (radius_m / dist).min(1.0).asin().tan();
            (px, py, rad / (r - l) * w as f32, rad / (u - d) * h as f32)
        });
        // The dimmer's points in pixels, and how far from them (across, down) its panel may
        // darken: the object's radius times AWAY_RADII and the panel's reach with one cell
        // more.
        let mut dark = Vec::new();
        if let Some(dimmed) = dimmed {
            let fov_deg = [r.atan() - l.atan(), u.atan() - d.atan()].map(f32::to_degrees);
            let panel = vitreous_optics::display::dimmer::Panel::new(&dimmed.panel, fov_deg);
            // The panel darkens squares of cells: how far, in pixels, across and down.
            let reach = [0, 1]
                .map(|a| (panel.reach()[a] + 1) as f32 * [w, h][a] as f32 / panel.cells[a] as f32);
            for &point in &dimmed.points {
                let at = project(point);
                let alpha = at
                    .filter(|&(x, y, _)| x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32)
                    .map_or(0, |(x, y, _)| {
                        image[((y as usize) * w + x as usize) * 4 + 3]
                    });
                dimmed_points_alpha.push(alpha);
                if let Some((x, y, dist)) = at {
                    let rad = (radius_m / dist).min(1.0).asin().tan();
                    let (rx, ry) = (rad / (r - l) * w as f32, rad / (u - d) * h as f32);
                    dark.push((x, y, AWAY_RADII * rx + reach[0], AWAY_RADII * ry + reach[1]));
                }
            }
        }
        for row in 0..h {
            for col in 0..w {
                let i = (row * w + col) * 4;
                let got = &image[i..i + 3];
                if image[i + 3] != 0 {
                    alpha_nonzero += 1;
                }
                let r2 = disc.map_or(f32::INFINITY, |(px, py, rx, ry)| {
                    let dx = (col as f32 + 0.5 - px) / rx;
                    let dy = (row as f32 + 0.5 - py) / ry;
                    dx * dx + dy * dy
                });
                let like_world = |wv: &Vec<u8>| {
                    got.iter()
                        .zip(&wv[i..i + 3])
                        .all(|(&a, &b)| a.abs_diff(b) <= LIT_THRESHOLD)
                };
                let (x, y) = (col as f32 + 0.5, row as f32 + 0.5);
                let past_dimmer = dark
                    .iter()
                    .all(|&(px, py, fx, fy)| (x - px).abs() > fx || (y - py).abs() > fy);
                if r2 > AWAY_RADII * AWAY_RADII && past_dimmer {
                    away += 1;
                    if image[i + 3] != 0 {
                        alpha_away += 1;
                    }
                    let ok = match (world_behind, world) {
                        (true, Some(wv)) => like_world(wv),
                        (true, None) => false,
                        (false, _) => got.iter().all(|&a| a <= LIT_THRESHOLD),
                    };
                    if ok {
                        away_ok += 1;
                    }
                }
                if r2 > 1.0 {
                    continue;
                }
                region += 1;
                sum += got.iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0;
                let lit = match (world_behind, world) {
                    (true, Some(wv)) => !like_world(wv),
                    _ => got.iter().any(|&a| a > LIT_THRESHOLD),
                };
                if lit {
                    object += 1;
                }
            }
        }
    }
    let share = |n: u64, of: u64| if of == 0 { 0.0 } else { n as f64 / of as f64 };
    let object_fraction = share(object, region);
    let away_fraction = share(away_ok, away);
    let alpha_ok = if dimmed.is_some() {
        alpha_away == 0 && dimmed_points_alpha.iter().all(|&a| a > 0)
    } else {
        !blend.uses_source_alpha() || alpha_nonzero == 0
    };
    ReadbackCheck {
        frame: input.index,
        blend: blend.to_string(),
        region_px: region,
        object_px: object,
        object_fraction,
        mean_value: if region == 0 {
            0.0
        } else {
            sum / region as f64
        },
        away_px: away,
        away_fraction,
        alpha_nonzero_px: alpha_nonzero,
        alpha_away_px: alpha_away,
        dimmed_points_alpha,
        passed: region > 0
            && object_fraction >= MIN_OBJECT_FRACTION
            && away > 0
            && away_fraction >= MIN_AWAY_FRACTION
            && alpha_ok,
    }
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
    use crate::test_frame::test_frame as frame;

    const W: u32 = 32;
    const H: u32 = 32;

    /// An image of `background` with the pixels within 4 px of the centre `object`.
    fn image(background: [u8; 4], object: [u8; 4]) -> Vec<u8> {
        let mut out = Vec::new();
        for row in 0..H {
            for col in 0..W {
                let (dx, dy) = (col as f32 + 0.5 - 16.0, row as f32 + 0.5 - 16.0);
                out.extend(if dx * dx + dy * dy < 16.0 {
                    object
                } else {
                    background
                });
            }
        }
        out
    }

    fn readback(eye: Vec<u8>, world: Option<Vec<u8>>) -> vitreous_render::Readback {
        vitreous_render::Readback {
            width: W,
            height: H,
            eyes: [eye.clone(), eye],
            world: world.map(|w| [w.clone(), w]),
        }
    }

    /// The test frame's fov is 1 rad across 32 px: a 0.1 m object 1 m ahead covers a disc
    /// of about 3.2 px radius at the centre.
    const CENTER: glam::Vec3 = glam::Vec3::new(0.0, 0.0, -1.0);

    #[test]
    fn additive_needs_the_object_on_black() {
        let on_black = image([0, 0, 0, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(on_black, None),
            CENTER,
            0.1,
            Blend::Additive,
            None,
        );
        assert!(
            c.passed && c.object_px == c.region_px && c.away_fraction == 1.0,
            "{c:?}"
        );
        // The world drawn behind on an additive display: fails.
        let on_grey = image([128, 128, 128, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(on_grey, None),
            CENTER,
            0.1,
            Blend::Additive,
            None,
        );
        assert!(!c.passed && c.away_fraction == 0.0, "{c:?}");
        let dark = image([0, 0, 0, 255], [0, 0, 0, 255]);
        let c = check_readback(
            &frame(),
            &readback(dark, None),
            CENTER,
            0.1,
            Blend::Additive,
            None,
        );
        assert!(!c.passed && c.object_px == 0);
    }

    #[test]
    fn alpha_blend_needs_alpha_zero_everywhere() {
        let premultiplied = image([0, 0, 0, 0], [200, 200, 200, 0]);
        let c = check_readback(
            &frame(),
            &readback(premultiplied, None),
            CENTER,
            0.1,
            Blend::AlphaBlend,
            None,
        );
        assert!(c.passed && c.alpha_nonzero_px == 0, "{c:?}");
        // The same colour with opaque alpha would hide the world: fails.
        let opaque = image([0, 0, 0, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(opaque, None),
            CENTER,
            0.1,
            Blend::AlphaBlend,
            None,
        );
        assert!(
            !c.passed && c.alpha_nonzero_px == u64::from(2 * W * H),
            "{c:?}"
        );
    }

    fn dimmed_at(points: Vec<glam::Vec3>) -> Dimmed {
        Dimmed {
            points,
            panel: vitreous_optics::display::dimmer::DimmerDesc {
                cells: [16, 16],
                blur_deg: 1.0,
                max: 0.9,
                registration_error_deg: 0.0,
            },
        }
    }

    #[test]
    fn a_dimmer_needs_alpha_at_the_object_and_its_shadow_and_none_far_away() {
        // A 0.03 m object 1 m ahead: a disc of about 1 px radius; the image dims the 4 px
        // around it, where the shadow's point (1.6 px below) lies too. A panel of 16 x 16 cells
        // (2 px each) spreads a want one cell (with one more, 4 px): away is beyond about
        // 5 px.
        let dimmed = image([0, 0, 0, 0], [200, 200, 200, 180]);
        let shadow = glam::Vec3::new(0.0, -0.05, -1.0);
        let c = check_readback(
            &frame(),
            &readback(dimmed.clone(), None),
            CENTER,
            0.03,
            Blend::AlphaBlend,
            Some(&dimmed_at(vec![CENTER, shadow])),
        );
        assert!(c.passed && c.alpha_away_px == 0, "{c:?}");
        assert_eq!(c.dimmed_points_alpha, vec![180; 4]);
        // A shadow 10 px below, left undimmed: fails.
        let c = check_readback(
            &frame(),
            &readback(dimmed, None),
            CENTER,
            0.03,
            Blend::AlphaBlend,
            Some(&dimmed_at(vec![CENTER, glam::Vec3::new(0.0, -0.3, -1.0)])),
        );
        assert!(!c.passed, "a shadow left undimmed: {c:?}");
        // Alpha everywhere: far pixels dimmed too.
        let everywhere = image([0, 0, 0, 90], [200, 200, 200, 180]);
        let c = check_readback(
            &frame(),
            &readback(everywhere, None),
            CENTER,
            0.03,
            Blend::AlphaBlend,
            Some(&dimmed_at(vec![CENTER])),
        );
        assert!(!c.passed && c.alpha_away_px > 0, "{c:?}");
    }

    #[test]
    fn opaque_needs_the_world_photo_behind_the_object() {
        let world = image([90, 100, 110, 255], [90, 100, 110, 255]);
        let drawn = image([90, 100, 110, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(drawn, Some(world.clone())),
            CENTER,
            0.1,
            Blend::Opaque,
            None,
        );
        assert!(c.passed && c.away_fraction == 1.0, "{c:?}");
        let on_black = image([0, 0, 0, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(on_black, Some(world)),
            CENTER,
            0.1,
            Blend::Opaque,
            None,
        );
        assert!(!c.passed && c.away_fraction == 0.0, "{c:?}");
    }

    #[test]
    fn an_object_behind_the_viewer_fails() {
        let lit = image([200, 200, 200, 255], [200, 200, 200, 255]);
        let c = check_readback(
            &frame(),
            &readback(lit, None),
            glam::Vec3::new(0.0, 0.0, 1.0),
            0.1,
            Blend::Additive,
            None,
        );
        assert!(!c.passed && c.region_px == 0);
    }

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
