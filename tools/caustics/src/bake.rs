//! The bake: the wavefront grid, flux bookkeeping, the gain map and comparisons.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{DVec2, Vec2};
use rayon::prelude::*;

use crate::emission::EmissionCone;
use crate::splat::FluxGrid;
use crate::trace::{Corner, End, Leaf, Tracer};
use crate::{Bake, CausticScene, InputError, MAX_BAKE_SIDE_PX};

/// Bake settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeParams {
    /// Floor texture width, texels (local x).
    pub width_px: u32,
    /// Floor texture height, texels (local y; row 0 = photo top).
    pub height_px: u32,
    /// Grid rays to trace (the grid is the nearest square, at least 2 x 2 cells).
    pub budget_rays: u64,
    /// Rotates the emission grid about the cone axis; a fixed seed gives a fixed bake.
    pub seed: u64,
    /// Most surface interactions (reflections and refractions) on one path.
    pub max_interactions: u32,
    /// Paths carrying less than this fraction of a grid ray's flux end (counted as pruned).
    pub min_weight: f32,
}

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            width_px: 1980,
            height_px: 1980,
            budget_rays: 1 << 18,
            seed: 0,
            max_interactions: 12,
            min_weight: 1e-4,
        }
    }
}

impl BakeParams {
    /// Grid cells per side of the square emission domain.
    pub fn grid_cells(&self) -> u32 {
        (((self.budget_rays as f64).sqrt() - 1.0).round() as u32).max(2)
    }

    /// The parameters as `key=value` text (stored in the bake file).
    pub fn describe(&self) -> String {
        format!(
            "method=wavefront-v1; width_px={}; height_px={}; budget_rays={}; grid_cells={}; \
             seed={}; max_interactions={}; min_weight={}",
            self.width_px,
            self.height_px,
            self.budget_rays,
            self.grid_cells(),
            self.seed,
            self.max_interactions,
            self.min_weight
        )
    }
}

/// Where the flux of the emission cone went, in units of the light's intensity times
/// steradians (watts for a 1 W/sr light). The fields sum to `emitted`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FluxLedger {
    /// Flux sent into the cone around the object.
    pub emitted: f64,
    /// Passed the object by (direct light).
    pub direct: f64,
    /// Reached the floor rectangle after meeting the object.
    pub floor: f64,
    /// Reflected off the outside of the object and left without reaching the floor.
    pub reflected_away: f64,
    /// Entered the object and left the scene without reaching the floor.
    pub transmitted_away: f64,
    /// Still travelling at the interaction limit (absorbed by the limit).
    pub interaction_limit: f64,
    /// Dropped for carrying less than the minimum weight.
    pub pruned: f64,
}

impl FluxLedger {
    /// Sum of every destination.
    pub fn accounted(&self) -> f64 {
        self.direct
            + self.floor
            + self.reflected_away
            + self.transmitted_away
            + self.interaction_limit
            + self.pruned
    }

    fn add(&mut self, other: &FluxLedger) {
        self.emitted += other.emitted;
        self.direct += other.direct;
        self.floor += other.floor;
        self.reflected_away += other.reflected_away;
        self.transmitted_away += other.transmitted_away;
        self.interaction_limit += other.interaction_limit;
        self.pruned += other.pruned;
    }

    fn leaf(&mut self, leaf: &Leaf, flux: f64) {
        let f = flux * leaf.weight as f64;
        match leaf.end {
            End::Floor(_) => self.floor += f,
            End::Away if leaf.reflected_first => self.reflected_away += f,
            End::Away => self.transmitted_away += f,
            End::Limit => self.interaction_limit += f,
            End::Pruned => self.pruned += f,
        }
    }
}

/// Everything a bake produces.
#[derive(Clone, Debug)]
pub struct BakeOutput {
    /// The gain map with its inputs hash and parameters.
    pub bake: Bake,
    /// E_through / E_without per texel: light that met the object and reached the floor,
    /// relative to the unobstructed irradiance.
    pub through_rel: Vec<f32>,
    /// E_blocked / E_without per texel: the fraction of the direct light the object stops
    /// (1 in its full shadow).
    pub blocked_rel: Vec<f32>,
    /// Flux bookkeeping.
    pub ledger: FluxLedger,
    /// Sum of the floor flux map (should equal `ledger.floor` to rounding).
    pub floor_flux_deposited: f64,
    /// Wall-clock time of the bake.
    pub elapsed: Duration,
}

