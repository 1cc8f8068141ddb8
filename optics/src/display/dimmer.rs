//! A segmented dimmer ([`DimmerDesc`], `[display] model = "dimmer"`) as the eye meets it, on
//! the CPU: the panel's cells, each taking away a share of the real world's light, seen through
//! the panel's optical blur. The renderer's GPU pass (shaders/dimmer_panel.wgsl `soften`)
//! evaluates the same sums; the see-through preview (vitreous-frames) and the tests use these.
//!
//! The panel is `cells[0] x cells[1]` cells spread evenly over the eye image. A cell holding
//! `p` takes away the share `p` of the light behind it; the panel sits out of focus, so the eye
//! sees its pattern through a Gaussian point spread of standard deviation `sigma` (in cells).
//! The share taken away at a point `u` (in cells) is then exactly
//! `D(u) = sum_c p_c wx(c, u) wy(c, u)`, with `w(c, u) = Phi((c + 1 - u) / sigma) -
//! Phi((c - u) / sigma)` the Gaussian's mass over the cell and `Phi` the normal distribution.
//! `D` is evaluated on a grid [`FINE`] times finer than the cells and interpolated bilinearly
//! between its points.

/// A segmented dimmer in front of the display (Magic Leap 2's): a coarse panel whose cells
/// each take away a share of the real world's light, seen out of focus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DimmerDesc {
    /// Cells across and down the eye's view.
    pub cells: [u32; 2],
    /// Standard deviation of the panel's optical blur (a Gaussian point spread), degrees.
    pub blur_deg: f32,
    /// The largest share of the real world's light a cell takes away (0..1).
    pub max: f32,
    /// How far the display's light and panel may land from where the real world is, degrees
    /// (one standard deviation per axis; `[display] registration_error_deg`): the panel and
    /// the light that gives its halo back are planned for it.
    pub registration_error_deg: f32,
}

/// Points of the attenuation grid per cell side.
pub const FINE: u32 = 4;

/// The most cells the blur's sum reaches on each side (the shader's array of column weights
/// holds 2 x 31 + 1); a blur of up to 7.5 cells is summed over 4 standard deviations.
pub const MAX_REACH: i32 = 31;

/// The largest blur a scene may ask for, in cells ([`MAX_REACH`] over 4).
pub const MAX_SIGMA_CELLS: f32 = 7.5;

/// The error function, by Abramowitz and Stegun 7.1.26 (absolute error below 1.5e-7); the
/// shader computes the same polynomial.
pub fn erf(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_6
            + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152_1 + t * 1.061_405_4))));
    let y = 1.0 - poly * (-x * x).exp();
    y.copysign(x)
}

/// The share of a Gaussian of standard deviation `sigma` centred at `u` that falls on the cell
/// `[c, c + 1)`.
pub fn cell_weight(c: i32, u: f32, sigma: f32) -> f32 {
    let s = sigma.max(1e-3) * std::f32::consts::SQRT_2;
    0.5 * (erf((c as f32 + 1.0 - u) / s) - erf((c as f32 - u) / s))
}

/// One eye's panel: its cells, its blur in cells, and how far it spreads a want.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Panel {
    /// Cells across and down.
    pub cells: [u32; 2],
    /// The blur's standard deviation in cells, across and down.
    pub sigma: [f32; 2],
    /// How many cells around a cell that wants darkening the panel darkens too (its spread,
    /// [`Panel::spread_cells`]); negative: how many cells in from the wanted patch's edge the
    /// panel stops (an erosion).
    pub spread: i32,
}

/// The spread of a panel of `cells` over a view `fov_deg` wide and high for a display whose
/// light may land `registration_error_deg` (one standard deviation) from where the world
/// is: one cell around every wanted cell, less one cell for each cell's width that twice the
/// error spans along the panel's finer axis. One cell covers the wanted patch's edge, which
/// the blur softens (measured against the physical reference, a spread of 2.5 standard
/// deviations of the blur, which covered 97.5 % of every want, darkened a patch whose
/// given-back light costs more than it gains even perfectly registered: docs/display.md);
/// a cell whose want the error may move off it is not darkened.
pub fn spread_cells(cells: [u32; 2], fov_deg: [f32; 2], registration_error_deg: f32) -> i32 {
    let cell_deg = (0..2)
        .map(|i| fov_deg[i] / cells[i].max(1) as f32)
        .fold(f32::INFINITY, f32::min);
    let spanned = (2.0 * registration_error_deg.max(0.0) / cell_deg.max(1e-6)).floor();
    (1.0 - spanned).max(-(MAX_REACH as f32)) as i32
}

