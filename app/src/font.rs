//! The embedded font (DejaVu Sans, licence in `app/assets/fonts/LICENSE-DejaVu.txt`): the plots,
//! the viewer's overlay and `vitreous sheet`'s captions need no system fonts.

use std::sync::Once;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use anyhow::{Result, anyhow};
use plotters::style::FontStyle;

/// DejaVu Sans, TrueType.
pub static FONT_TTF: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Makes the embedded font the plots' `sans-serif` (once per process).
pub fn register_plot_font() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_TTF)
            .map_err(|_| anyhow!("the embedded DejaVu Sans font could not be parsed"));
    });
    result
}

/// Lines of white text on a darkened box, drawn into RGBA8 pictures with the embedded font.
pub struct TextBox {
    /// The parsed font.
    font: FontRef<'static>,
    /// Height of the text, pixels.
    px: f32,
}

impl TextBox {
    /// Text `px` pixels high in the embedded font.
    pub fn new(px: f32) -> Result<TextBox> {
        let font = FontRef::try_from_slice(FONT_TTF)
            .map_err(|_| anyhow!("the embedded DejaVu Sans font could not be parsed"))?;
        Ok(TextBox { font, px })
    }

    /// The width and height of the box that [`TextBox::draw`] fills for `lines`, pixels.
    pub fn size(&self, lines: &[String]) -> (u32, u32) {
        let scaled = self.font.as_scaled(PxScale::from(self.px));
        let line_h = scaled.height() + scaled.line_gap();
        let text_w = lines
            .iter()
            .map(|l| {
                l.chars()
                    .map(|c| scaled.h_advance(self.font.glyph_id(c)))
                    .sum::<f32>()
            })
            .fold(0.0f32, f32::max);
        (
            (text_w + 12.0).ceil() as u32,
            (line_h * lines.len() as f32 + 8.0).ceil() as u32,
        )
    }

    /// Draws `lines` into `out` (RGBA8, `width` x `height`) with the box's top left corner at
    /// `at`, the box's picture darkened to a third; whatever falls outside `out` is cut off.
    pub fn draw(
        &self,
        out: &mut [u8],
        (width, height): (u32, u32),
        at: (u32, u32),
        lines: &[String],
    ) {
        if lines.is_empty() {
            return;
        }
        let scale = PxScale::from(self.px);
        let scaled = self.font.as_scaled(scale);
        let line_h = scaled.height() + scaled.line_gap();
        let (box_w, box_h) = self.size(lines);
        let (x0, y0) = at;
        for y in y0..(y0 + box_h).min(height) {
            for x in x0..(x0 + box_w).min(width) {
                let i = (y as usize * width as usize + x as usize) * 4;
                for c in &mut out[i..i + 3] {
                    *c /= 3;
                }
            }
        }
        for (n, line) in lines.iter().enumerate() {
            let mut x = x0 as f32 + 6.0;
            let baseline = y0 as f32 + 4.0 + scaled.ascent() + line_h * n as f32;
            for c in line.chars() {
                let id = self.font.glyph_id(c);
                let glyph = id.with_scale_and_position(scale, point(x, baseline));
                x += scaled.h_advance(id);
                let Some(outline) = self.font.outline_glyph(glyph) else {
                    continue;
                };
                let bounds = outline.px_bounds();
                outline.draw(|gx, gy, coverage| {
                    let px = bounds.min.x as i64 + i64::from(gx);
                    let py = bounds.min.y as i64 + i64::from(gy);
                    if px < 0 || py < 0 || px >= i64::from(width) || py >= i64::from(height) {
                        return;
                    }
                    let i = (py as usize * width as usize + px as usize) * 4;
                    for c in &mut out[i..i + 3] {
                        let v = f32::from(*c) + (255.0 - f32::from(*c)) * coverage;
                        *c = v.min(255.0) as u8;
                    }
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lights_pixels_inside_its_box_and_darkens_the_rest_of_it() {
        let text = TextBox::new(14.0).unwrap();
        let lines = vec!["disc 0.271".to_owned(), "shadow 0.146".to_owned()];
        let (bw, bh) = text.size(&lines);
        assert!(bw > 40 && bh > 28, "{bw} x {bh}");
        let (w, h) = (bw + 20, bh + 20);
        let mut out = vec![90u8; (w * h * 4) as usize];
        text.draw(&mut out, (w, h), (10, 10), &lines);
        let at = |x: u32, y: u32| out[((y * w + x) * 4) as usize];
        // Outside the box: untouched; inside: darkened, or lit where a glyph is.
        assert_eq!(at(5, 5), 90);
        assert_eq!(at(w - 3, h - 3), 90);
        let inside: Vec<u8> = (10..10 + bh)
            .flat_map(|y| (10..10 + bw).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .collect();
        assert!(inside.iter().all(|&v| v >= 30));
        assert!(inside.iter().filter(|&&v| v == 30).count() > inside.len() / 2);
        assert!(inside.iter().any(|&v| v > 200));
        // A box reaching past the picture's edge is cut off, not a panic.
        text.draw(&mut out, (w, h), (w - 4, h - 4), &lines);
    }
}