/// eq. 6 made per texel: the relative caustic gain G = max(0, E_with / E_without - 1) with
/// E_with = E_without - E_blocked + E_through, i.e. G = max(0, through_rel - blocked_rel).
/// With a Lambertian floor of recorded luminance L_r = rho E_without / pi, the floor with the
/// object is L_c = rho E_with / pi, so max(0, L_c - L_r) = G * L_r.
/// Gains below [`MIN_GAIN`] are stored as 0.
pub fn gain(through_rel: f32, blocked_rel: f32) -> f32 {
    let g = (through_rel - blocked_rel).max(0.0);
    if g < MIN_GAIN { 0.0 } else { g }
}

/// The floor's light with the object over that without it, `E_with / E_without = 1 -
/// blocked_rel + through_rel` (never below 0: rounding in the full shadow): below 1 in the
/// shadow, above in the caustic; what the glass sees of the floor under it.
/// Within [`MIN_GAIN`] of 1 it is stored as 1 (the faint light the glass spreads over the
/// whole floor, invisible, as the gain drops it), so that the EXR compresses.
pub fn light_ratio(through_rel: f32, blocked_rel: f32) -> f32 {
    let change = through_rel - blocked_rel;
    if change.abs() < MIN_GAIN {
        1.0
    } else {
        (1.0 + change).max(0.0)
    }
}

/// Smallest gain kept: a brightening of 0.1 % of the floor is invisible (well under one
/// 8-bit display step), and zeroing the faint light spread over the whole floor lets the EXR
/// compress to a small file.
pub const MIN_GAIN: f32 = 1e-3;