impl Panel {
    /// The panel `desc` describes over a view `fov_deg` wide and high (degrees): the blur is
    /// converted at the view's mean cells per degree (at most [`MAX_SIGMA_CELLS`]).
    pub fn new(desc: &DimmerDesc, fov_deg: [f32; 2]) -> Panel {
        Panel {
            cells: desc.cells,
            sigma: [0, 1].map(|i| {
                (desc.blur_deg * desc.cells[i] as f32 / fov_deg[i].max(1e-3)).min(MAX_SIGMA_CELLS)
            }),
            spread: spread_cells(desc.cells, fov_deg, desc.registration_error_deg),
        }
    }

    /// How far (in cells, across and down) the panel may darken around a cell that wants
    /// darkening: its spread, or none when it erodes. What the blurred patch takes away
    /// beyond what the target needs is given back as light (the halo compensated).
    pub fn reach(&self) -> [u32; 2] {
        [self.spread.max(0) as u32; 2]
    }

    /// The panel each cell holds for `wanted` (one want per cell, rows from the top): the
    /// largest want within [`Panel::spread`] cells, or with a negative spread the least within
    /// that many (cells beyond the panel want nothing). shaders/dimmer_panel.wgsl `spread`
    /// computes the same.
    pub fn spread_wants(&self, wanted: &[f32]) -> Vec<f32> {
        let [cx, cy] = self.cells.map(|c| c as i32);
        let r = self.spread.abs();
        (0..cy)
            .flat_map(|y| (0..cx).map(move |x| (x, y)))
            .map(|(x, y)| {
                let values = (y - r..=y + r).flat_map(|yy| {
                    (x - r..=x + r).map(move |xx| {
                        if xx < 0 || yy < 0 || xx >= cx || yy >= cy {
                            0.0
                        } else {
                            wanted[(yy * cx + xx) as usize]
                        }
                    })
                });
                if self.spread >= 0 {
                    values.fold(0.0, f32::max)
                } else {
                    values.fold(1.0, f32::min)
                }
            })
            .collect()
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        (self.cells[0] * self.cells[1]) as usize
    }

    /// Whether the panel has no cell.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell under pixel `(x, y)` of a `size` image, as an index.
    pub fn cell_of(&self, x: u32, y: u32, size: [u32; 2]) -> usize {
        let cx = (u64::from(x) * u64::from(self.cells[0]) / u64::from(size[0])) as u32;
        let cy = (u64::from(y) * u64::from(self.cells[1]) / u64::from(size[1])) as u32;
        (cy.min(self.cells[1] - 1) * self.cells[0] + cx.min(self.cells[0] - 1)) as usize
    }

    /// The panel a runtime makes of a submitted alpha image: each cell the mean of the alpha
    /// (0..1) of the pixels under it.
    pub fn from_alpha(&self, alpha: &[f32], size: [u32; 2]) -> Vec<f32> {
        let mut sum = vec![0.0f64; self.len()];
        let mut count = vec![0u32; self.len()];
        for y in 0..size[1] {
            for x in 0..size[0] {
                let c = self.cell_of(x, y, size);
                sum[c] += f64::from(alpha[(y * size[0] + x) as usize]);
                count[c] += 1;
            }
        }
        sum.iter()
            .zip(&count)
            .map(|(&s, &n)| {
                if n == 0 {
                    0.0
                } else {
                    (s / f64::from(n)) as f32
                }
            })
            .collect()
    }

