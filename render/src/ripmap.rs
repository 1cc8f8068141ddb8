//! Ripmaps of the real floor and background photos: each photo box-filtered down by `2^i`
//! across and `2^j` down (`i`, `j` below [`LEVELS`]), every reduction packed into one atlas,
//! so that a shader reads a photo averaged over a pixel's footprint (long and thin where the
//! eye looks along the floor) with one bilinear fetch: the reduction whose texels are about
//! the footprint's size along each of the photo's axes (shaders/shared/compensation.wgsl).
//!
//! Reduction `(i, j)` of a `W x H` photo is `ceil(W / 2^i) x ceil(H / 2^j)` texels, each the
//! mean, in linear light, of the photo's texels in its `2^i x 2^j` block (clipped at the
//! photo's edge), stored as 8-bit sRGB. A photo's reductions lie in columns by `i` and rows
//! by `j`; the second photo's to the right of the first's.

use vitreous_optics::srgb;

use crate::error::{RenderError, Result};
use crate::scene::{TexelData, TextureDesc};

/// Reductions along each axis: by 1, 2, 4, ..., 32.
pub const LEVELS: usize = 6;

/// Where a photo's reductions lie in the atlas, in atlas texels: `columns[i]` the left edge
/// and width of reduction column `i`, `rows[j]` the top edge and height of row `j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhotoLevels {
    /// Left edge and width of each column.
    pub columns: [(u32, u32); LEVELS],
    /// Top edge and height of each row.
    pub rows: [(u32, u32); LEVELS],
    /// The photo's own width and height.
    pub size: (u32, u32),
}

/// The atlas: RGBA 8-bit sRGB texels, row by row.
#[derive(Clone, Debug)]
pub struct Atlas {
    /// Width, texels.
    pub width: u32,
    /// Height, texels.
    pub height: u32,
    /// The texels.
    pub texels: Vec<u8>,
    /// Each photo's reductions, in the order given.
    pub photos: Vec<PhotoLevels>,
}

