//! What the wearer sees: the display's light over the real world as the headset passes it. An
//! additive display passes all of the world and adds its light; a global dimmer
//! (`[display] global_dimmer`) takes away its share of the world everywhere; a segmented dimmer
//! (`[display] model = "dimmer"`) takes away, under each of its cells, the mean alpha of the
//! eye image's pixels there (as a runtime would drive it), seen through the panel's blur
//! (vitreous_optics::display::dimmer).

use glam::Vec2;
use vitreous_optics::display::dimmer::{DimmerDesc, Panel};
use vitreous_optics::display::registration::Misregistration;

/// What the wearer perceives: the display's light added to the real world's, in linear light
/// (an optical see-through display can only add). Both inputs and the output are sRGB RGBA8.
pub fn see_through(eye: &[u8], world: &[u8]) -> Vec<u8> {
    let lut: Vec<f32> = (0..=255u8).map(vitreous_optics::srgb::to_linear).collect();
    eye.chunks_exact(4)
        .zip(world.chunks_exact(4))
        .flat_map(|(e, w)| {
            let add = |c: usize| {
                vitreous_optics::srgb::from_linear(lut[e[c] as usize] + lut[w[c] as usize])
            };
            [add(0), add(1), add(2), 255]
        })
        .collect()
}

/// The scene's field of view, degrees across and down.
pub fn scene_fov_deg(scene: &vitreous_scene::Scene) -> [f32; 2] {
    let fov = scene.output.fov;
    [
        (fov.angle_right_rad - fov.angle_left_rad).to_degrees(),
        (fov.angle_up_rad - fov.angle_down_rad).to_degrees(),
    ]
}

/// How the display composes its light with the real world for the eye.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WearerView {
    /// The segmented dimmer's panel, if the display has one.
    pub panel: Option<Panel>,
    /// The share of the world the global dimmer takes away everywhere (0 none).
    pub global_dimmer: f32,
}

impl WearerView {
    /// An additive display without dimming: light added to the whole world.
    pub fn additive() -> WearerView {
        WearerView::default()
    }

    /// The display `dimmer` and `global_dimmer` describe, for a view `fov_deg` wide and high.
    pub fn new(dimmer: Option<DimmerDesc>, global_dimmer: Option<f32>, fov_deg: [f32; 2]) -> Self {
        WearerView {
            panel: dimmer.map(|d| Panel::new(&d, fov_deg)),
            global_dimmer: global_dimmer.unwrap_or(0.0),
        }
    }

    /// The display `scene` describes (`[display]`), for the scene's own field of view.
    pub fn of_scene(scene: &vitreous_scene::Scene) -> WearerView {
        WearerView::new(scene.dimmer, scene.global_dimmer, scene_fov_deg(scene))
    }

    /// Whether the display takes any of the real world away (a dimmer of either kind).
    pub fn dims(&self) -> bool {
        self.panel.is_some() || self.global_dimmer > 0.0
    }

    /// The share of the real world the eye receives at each pixel of a `size` image whose
    /// display light is `eye` (sRGB RGBA8, alpha the share the segmented dimmer takes away).
    pub fn passed(&self, eye: &[u8], size: [u32; 2]) -> Vec<f32> {
        let pass = 1.0 - self.global_dimmer;
        let Some(panel) = self.panel else {
            return vec![pass; eye.len() / 4];
        };
        let alpha: Vec<f32> = eye
            .chunks_exact(4)
            .map(|p| f32::from(p[3]) / 255.0)
            .collect();
        let soft = panel.soften(&panel.from_alpha(&alpha, size));
        (0..eye.len() / 4)
            .map(|i| {
                let (x, y) = (i as u32 % size[0], i as u32 / size[0]);
                pass * (1.0 - panel.at_pixel(&soft, x, y, size))
            })
            .collect()
    }

    /// The real world `world` (sRGB RGBA8) as the eye receives it through the display whose
    /// light is `eye`: sRGB RGBA8, opaque.
    pub fn dimmed_world(&self, eye: &[u8], world: &[u8], size: [u32; 2]) -> Vec<u8> {
        let passed = self.passed(eye, size);
        world
            .chunks_exact(4)
            .zip(&passed)
            .flat_map(|(w, &p)| {
                let c = |c: usize| {
                    vitreous_optics::srgb::from_linear(p * vitreous_optics::srgb::to_linear(w[c]))
                };
                [c(0), c(1), c(2), 255]
            })
            .collect()
    }

