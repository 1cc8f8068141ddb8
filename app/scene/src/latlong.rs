//! A latitude-longitude map turned about the vertical (`[environment] yaw_deg`): the map's
//! columns moved round, as maps drawn for other conventions need (OpenEXR's, which UsdLux and
//! MaterialX follow, puts +z in the middle: the same map turned by 180 degrees).
//!
//! The scene's map looks down -z in its middle column with +x a quarter of the width to its
//! right (`u = atan2(x, -z) / 2 pi + 0.5`, shaders/glass.wgsl `latlong_uv`). Turning it by
//! `yaw` (counter-clockwise seen from above, as the scene's rotations) moves what was seen along
//! a direction `d` to `R_y(yaw) d`: the turned map's column at `u` is the file's at
//! `u + yaw / 360`, wrapped round, linearly between the two nearest columns (exact for turns
//! by whole columns). Done once at load, so the GPU's glass, the previews and the physical
//! reference all see the one turned map.

use crate::{Image, PixelData};

/// `map` turned by `yaw_deg` about the vertical; unchanged at 0 or for an 8-bit image.
pub(crate) fn turned_about_vertical(map: Image, yaw_deg: f32) -> Image {
    let columns = map.width as usize;
    let shift = (yaw_deg / 360.0).rem_euclid(1.0) * columns as f32;
    let PixelData::LinearF32(texels) = &map.data else {
        return map;
    };
    if shift == 0.0 || columns == 0 {
        return map;
    }
    let whole = shift.floor() as usize;
    let t = shift - shift.floor();
    let turned = texels
        .chunks_exact(columns * 4)
        .flat_map(|row| {
            (0..columns).flat_map(move |x| {
                let a = &row[(x + whole) % columns * 4..][..4];
                let b = &row[(x + whole + 1) % columns * 4..][..4];
                (0..4).map(move |c| a[c] + (b[c] - a[c]) * t)
            })
        })
        .collect();
    Image {
        data: PixelData::LinearF32(turned),
        ..map
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-row map whose column x holds x in every channel.
    fn ramp(width: u32) -> Image {
        Image {
            width,
            height: 1,
            data: PixelData::LinearF32((0..width).flat_map(|x| [x as f32; 4]).collect()),
        }
    }

    fn red(map: &Image) -> Vec<f32> {
        match &map.data {
            PixelData::LinearF32(v) => v.chunks_exact(4).map(|p| p[0]).collect(),
            PixelData::Srgb8(_) => unreachable!("a float map"),
        }
    }

    #[test]
    fn a_quarter_turn_moves_the_middle_column_to_minus_x() {
        // 8 columns: u = 0.5 (-z) is column 4, u = 0.25 (-x) column 2. Turned by +90 degrees
        // (counter-clockwise from above), what was ahead is to the left.
        let turned = turned_about_vertical(ramp(8), 90.0);
        let r = red(&turned);
        assert_eq!(r[2], 4.0, "{r:?}");
        assert_eq!(r, vec![2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 0.0, 1.0]);
        // Turned back, and a full turn, leave the map as it was.
        assert_eq!(red(&turned_about_vertical(turned, -90.0)), red(&ramp(8)));
        assert_eq!(red(&turned_about_vertical(ramp(8), 360.0)), red(&ramp(8)));
        // A half turn puts -z's column at +z (u = 0 and 1, column 0).
        assert_eq!(red(&turned_about_vertical(ramp(8), 180.0))[0], 4.0);
    }

    #[test]
    fn a_turn_between_columns_interpolates_and_wraps() {
        // A sixteenth of a turn on 8 columns is half a column.
        let r = red(&turned_about_vertical(ramp(8), 22.5));
        assert_eq!(r[0], 0.5);
        assert_eq!(r[6], 6.5);
        assert_eq!(r[7], 3.5, "the last column meets the first: {r:?}");
    }
}