/// Packs the ripmaps of `photos` (8-bit sRGB) into one atlas.
pub fn atlas(photos: &[&TextureDesc]) -> Result<Atlas> {
    let mut levels = Vec::new();
    let (mut x0, mut height) = (0u32, 0u32);
    for p in photos {
        let (w, h) = (p.width.max(1), p.height.max(1));
        let mut columns = [(0, 0); LEVELS];
        let mut rows = [(0, 0); LEVELS];
        let (mut x, mut y) = (x0, 0);
        for k in 0..LEVELS {
            let (cw, rh) = (w.div_ceil(1 << k), h.div_ceil(1 << k));
            columns[k] = (x, cw);
            rows[k] = (y, rh);
            x += cw;
            y += rh;
        }
        levels.push(PhotoLevels {
            columns,
            rows,
            size: (w, h),
        });
        x0 = x;
        height = height.max(y);
    }
    let width = x0;
    let mut texels = vec![0u8; width as usize * height as usize * 4];
    for (p, at) in photos.iter().zip(&levels) {
        let TexelData::Srgb8(bytes) = p.data else {
            return Err(RenderError::Creation(
                "a real plane's photo must be 8-bit sRGB".into(),
            ));
        };
        let (w, h) = (p.width as usize, p.height as usize);
        // Summed-area table of the photo in linear light (RGB), one row and column of zeros
        // first, so that any block's sum is four lookups.
        let mut sums = vec![[0f64; 3]; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = [0f64; 3];
            for x in 0..w {
                let t = &bytes[(y * w + x) * 4..(y * w + x) * 4 + 3];
                for c in 0..3 {
                    row[c] += f64::from(srgb::to_linear(t[c]));
                    sums[(y + 1) * (w + 1) + x + 1][c] = sums[y * (w + 1) + x + 1][c] + row[c];
                }
            }
        }
        let block = |x0: usize, y0: usize, x1: usize, y1: usize| {
            let s = |x: usize, y: usize| sums[y * (w + 1) + x];
            let n = ((x1 - x0) * (y1 - y0)) as f64;
            let (a, b, c, d) = (s(x1, y1), s(x0, y1), s(x1, y0), s(x0, y0));
            [0, 1, 2].map(|k| (a[k] - b[k] - c[k] + d[k]) / n)
        };
        for (i, &(cx, cw)) in at.columns.iter().enumerate() {
            for (j, &(ry, rh)) in at.rows.iter().enumerate() {
                for ty in 0..rh as usize {
                    let (y0, y1) = (ty << j, ((ty + 1) << j).min(h));
                    for tx in 0..cw as usize {
                        let (x0, x1) = (tx << i, ((tx + 1) << i).min(w));
                        let mean = block(x0, y0, x1, y1);
                        let o = ((ry as usize + ty) * width as usize + cx as usize + tx) * 4;
                        for c in 0..3 {
                            texels[o + c] = srgb::from_linear(mean[c] as f32);
                        }
                        texels[o + 3] = 255;
                    }
                }
            }
        }
    }
    Ok(Atlas {
        width,
        height,
        texels,
        photos: levels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn photo(w: u32, h: u32, f: impl Fn(u32, u32) -> u8) -> Vec<u8> {
        let mut out = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = f(x, y);
                out.extend_from_slice(&[v, v, v, 255]);
            }
        }
        out
    }

    #[test]
    fn each_reduction_is_the_linear_mean_of_its_block() {
        // Stripes one texel tall, black and white: reduced down by 2 they are one grey (the
        // linear mean, sRGB 188), across by 2 they stay stripes.
        let bytes = photo(8, 8, |_, y| if y % 2 == 0 { 0 } else { 255 });
        let desc = TextureDesc {
            width: 8,
            height: 8,
            data: TexelData::Srgb8(&bytes),
        };
        let a = atlas(&[&desc]).unwrap();
        let at = |i: usize, j: usize, x: u32, y: u32| {
            let p = &a.photos[0];
            let (cx, _) = p.columns[i];
            let (ry, _) = p.rows[j];
            a.texels[(((ry + y) * a.width + cx + x) * 4) as usize]
        };
        assert_eq!(at(0, 0, 3, 0), 0);
        assert_eq!(at(0, 0, 3, 1), 255);
        assert_eq!(at(0, 1, 3, 0), 188);
        assert_eq!(at(1, 0, 1, 1), 255);
        assert_eq!(at(3, 3, 0, 0), 188);
    }

    #[test]
    fn reductions_of_two_photos_lie_side_by_side_without_overlap() {
        let (a_bytes, b_bytes) = (photo(10, 6, |_, _| 10), photo(7, 9, |_, _| 200));
        let a = TextureDesc {
            width: 10,
            height: 6,
            data: TexelData::Srgb8(&a_bytes),
        };
        let b = TextureDesc {
            width: 7,
            height: 9,
            data: TexelData::Srgb8(&b_bytes),
        };
        let atlas = atlas(&[&a, &b]).unwrap();
        let (pa, pb) = (&atlas.photos[0], &atlas.photos[1]);
        // Odd sizes round up: 10, 5, 3, 2, 1, 1 across.
        assert_eq!(pa.columns.map(|c| c.1), [10, 5, 3, 2, 1, 1]);
        assert_eq!(pb.columns[0].0, 22);
        assert_eq!(atlas.width, 22 + 7 + 4 + 2 + 1 + 1 + 1);
        assert_eq!(atlas.height, 9 + 5 + 3 + 2 + 1 + 1);
        // Every texel of each reduction holds its photo's grey.
        for (p, grey) in [(pa, 10), (pb, 200)] {
            for &(cx, cw) in &p.columns {
                for &(ry, rh) in &p.rows {
                    for y in ry..ry + rh {
                        for x in cx..cx + cw {
                            assert_eq!(atlas.texels[((y * atlas.width + x) * 4) as usize], grey);
                        }
                    }
                }
            }
        }
    }
}