    /// The share of the light the eye loses through the panel holding `values` (one per
    /// cell), on the grid [`FINE`] times finer than the cells (rows from the top).
    pub fn soften(&self, values: &[f32]) -> Vec<f32> {
        let [cx, cy] = self.cells;
        let (fw, fh) = (cx * FINE, cy * FINE);
        let reach = self
            .sigma
            .map(|s| ((4.0 * s).ceil() as i32 + 1).min(MAX_REACH));
        let mut out = Vec::with_capacity((fw * fh) as usize);
        for j in 0..fh {
            let v = (j as f32 + 0.5) / FINE as f32;
            for i in 0..fw {
                let u = (i as f32 + 0.5) / FINE as f32;
                let (c0, r0) = (u.floor() as i32, v.floor() as i32);
                let mut d = 0.0f32;
                for r in (r0 - reach[1]).max(0)..=(r0 + reach[1]).min(cy as i32 - 1) {
                    let wy = cell_weight(r, v, self.sigma[1]);
                    for c in (c0 - reach[0]).max(0)..=(c0 + reach[0]).min(cx as i32 - 1) {
                        let p = values[(r as u32 * cx + c as u32) as usize];
                        if p > 0.0 {
                            d += p * cell_weight(c, u, self.sigma[0]) * wy;
                        }
                    }
                }
                out.push(d);
            }
        }
        out
    }

