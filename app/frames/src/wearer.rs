//! What the wearer sees: the display's light over the real world as the headset passes it. An
//! additive display passes all of the world and adds its light; a global dimmer
//! (`[display] global_dimmer`) takes away its share of the world everywhere; a segmented dimmer
//! (`[display] model = "dimmer"`) takes away, under each of its cells, the mean alpha of the
//! eye image's pixels there (as a runtime would drive it), seen through the panel's blur
//! (vitreous_optics::display::dimmer).

use vitreous_optics::display::dimmer::{DimmerDesc, Panel};

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
}