    /// What the eye sees of `eye` (the display's light, sRGB RGBA8, alpha the share the dimmer
    /// takes away) over `world` (the real world, sRGB RGBA8), both `size` pixels: sRGB RGBA8.
    pub fn see(&self, eye: &[u8], world: &[u8], size: [u32; 2]) -> Vec<u8> {
        if !self.dims() {
            return see_through(eye, world);
        }
        // One rounding to 8 bits, of the sum: the dimmed world is not rounded on its own.
        let lut: Vec<f32> = (0..=255u8).map(vitreous_optics::srgb::to_linear).collect();
        let passed = self.passed(eye, size);
        eye.chunks_exact(4)
            .zip(world.chunks_exact(4))
            .zip(&passed)
            .flat_map(|((e, w), &p)| {
                let c = |c: usize| {
                    vitreous_optics::srgb::from_linear(lut[e[c] as usize] + p * lut[w[c] as usize])
                };
                [c(0), c(1), c(2), 255]
            })
            .collect()
    }
}

impl WearerView {
    /// What the eye sees of `eye` over `world` (as [`WearerView::see`]) when the display's light
    /// and its panel land `error` away from where they belong, at `ppd` pixels per degree:
    /// every pixel of the world meets the display's light and panel of the point
    /// [`Misregistration::display_point`] gives (bilinear between pixels; beyond the display's
    /// edge no light and no panel).
    pub fn see_misregistered(
        &self,
        eye: &[u8],
        world: &[u8],
        size: [u32; 2],
        error: &Misregistration,
        ppd: f32,
    ) -> Vec<u8> {
        if error.is_none() {
            return self.see(eye, world, size);
        }
        let lut: Vec<f32> = (0..=255u8).map(vitreous_optics::srgb::to_linear).collect();
        let passed = self.passed(eye, size);
        let outside = 1.0 - self.global_dimmer;
        let [w, h] = size;
        // The display's light (linear RGB) and the share of the world it passes at pixel i.
        let texel = |x: i64, y: i64| -> [f32; 4] {
            if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
                return [0.0, 0.0, 0.0, outside];
            }
            let i = (y as usize) * w as usize + x as usize;
            let e = &eye[i * 4..i * 4 + 3];
            [
                lut[e[0] as usize],
                lut[e[1] as usize],
                lut[e[2] as usize],
                passed[i],
            ]
        };
        let mut out = Vec::with_capacity(world.len());
        for (i, px) in world.chunks_exact(4).enumerate() {
            let (x, y) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
            let p = error.display_point(Vec2::new(x, y), size, ppd) - Vec2::splat(0.5);
            let (x0, y0) = (p.x.floor(), p.y.floor());
            let (fx, fy) = (p.x - x0, p.y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let mut sum = [0.0f32; 4];
            for (dx, dy, weight) in [
                (0, 0, (1.0 - fx) * (1.0 - fy)),
                (1, 0, fx * (1.0 - fy)),
                (0, 1, (1.0 - fx) * fy),
                (1, 1, fx * fy),
            ] {
                if weight > 0.0 {
                    let t = texel(x0 + dx, y0 + dy);
                    for (s, v) in sum.iter_mut().zip(t) {
                        *s += weight * v;
                    }
                }
            }
            let c = |c: usize| {
                vitreous_optics::srgb::from_linear(sum[c] + sum[3] * lut[px[c] as usize])
            };
            out.extend([c(0), c(1), c(2), 255]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_additive_display_adds_and_a_global_dimmer_dims_the_world_only() {
        let eye = [0u8, 0, 0, 0, 255, 255, 255, 0];
        let world = [128u8, 128, 128, 255, 0, 0, 0, 255];
        let plain = WearerView::additive().see(&eye, &world, [2, 1]);
        assert_eq!(plain, see_through(&eye, &world));
        let dimmed = WearerView::new(None, Some(0.5), [40.0, 30.0]).see(&eye, &world, [2, 1]);
        // Half the world's light (0.216 linear -> 0.108) and all the display's.
        assert_eq!(
            dimmed[0],
            vitreous_optics::srgb::from_linear(0.5 * vitreous_optics::srgb::to_linear(128))
        );
        assert_eq!(&dimmed[4..7], &[255, 255, 255]);
    }

    #[test]
    fn the_eye_sees_the_sum_rounded_once() {
        // A dark world pixel half passed, plus a little display light: rounding the dimmed
        // world to 8 bits first would lose the half step the sum keeps.
        let eye = [1u8, 1, 1, 0];
        let world = [27u8, 27, 27, 255];
        let seen = WearerView::new(None, Some(0.5), [40.0, 30.0]).see(&eye, &world, [1, 1]);
        let want = vitreous_optics::srgb::from_linear(
            vitreous_optics::srgb::to_linear(1) + 0.5 * vitreous_optics::srgb::to_linear(27),
        );
        assert_eq!(seen[..3], [want; 3]);
        let rounded_twice = see_through(
            &eye,
            &WearerView::new(None, Some(0.5), [40.0, 30.0]).dimmed_world(&eye, &world, [1, 1]),
        );
        assert_ne!(rounded_twice[0], want, "the case must tell the two apart");
    }

    #[test]
    fn a_dimmed_patch_darkens_the_world_with_a_soft_edge() {
        let desc = DimmerDesc {
            cells: [16, 12],
            blur_deg: 2.5,
            max: 1.0,
            registration_error_deg: 0.0,
        };
        let view = WearerView::new(Some(desc), None, [40.0, 30.0]);
        let (w, h) = (160u32, 120u32);
        // Alpha 1 over the middle 4 x 4 cells (pixels 60-99 across, 40-79 down).
        let mut eye = vec![0u8; (w * h * 4) as usize];
        for y in 40..80 {
            for x in 60..100 {
                eye[((y * w + x) * 4 + 3) as usize] = 255;
            }
        }
        let world = vec![200u8; (w * h * 4) as usize];
        let seen = view.see(&eye, &world, [w, h]);
        let at = |x: u32, y: u32| seen[((y * w + x) * 4) as usize];
        // The blur is one cell (2.5 degrees at 16 cells over 40): the middle keeps 9 % of the
        // world's light (two standard deviations each way), the edge more, and far away the
        // world is untouched.
        assert!(at(80, 60) < 80, "{}", at(80, 60));
        assert!(
            at(60, 60) > at(80, 60) && at(60, 60) < 200,
            "{}",
            at(60, 60)
        );
        assert_eq!(at(5, 5), 200);
    }

    #[test]
    fn a_misregistered_display_lands_its_light_and_panel_elsewhere() {
        let desc = DimmerDesc {
            cells: [16, 12],
            blur_deg: 0.5,
            max: 1.0,
            registration_error_deg: 0.0,
        };
        let view = WearerView::new(Some(desc), None, [40.0, 30.0]);
        let (w, h) = (160u32, 120u32);
        // A bright light and full alpha over the middle 4 x 4 cells (pixels 60-99, 40-79).
        let mut eye = vec![0u8; (w * h * 4) as usize];
        for y in 40..80 {
            for x in 60..100 {
                eye[((y * w + x) * 4) as usize..((y * w + x) * 4 + 4) as usize]
                    .copy_from_slice(&[250, 250, 250, 255]);
            }
        }
        let world = vec![100u8; (w * h * 4) as usize];
        let size = [w, h];
        let ppd = 4.0;
        let none = Misregistration::default();
        assert_eq!(
            view.see_misregistered(&eye, &world, size, &none, ppd),
            view.see(&eye, &world, size)
        );
        // Two degrees right (8 px): the light's left edge moves from x = 60 to 68.
        let right = Misregistration::new([2.0, 0.0], 0.0).unwrap();
        let moved = view.see_misregistered(&eye, &world, size, &right, ppd);
        let plain = view.see(&eye, &world, size);
        let at = |img: &[u8], x: u32, y: u32| img[((y * w + x) * 4) as usize];
        assert_eq!(at(&plain, 64, 60), 250);
        // There the world as it is now (the panel moved too), and the light 8 px further on.
        assert!(
            at(&moved, 64, 60).abs_diff(100) < 5,
            "{}",
            at(&moved, 64, 60)
        );
        assert_eq!(at(&moved, 72, 60), 250);
        assert!(at(&plain, 104, 60).abs_diff(100) < 5 && at(&moved, 104, 60) >= 250);
        // The shifted image is the plain one moved by 8 px, away from the edges.
        for y in 10..110 {
            for x in 20..140 {
                assert_eq!(at(&moved, x + 8, y), at(&plain, x, y), "{x} {y}");
            }
        }
    }
}