/// Bakes the caustic gain map. `progress` is called with (grid rows done, grid rows).
pub fn bake(
    scene: &CausticScene,
    params: &BakeParams,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<BakeOutput, InputError> {
    let start = Instant::now();
    if params.width_px == 0
        || params.height_px == 0
        || params.width_px > MAX_BAKE_SIDE_PX
        || params.height_px > MAX_BAKE_SIDE_PX
    {
        return Err(InputError::BadValue(format!(
            "the bake resolution must be 1..={MAX_BAKE_SIDE_PX} texels per side, found {} x {}",
            params.width_px, params.height_px
        )));
    }
    if params.budget_rays > 1 << 32 {
        return Err(InputError::BadValue(format!(
            "a budget of {} rays is more than this baker handles (at most 2^32)",
            params.budget_rays
        )));
    }
    if !(params.min_weight >= 0.0 && params.min_weight < 1.0) || params.max_interactions == 0 {
        return Err(InputError::BadValue(
            "min_weight must be in 0..1 and max_interactions at least 1".into(),
        ));
    }
    let tracer = Tracer::new(
        scene,
        params.width_px,
        params.height_px,
        params.max_interactions,
        params.min_weight,
    )?;
    let rotation_rad = seed_angle(params.seed);
    let cone = EmissionCone::new(
        tracer.light,
        glam::Vec3::ZERO,
        tracer.radius_m,
        rotation_rad,
    );
    let n = params.grid_cells();
    let emitted = cone.solid_angle_sr(); // intensity 1 per steradian
    let cell_flux = emitted / (n as f64 * n as f64);

    let through = FluxGrid::new(params.width_px, params.height_px, emitted);
    let blocked = FluxGrid::new(params.width_px, params.height_px, emitted);
    // Spans larger than this are not interpolated (they straddle something the corners
    // cannot see, or are so spread that they hardly matter).
    let max_span_px = params.width_px.max(params.height_px) as f32 / 8.0;

    const ROWS_PER_BAND: u32 = 16;
    let bands = n.div_ceil(ROWS_PER_BAND);
    let rows_done = AtomicU64::new(0);
    let ledgers: Vec<FluxLedger> = (0..bands)
        .into_par_iter()
        .map(|band| {
            let mut ledger = FluxLedger::default();
            let mut stack = Vec::new();
            let trace_row = |j: u32, leaves: &mut Vec<Leaf>, stack: &mut Vec<_>| -> Vec<Corner> {
                leaves.clear();
                (0..=n)
                    .map(|i| {
                        let dir = cone.direction(i as f64 / n as f64, j as f64 / n as f64);
                        tracer.trace(dir, leaves, stack)
                    })
                    .collect()
            };
            let j0 = band * ROWS_PER_BAND;
            let j1 = (j0 + ROWS_PER_BAND).min(n);
            let mut leaves_a = Vec::new();
            let mut leaves_b = Vec::new();
            let mut row_a = trace_row(j0, &mut leaves_a, &mut stack);
            let mut scratch = Scratch::default();
            let ctx = Splatter {
                tracer: &tracer,
                cone: &cone,
                through: &through,
                blocked: &blocked,
                max_span_px,
            };
            for j in j0..j1 {
                let row_b = trace_row(j + 1, &mut leaves_b, &mut stack);
                for i in 0..n as usize {
                    let c00 = cv(&row_a, &leaves_a, i, j, n);
                    let c10 = cv(&row_a, &leaves_a, i + 1, j, n);
                    let c01 = cv(&row_b, &leaves_b, i, j + 1, n);
                    let c11 = cv(&row_b, &leaves_b, i + 1, j + 1, n);
                    // Alternate the diagonal so the mesh has no preferred direction.
                    let tris = if (i as u32 + j).is_multiple_of(2) {
                        [[c00, c10, c11], [c00, c11, c01]]
                    } else {
                        [[c00, c10, c01], [c10, c11, c01]]
                    };
                    for t in tris {
                        ctx.triangle(t, cell_flux / 2.0, 0, &mut ledger, &mut scratch, &mut stack);
                    }
                }
                row_a = row_b;
                std::mem::swap(&mut leaves_a, &mut leaves_b);
                let done = rows_done.fetch_add(1, Ordering::Relaxed) + 1;
                progress(done, n as u64);
            }
            ledger
        })
        .collect();
    let mut ledger = FluxLedger::default();
    for l in &ledgers {
        ledger.add(l);
    }
    ledger.emitted = emitted;

    let through = through.into_flux();
    let blocked = blocked.into_flux();
    let floor_flux_deposited: f64 = through.iter().sum();

    // Unobstructed irradiance at each texel centre: E = I cos(theta) / r^2 (I = 1).
    let floor = &tracer.floor;
    let (w, h) = (params.width_px as usize, params.height_px as usize);
    let texel_area_m2 = floor.area_m2() as f64 / (w * h) as f64;
    let mut through_rel = vec![0.0f32; w * h];
    let mut blocked_rel = vec![0.0f32; w * h];
    let mut gain_map = vec![0.0f32; w * h];
    through_rel
        .par_chunks_mut(w)
        .zip(blocked_rel.par_chunks_mut(w))
        .zip(gain_map.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((tr, br), gr))| {
            for x in 0..w {
                let local = Vec2::new(
                    (x as f32 + 0.5) / w as f32 - 0.5,
                    0.5 - (y as f32 + 0.5) / h as f32,
                );
                let to_light = (tracer.light - floor.point(local)).as_dvec3();
                let r2 = to_light.length_squared();
                let cos = to_light.dot(floor.normal.as_dvec3()) / r2.sqrt();
                let e_without = cos / r2;
                let k = y * w + x;
                let norm = 1.0 / (texel_area_m2 * e_without);
                tr[x] = (through[k] * norm) as f32;
                br[x] = (blocked[k] * norm) as f32;
                gr[x] = gain(tr[x], br[x]);
            }
        });

    Ok(BakeOutput {
        bake: Bake {
            width_px: params.width_px,
            height_px: params.height_px,
            gain: gain_map,
            light: Some(
                through_rel
                    .iter()
                    .zip(&blocked_rel)
                    .map(|(&t, &b)| light_ratio(t, b))
                    .collect(),
            ),
            inputs_hash: Some(scene.inputs_hash.clone()),
            params: params.describe(),
        },
        through_rel,
        blocked_rel,
        ledger,
        floor_flux_deposited,
        elapsed: start.elapsed(),
    })
}

