//! Depositing flux onto the floor texel grid.
//!
//! Sums are kept in 64-bit fixed point and added atomically: integer addition commutes, so
//! the result does not depend on which thread got there first (byte-identical bakes).

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec2;

/// Largest subdivision of a floor triangle per edge (a bigger triangle is spread coarser).
const MAX_SUBDIVISION: u32 = 64;
/// Target sub-triangle edge, texels of the level it is drawn on: fine enough that the
/// bilinear splat of its centroid stands for its area.
const SUB_EDGE_PX: f32 = 0.75;
/// A triangle is drawn on the finest level where its longest edge is at most this many
/// texels; coarser levels are 2x, 4x, ... the texel size.
const LEVEL_EDGE_PX: f32 = 4.0;
/// Coarsest level.
const MAX_LEVEL: usize = 6;

/// One level of the flux pyramid.
struct Level {
    width: usize,
    height: usize,
    cells: Vec<AtomicU64>,
}

/// One flux map on the floor grid, with coarser levels for large floor triangles (a large
/// triangle carries a smooth spread of flux, so it is drawn at a texel size matching its
/// own, and the levels are summed when the bake ends).
pub(crate) struct FluxGrid {
    /// Level 0 is the full resolution.
    levels: Vec<Level>,
    /// Fixed-point units per unit of flux.
    scale: f64,
}

impl FluxGrid {
    /// An empty grid; `max_total_flux` bounds what will ever be deposited in all.
    pub fn new(width: u32, height: u32, max_total_flux: f64) -> Self {
        let levels = (0..=MAX_LEVEL)
            .map(|l| {
                let (w, h) = (
                    (width as usize).div_ceil(1 << l),
                    (height as usize).div_ceil(1 << l),
                );
                Level {
                    width: w,
                    height: h,
                    cells: (0..w * h).map(|_| AtomicU64::new(0)).collect(),
                }
            })
            .collect();
        FluxGrid {
            levels,
            // 2^52 units for everything: far from u64 overflow, far finer than f32.
            scale: (1u64 << 52) as f64 / max_total_flux.max(f64::MIN_POSITIVE),
        }
    }

    fn add(&self, level: &Level, x: usize, y: usize, flux: f64) {
        let units = (flux * self.scale).round() as u64;
        if units > 0 {
            level.cells[y * level.width + x].fetch_add(units, Ordering::Relaxed);
        }
    }

    /// Bilinear deposit at continuous texel coordinates of `level` (texel (i, j) spans
    /// [i, i+1) x [j, j+1)); weights off the grid go to the edge texel, so none is lost.
    fn splat(&self, level: usize, p: Vec2, flux: f64) {
        let lv = &self.levels[level];
        let x = (p.x - 0.5).clamp(0.0, (lv.width - 1) as f32);
        let y = (p.y - 0.5).clamp(0.0, (lv.height - 1) as f32);
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = ((x - x0 as f32) as f64, (y - y0 as f32) as f64);
        let (x1, y1) = ((x0 + 1).min(lv.width - 1), (y0 + 1).min(lv.height - 1));
        self.add(lv, x0, y0, flux * (1.0 - fx) * (1.0 - fy));
        self.add(lv, x1, y0, flux * fx * (1.0 - fy));
        self.add(lv, x0, y1, flux * (1.0 - fx) * fy);
        self.add(lv, x1, y1, flux * fx * fy);
    }

    /// Deposits `flux` at continuous full-resolution texel coordinates `p`, split
    /// bilinearly between the four nearest texel centres.
    pub fn point(&self, p: Vec2, flux: f64) {
        self.splat(0, p, flux);
    }