    /// `soft` (from [`Panel::soften`]) at the centre of pixel `(x, y)` of a `size` image,
    /// interpolated bilinearly between the grid's points (clamped at its edges).
    pub fn at_pixel(&self, soft: &[f32], x: u32, y: u32, size: [u32; 2]) -> f32 {
        let n = [self.cells[0] * FINE, self.cells[1] * FINE];
        let at = |i: usize| (([x, y][i] as f32 + 0.5) / size[i] as f32) * n[i] as f32 - 0.5;
        let (u, v) = (
            at(0).clamp(0.0, (n[0] - 1) as f32),
            at(1).clamp(0.0, (n[1] - 1) as f32),
        );
        let (u0, v0) = (u.floor() as u32, v.floor() as u32);
        let (u1, v1) = ((u0 + 1).min(n[0] - 1), (v0 + 1).min(n[1] - 1));
        let (fu, fv) = (u - u0 as f32, v - v0 as f32);
        let s = |i: u32, j: u32| soft[(j * n[0] + i) as usize];
        let top = s(u0, v0) + (s(u1, v0) - s(u0, v0)) * fu;
        let bottom = s(u0, v1) + (s(u1, v1) - s(u0, v1)) * fu;
        top + (bottom - top) * fv
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The normal distribution by numerical integration of its density (independent of `erf`).
    fn phi(z: f64) -> f64 {
        let steps = 20_000;
        let lo = -10.0;
        let h = (z - lo) / steps as f64;
        let density = |t: f64| (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt();
        (0..steps)
            .map(|i| density(lo + (i as f64 + 0.5) * h) * h)
            .sum()
    }

    #[test]
    fn erf_matches_the_integrated_normal_distribution() {
        for z in [-3.0, -1.2, -0.3, 0.0, 0.4, 1.0, 2.5] {
            let ours = 0.5 * (1.0 + f64::from(erf(z as f32 / std::f32::consts::SQRT_2)));
            assert!((ours - phi(z)).abs() < 2e-6, "{z}: {ours} vs {}", phi(z));
        }
    }

    fn panel(cells: [u32; 2], sigma: f32) -> Panel {
        Panel {
            cells,
            sigma: [sigma; 2],
            spread: 1,
        }
    }

    #[test]
    fn a_full_panel_takes_away_everything_inside_and_a_cells_weights_sum_to_one() {
        let p = panel([40, 40], 1.5);
        let soft = p.soften(&vec![1.0; p.len()]);
        // Far from the edges, the whole Gaussian lies on cells holding 1.
        let w = 40 * FINE as usize;
        let mid = soft[(20 * FINE as usize) * w + 20 * FINE as usize];
        assert!((mid - 1.0).abs() < 1e-5, "{mid}");
        let total: f32 = (-20..20).map(|c| cell_weight(c, 0.3, 2.0)).sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
    }

    #[test]
    fn one_dark_cell_spreads_as_the_blur_says() {
        let p = panel([21, 21], 1.0);
        let mut values = vec![0.0; p.len()];
        values[10 * 21 + 10] = 1.0;
        let soft = p.soften(&values);
        let w = (21 * FINE) as usize;
        // The grid's points lie at (i + 0.5) / FINE cells.
        let at = |i: usize, j: usize| soft[j * w + i];
        let u = |i: usize| (i as f64 + 0.5) / f64::from(FINE);
        let mass = |c: f64, x: f64| phi(c + 1.0 - x) - phi(c - x);
        let (i, j) = (42, 42);
        let centre = (mass(10.0, u(i)) * mass(10.0, u(j))) as f32;
        assert!((at(i, j) - centre).abs() < 1e-4, "{} vs {centre}", at(i, j));
        // Two cells to the right: the mass over the lit cell seen from there.
        let two = (mass(10.0, u(i + 8)) * mass(10.0, u(j))) as f32;
        assert!(
            (at(i + 8, j) - two).abs() < 1e-4,
            "{} vs {two}",
            at(i + 8, j)
        );
        assert!(two < 0.2 * centre);
        // Symmetric about the cell's centre (grid points 41 and 42 straddle it).
        assert!((at(41 - 8, j) - at(i + 8, j)).abs() < 1e-6);
    }

    #[test]
    fn a_want_spreads_one_cell_and_erodes_under_a_registration_error() {
        // Magic Leap 2's panel: 64 x 48 cells over 40 x 30 degrees, 0.625 degrees a cell.
        let (cells, fov) = ([64, 48], [40.0, 30.0]);
        assert_eq!(spread_cells(cells, fov, 0.0), 1);
        assert_eq!(spread_cells(cells, fov, 0.125), 1);
        assert_eq!(spread_cells(cells, fov, 0.25), 1);
        assert_eq!(spread_cells(cells, fov, 0.32), 0);
        assert_eq!(spread_cells(cells, fov, 0.65), -1);
        // A 3 x 3 patch wanting 0.8 and one cell beside it wanting 0.4.
        let mut p = panel([9, 9], 1.0);
        let mut wanted = vec![0.0; 81];
        for y in 3..6 {
            for x in 3..6 {
                wanted[y * 9 + x] = 0.8;
            }
        }
        wanted[4 * 9 + 6] = 0.4;
        let spread = p.spread_wants(&wanted);
        assert_eq!(spread[4 * 9 + 4], 0.8);
        assert_eq!(spread[2 * 9 + 2], 0.8, "one cell around the patch");
        assert_eq!(spread[9 + 1], 0.0, "two cells away");
        assert_eq!(spread[4 * 9 + 7], 0.4, "beside the lone cell");
        p.spread = -1;
        let eroded = p.spread_wants(&wanted);
        assert_eq!(eroded[4 * 9 + 4], 0.8, "the patch's middle keeps its want");
        assert_eq!(eroded[3 * 9 + 3], 0.0, "its edge does not");
        assert_eq!(eroded[4 * 9 + 6], 0.0);
    }

    #[test]
    fn the_runtimes_panel_is_the_mean_alpha_of_each_cell() {
        let p = panel([2, 1], 1.0);
        let alpha = [1.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0, 1.0];
        // 4 x 2 pixels: the left cell holds x 0-1, the right x 2-3.
        assert_eq!(p.from_alpha(&alpha, [4, 2]), vec![0.25, 0.5]);
        assert_eq!(p.cell_of(3, 1, [4, 2]), 1);
    }

    #[test]
    fn the_blur_in_cells_follows_the_view() {
        let desc = DimmerDesc {
            cells: [64, 48],
            blur_deg: 1.25,
            max: 0.9,
            registration_error_deg: 0.0,
        };
        let p = Panel::new(&desc, [40.0, 30.0]);
        assert!((p.sigma[0] - 2.0).abs() < 1e-6 && (p.sigma[1] - 2.0).abs() < 1e-6);
        assert_eq!(p.reach(), [1, 1]);
    }
}