/// The grid rotation for a seed, radians.
fn seed_angle(seed: u64) -> f64 {
    if seed == 0 {
        return 0.0;
    }
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
}

#[derive(Default)]
struct Scratch {
    matched: [Vec<bool>; 3],
}

/// A corner of an emission triangle: its place on the unit square and its traced ray.
#[derive(Clone, Copy)]
struct CornerView<'a> {
    /// Emission-square coordinates.
    st: DVec2,
    /// The traced ray.
    corner: Corner,
    /// Its leaves, sorted by signature.
    leaves: &'a [Leaf],
}

fn cv<'a>(row: &[Corner], leaves: &'a [Leaf], i: usize, j: u32, n: u32) -> CornerView<'a> {
    let c = row[i];
    CornerView {
        st: DVec2::new(i as f64 / n as f64, j as f64 / n as f64),
        corner: c,
        leaves: &leaves[c.first_leaf as usize..(c.first_leaf + c.leaf_count) as usize],
    }
}

/// Emission triangles whose corners disagree (one hits the object and one does not, or a
/// path with at least this weight is not shared) are split in four, up to
/// [`MAX_REFINE_DEPTH`] times, so discontinuities (silhouettes, facet edges, the onset of
/// total internal reflection) are resolved 2^depth times finer than the grid.
const REFINE_WEIGHT: f32 = 0.03;
/// Most times an emission triangle is split.
const MAX_REFINE_DEPTH: u32 = 2;

/// Draws emission triangles onto the floor maps.
struct Splatter<'a> {
    tracer: &'a Tracer,
    cone: &'a EmissionCone,
    through: &'a FluxGrid,
    blocked: &'a FluxGrid,
    max_span_px: f32,
}

impl Splatter<'_> {
    /// Deposits one emission triangle's flux: paths shared by all three corners spread
    /// over their floor triangle; everything else at the corners, a third each, after
    /// refining where the corners disagree.
    fn triangle(
        &self,
        corners: [CornerView; 3],
        flux: f64,
        depth: u32,
        ledger: &mut FluxLedger,
        scratch: &mut Scratch,
        stack: &mut Vec<crate::trace::Ray>,
    ) {
        if depth < MAX_REFINE_DEPTH && disagree(&corners) {
            // The emission map is equal-area, so the four halves-of-edges triangles carry
            // exactly a quarter of the flux each.
            let mut owned: [Vec<Leaf>; 3] = Default::default();
            let mut mids = [Corner::default(); 3];
            let mut sts = [DVec2::ZERO; 3];
            for k in 0..3 {
                let (a, b) = (corners[k].st, corners[(k + 1) % 3].st);
                sts[k] = (a + b) / 2.0;
                let dir = self.cone.direction(sts[k].x, sts[k].y);
                mids[k] = self.tracer.trace(dir, &mut owned[k], stack);
            }
            let m = |k: usize| CornerView {
                st: sts[k],
                corner: mids[k],
                leaves: &owned[k],
            };
            let [a, b, c] = corners;
            let (ab, bc, ca) = (m(0), m(1), m(2));
            for t in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
                self.triangle(t, flux / 4.0, depth + 1, ledger, scratch, stack);
            }
            return;
        }
        let third = flux / 3.0;
        // The object's shadow: where the straight rays that hit it would have landed.
        let straight: [Option<Vec2>; 3] =
            corners.map(|c| c.corner.hit.then_some(c.corner.straight).flatten());
        match (straight[0], straight[1], straight[2]) {
            (Some(a), Some(b), Some(c)) if span(a, b, c) <= self.max_span_px => {
                self.blocked.triangle(a, b, c, flux)
            }
            _ => {
                for s in straight.iter().flatten() {
                    self.blocked.point(*s, third);
                }
            }
        }
        let leaves: [&[Leaf]; 3] = corners.map(|c| c.leaves);
        for (k, c) in corners.iter().enumerate() {
            if !c.corner.hit {
                ledger.direct += third;
            }
            for leaf in leaves[k] {
                ledger.leaf(leaf, third);
            }
            scratch.matched[k].clear();
            scratch.matched[k].resize(leaves[k].len(), false);
        }
        // Paths shared by all three corners (leaves are sorted by signature).
        for (i0, l0) in leaves[0].iter().enumerate() {
            let End::Floor(p0) = l0.end else { continue };
            let find = |k: usize| leaves[k].binary_search_by_key(&l0.sig, |l| l.sig).ok();
            let (Some(i1), Some(i2)) = (find(1), find(2)) else {
                continue;
            };
            let (l1, l2) = (&leaves[1][i1], &leaves[2][i2]);
            let (End::Floor(p1), End::Floor(p2)) = (l1.end, l2.end) else {
                continue;
            };
            if span(p0, p1, p2) > self.max_span_px {
                continue;
            }
            let w = (l0.weight + l1.weight + l2.weight) as f64;
            self.through.triangle(p0, p1, p2, third * w);
            scratch.matched[0][i0] = true;
            scratch.matched[1][i1] = true;
            scratch.matched[2][i2] = true;
        }
        for (list, matched) in leaves.iter().zip(&scratch.matched) {
            for (leaf, &done) in list.iter().zip(matched) {
                if let (End::Floor(p), false) = (leaf.end, done) {
                    self.through.point(p, third * leaf.weight as f64);
                }
            }
        }
    }
}

