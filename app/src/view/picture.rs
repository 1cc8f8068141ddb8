//! The window's picture: the eye images read back from the renderer (the display's light, or
//! the see-through preview as `replay` writes it), scaled into the window, with the overlay
//! text on top.

use vitreous_render::Readback;

use super::input::EyesShown;
use crate::font::TextBox;

/// Height of the overlay's text, pixels.
const TEXT_PX: f32 = 14.0;

/// Steps of the linear-light table used to encode the preview back to sRGB.
const LINEAR_STEPS: usize = 4096;

/// Lookup tables for adding the display's light to the world's in linear light.
pub struct SeeThrough {
    /// sRGB byte to linear light.
    to_linear: [f32; 256],
    /// Linear light 0..1 in [`LINEAR_STEPS`] steps to an sRGB byte.
    to_srgb: Vec<u8>,
}

impl SeeThrough {
    /// The tables.
    pub fn new() -> SeeThrough {
        let mut to_linear = [0.0; 256];
        for (i, v) in to_linear.iter_mut().enumerate() {
            *v = vitreous_optics::srgb::to_linear(i as u8);
        }
        let to_srgb = (0..=LINEAR_STEPS)
            .map(|i| vitreous_optics::srgb::from_linear(i as f32 / LINEAR_STEPS as f32))
            .collect();
        SeeThrough { to_linear, to_srgb }
    }

    /// One channel of display light `eye` added to world light `world` (both sRGB bytes).
    fn add(&self, eye: u8, world: u8) -> u8 {
        let sum = (self.to_linear[eye as usize] + self.to_linear[world as usize]).min(1.0);
        self.to_srgb[(sum * LINEAR_STEPS as f32 + 0.5) as usize]
    }
}

impl Default for SeeThrough {
    fn default() -> Self {
        SeeThrough::new()
    }
}

/// Fills `out` (RGBA8, `width` x `height`) with the eye images of `readback` as `eyes` says,
/// each scaled (nearest pixel) to its part of the window; with `preview`, the world views are
/// added in linear light.
pub fn compose(
    out: &mut [u8],
    width: u32,
    height: u32,
    readback: &Readback,
    eyes: EyesShown,
    preview: Option<&SeeThrough>,
    world: Option<&[Vec<u8>; 2]>,
) {
    let parts: &[(usize, u32, u32)] = match eyes {
        EyesShown::Both => &[(0, 0, width / 2), (1, width / 2, width - width / 2)],
        EyesShown::Left => &[(0, 0, width)],
        EyesShown::Right => &[(1, 0, width)],
    };
    let (ew, eh) = (readback.width as usize, readback.height as usize);
    let see = preview.zip(world);
    let width = width as usize;
    // Index loops over whole rows: this runs for every pixel of every frame, and iterator
    // adapters per pixel cost more than the copy itself in unoptimised builds.
    for &(eye, x0, part_w) in parts {
        let part_w = part_w as usize;
        if part_w == 0 {
            continue;
        }
        let src = &readback.eyes[eye];
        // Byte offset in a source row of each column of the part.
        let columns: Vec<usize> = (0..part_w)
            .map(|x| ((x * ew) / part_w).min(ew - 1) * 4)
            .collect();
        for y in 0..height as usize {
            let sy = ((y * eh) / height as usize).min(eh - 1);
            let src_row = &src[sy * ew * 4..(sy + 1) * ew * 4];
            let row = &mut out[(y * width + x0 as usize) * 4..][..part_w * 4];
            match see {
                None if part_w == ew => row.copy_from_slice(src_row),
                None => {
                    let mut x = 0;
                    while x < part_w {
                        let (o, i) = (x * 4, columns[x]);
                        row[o..o + 3].copy_from_slice(&src_row[i..i + 3]);
                        x += 1;
                    }
                }
                Some((tables, world)) => {
                    let world_row = &world[eye][sy * ew * 4..(sy + 1) * ew * 4];
                    let mut x = 0;
                    while x < part_w {
                        let (o, i) = (x * 4, columns[x]);
                        row[o] = tables.add(src_row[i], world_row[i]);
                        row[o + 1] = tables.add(src_row[i + 1], world_row[i + 1]);
                        row[o + 2] = tables.add(src_row[i + 2], world_row[i + 2]);
                        x += 1;
                    }
                }
            }
            let mut a = 3;
            while a < row.len() {
                row[a] = 255;
                a += 4;
            }
        }
    }
}

/// Draws lines of text in the window's top left corner on a darkened box.
pub struct Overlay {
    /// The text's font and size.
    text: TextBox,
}

impl Overlay {
    /// The overlay with the embedded font.
    pub fn new() -> anyhow::Result<Overlay> {
        Ok(Overlay {
            text: TextBox::new(TEXT_PX)?,
        })
    }

    /// Draws `lines` into `out` (RGBA8, `width` x `height`).
    pub fn draw(&self, out: &mut [u8], width: u32, height: u32, lines: &[String]) {
        self.text.draw(out, (width, height), (0, 0), lines);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn readback(left: u8, right: u8) -> Readback {
        Readback {
            width: 2,
            height: 2,
            eyes: [vec![left; 16], vec![right; 16]],
            world: None,
        }
    }

    #[test]
    fn side_by_side_puts_each_eye_in_its_half() {
        let mut out = vec![0u8; 8 * 2 * 4];
        compose(
            &mut out,
            8,
            2,
            &readback(10, 200),
            EyesShown::Both,
            None,
            None,
        );
        assert_eq!(out[0], 10);
        assert_eq!(out[4 * 4], 200);
        assert_eq!(out[7 * 4 + 3], 255);
        compose(
            &mut out,
            8,
            2,
            &readback(10, 200),
            EyesShown::Right,
            None,
            None,
        );
        assert!(out.chunks(4).all(|p| p[0] == 200));
    }

    #[test]
    fn the_preview_adds_light_as_replay_does() {
        let tables = SeeThrough::new();
        for (e, w) in [(0u8, 0u8), (128, 64), (10, 250), (255, 255)] {
            let replay = vitreous_frames::output::see_through(&[e, e, e, 255], &[w, w, w, 255]);
            assert!(
                i16::from(tables.add(e, w)).abs_diff(i16::from(replay[0])) <= 1,
                "{e} + {w}"
            );
        }
    }

    #[test]
    fn overlay_text_lights_pixels_in_the_corner_only() {
        let (w, h) = (200u32, 100u32);
        let mut out = vec![90u8; (w * h * 4) as usize];
        Overlay::new()
            .unwrap()
            .draw(&mut out, w, h, &["K_g 3.2 px".into()]);
        let lit = out.chunks(4).filter(|p| p[0] > 200).count();
        assert!(lit > 20, "{lit} bright pixels");
        assert_eq!(
            out[((h - 1) * w + w - 1) as usize * 4],
            90,
            "far corner untouched"
        );
    }
}