    /// Spreads `flux` evenly over the triangle `a, b, c` (full-resolution texel
    /// coordinates): the triangle is cut into m^2 congruent sub-triangles whose centroids
    /// are splatted, on the level whose texels suit its size.
    pub fn triangle(&self, a: Vec2, b: Vec2, c: Vec2, flux: f64) {
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let mut level = 0;
        while level < MAX_LEVEL && longest > LEVEL_EDGE_PX * (1 << level) as f32 {
            level += 1;
        }
        let k = 1.0 / (1 << level) as f32;
        let (a, b, c) = (a * k, b * k, c * k);
        let m = ((longest * k / SUB_EDGE_PX).ceil() as u32).clamp(1, MAX_SUBDIVISION);
        if m == 1 {
            return self.splat(level, (a + b + c) / 3.0, flux);
        }
        let share = flux / (m * m) as f64;
        let (e1, e2) = ((b - a) / m as f32, (c - a) / m as f32);
        for i in 0..m {
            for j in 0..m - i {
                let (fi, fj) = (i as f32, j as f32);
                self.splat(
                    level,
                    a + e1 * (fi + 1.0 / 3.0) + e2 * (fj + 1.0 / 3.0),
                    share,
                );
                if i + j + 1 < m {
                    self.splat(
                        level,
                        a + e1 * (fi + 2.0 / 3.0) + e2 * (fj + 2.0 / 3.0),
                        share,
                    );
                }
            }
        }
    }

    /// The flux per full-resolution texel, in the units given to [`FluxGrid::new`]. Each
    /// coarse level is spread onto the next finer one with the transpose of bilinear 2x
    /// interpolation (1D weights 1/8, 3/8, 3/8, 1/8), which keeps every unit of flux.
    pub fn into_flux(self) -> Vec<f64> {
        let scale = self.scale;
        let mut levels = self.levels.into_iter().rev();
        let coarsest = levels.next().expect("at least one level");
        let mut acc: Vec<f64> = coarsest
            .cells
            .into_iter()
            .map(|c| c.into_inner() as f64 / scale)
            .collect();
        let (mut cw, mut ch) = (coarsest.width, coarsest.height);
        for fine in levels {
            let (fw, fh) = (fine.width, fine.height);
            let mut out: Vec<f64> = fine
                .cells
                .into_iter()
                .map(|c| c.into_inner() as f64 / scale)
                .collect();
            const W: [f64; 4] = [0.125, 0.375, 0.375, 0.125];
            for cy in 0..ch {
                for cx in 0..cw {
                    let v = acc[cy * cw + cx];
                    if v == 0.0 {
                        continue;
                    }
                    for (dy, wy) in W.iter().enumerate() {
                        let fy = (2 * cy + dy).saturating_sub(1).min(fh - 1);
                        for (dx, wx) in W.iter().enumerate() {
                            let fx = (2 * cx + dx).saturating_sub(1).min(fw - 1);
                            out[fy * fw + fx] += v * wx * wy;
                        }
                    }
                }
            }
            acc = out;
            (cw, ch) = (fw, fh);
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deposits_keep_every_unit_of_flux_and_their_centroid() {
        let g = FluxGrid::new(37, 21, 10.0);
        g.point(Vec2::new(0.1, 20.9), 1.0); // corner: clamped, kept
        g.triangle(
            Vec2::new(2.0, 1.0),
            Vec2::new(36.0, 2.0),
            Vec2::new(5.0, 20.0),
            3.0,
        );
        g.triangle(
            Vec2::new(4.2, 4.2),
            Vec2::new(4.3, 4.25),
            Vec2::new(4.25, 4.4),
            0.5,
        );
        let f = g.into_flux();
        let total: f64 = f.iter().sum();
        assert!((total - 4.5).abs() < 1e-9);
        // The big triangle's flux centroid sits at its centroid (3-fold check with its mass).
        let g = FluxGrid::new(128, 128, 1.0);
        let (a, b, c) = (
            Vec2::new(53.0, 55.0),
            Vec2::new(75.0, 59.0),
            Vec2::new(61.0, 78.0),
        );
        g.triangle(a, b, c, 1.0);
        let f = g.into_flux();
        let mut centroid = Vec2::ZERO;
        for (i, v) in f.iter().enumerate() {
            centroid += Vec2::new((i % 128) as f32 + 0.5, (i / 128) as f32 + 0.5) * *v as f32;
        }
        assert!(centroid.abs_diff_eq((a + b + c) / 3.0, 0.05), "{centroid}");
    }
}