/// Whether the corners see different things: hit versus miss, or a path of some weight
/// that not all three share with the same kind of end.
fn disagree(c: &[CornerView; 3]) -> bool {
    if c[0].corner.hit != c[1].corner.hit || c[1].corner.hit != c[2].corner.hit {
        return true;
    }
    for k in 0..3 {
        for leaf in c[k].leaves {
            if leaf.weight < REFINE_WEIGHT {
                continue;
            }
            for other in [(k + 1) % 3, (k + 2) % 3] {
                match c[other].leaves.binary_search_by_key(&leaf.sig, |l| l.sig) {
                    Ok(i) if same_kind(c[other].leaves[i].end, leaf.end) => {}
                    _ => return true,
                }
            }
        }
    }
    false
}

fn same_kind(a: End, b: End) -> bool {
    std::mem::discriminant(&a) == std::mem::discriminant(&b)
}

fn span(a: Vec2, b: Vec2, c: Vec2) -> f32 {
    (b - a).length().max((c - b).length()).max((a - c).length())
}

/// How far a gain map is from a reference, over the reference's caustic region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Texels where the reference gain exceeds the threshold.
    pub region_texels: usize,
    /// Relative RMS difference: sqrt(sum (G - G_ref)^2 / sum G_ref^2) over the region.
    pub rel_rms: f64,
    /// Root mean square of the per-texel relative difference (G - G_ref) / G_ref over the
    /// region (weights dim and bright texels alike).
    pub rel_rms_per_texel: f64,
}

/// Gain above which a texel counts as part of the caustic region: 10 % more light than the
/// bare floor, a clearly visible brightening.
pub const CAUSTIC_REGION_GAIN: f32 = 0.1;

/// Compares `test` against `reference` (same size) over the reference's caustic region
/// (gain above `threshold`). Reference resolutions that differ are refused with `None`.
pub fn compare(test: &[f32], reference: &[f32], threshold: f32) -> Option<Comparison> {
    if test.len() != reference.len() {
        return None;
    }
    let (mut n, mut diff2, mut ref2, mut rel2) = (0usize, 0.0f64, 0.0f64, 0.0f64);
    for (&g, &r) in test.iter().zip(reference) {
        if r > threshold {
            let d = (g - r) as f64;
            n += 1;
            diff2 += d * d;
            ref2 += (r as f64).powi(2);
            rel2 += (d / r as f64).powi(2);
        }
    }
    Some(Comparison {
        region_texels: n,
        rel_rms: if ref2 > 0.0 {
            (diff2 / ref2).sqrt()
        } else {
            0.0
        },
        rel_rms_per_texel: if n > 0 { (rel2 / n as f64).sqrt() } else { 0.0 },
    })
}
