//! The distance field by jump flooding (shaders/inducer_field.wgsl `fs_seed_jump`,
//! `fs_jump`, `fs_distance`): passes with halving jumps plus one more of jump 1 (JFA+1, which
//! mends most of plain jump flooding's rare misses) ping-pong two R32_UINT images of
//! nearest-shadow-texel coordinates (x | y << 16, nearest in metres), the first taking its seeds straight
//! from the shadow mask (every shadow texel is its own seed), and a last pass turns them into
//! the distance d to the shadow edge in metres for every lit texel, -1 inside the shadow
//! (`edge_distance_m` in [`super::reference`] on the CPU).
//!
//! The passes draw only the region that can change (the overlay's rectangle: the shadow and
//! its ramp), and the jumps start from what that region's span needs, or what a texel within
//! D of the shadow needs if that is less: d only matters below D (eq. 2), and a flood whose
//! jumps add up to at least the distance reaches every texel that near a seed.
//!
//! The schedule is plain data ([`distance_passes`]); the floor pass records it.

use super::fields::{DISTANCE, MASK, SEEDS_A, SEEDS_B};

/// Indices into the floor pass's full-screen pipelines.
pub(crate) const SEED_JUMP: usize = 0;
pub(crate) const JUMP: usize = 1;
pub(crate) const DIST: usize = 2;
pub(crate) const RAMP: usize = 3;
pub(crate) const COMBINE: usize = 4;

/// One full-screen pass over a floor-space field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FieldDraw {
    /// The field image written (an index of [`super::fields::FIELDS`]).
    pub target: usize,
    /// The pipeline ([`SEED_JUMP`] ..= [`COMBINE`]).
    pub pipeline: usize,
    /// The field image read as the source (binding 0; the mask is always binding 1).
    pub source: usize,
    /// The jump, texels (0 outside jump passes).
    pub step: i32,
}

/// The jump of each jump-flooding pass over a region `span_px` texels across (the field's
/// side, the side of the part of it the passes draw, or the farthest a seed must reach):
/// halving jumps from half the next power of two down to 1, then one more of 1. They add up
/// to at least `span_px`.
pub(crate) fn jumps(span_px: u32) -> Vec<i32> {
    let mut jumps = Vec::new();
    let mut step = span_px.max(1).next_power_of_two() / 2;
    while step >= 1 {
        jumps.push(step as i32);
        step /= 2;
    }
    jumps.push(1);
    jumps
}

/// The span the jumps must cover in a region `region_px` texels across for a ramp `reach_px`
/// texels wide: the region's, or the ramp's plus two texels (the half-texel edge offset and
/// rounding) if that is less.
pub(crate) fn flood_span(region_px: u32, reach_px: u32) -> u32 {
    region_px.min(reach_px.saturating_add(2))
}

/// The passes from the shadow mask to the distance field, in recording order: the first
/// jump seeded from [`MASK`] into [`SEEDS_A`], the others ping-ponging between [`SEEDS_A`]
/// and [`SEEDS_B`], and the distance pass into [`DISTANCE`] reading the last seeds written;
/// `span_px` as in [`jumps`].
pub(crate) fn distance_passes(span_px: u32) -> Vec<FieldDraw> {
    let mut draws = Vec::new();
    let mut source = MASK;
    for step in jumps(span_px) {
        let (target, pipeline) = match source {
            MASK => (SEEDS_A, SEED_JUMP),
            SEEDS_A => (SEEDS_B, JUMP),
            _ => (SEEDS_A, JUMP),
        };
        draws.push(FieldDraw {
            target,
            pipeline,
            source,
            step,
        });
        source = target;
    }
    draws.push(FieldDraw {
        target: DISTANCE,
        pipeline: DIST,
        source,
        step: 0,
    });
    draws
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jumps_halve_from_half_the_side_and_end_with_an_extra_one() {
        assert_eq!(jumps(512), vec![256, 128, 64, 32, 16, 8, 4, 2, 1, 1]);
        // A side that is not a power of two starts from half the next one.
        assert_eq!(jumps(20), vec![16, 8, 4, 2, 1, 1]);
    }

    #[test]
    fn distance_passes_ping_pong_and_read_what_the_previous_pass_wrote() {
        let draws = distance_passes(16);
        assert_eq!(
            draws.first().map(|d| (d.target, d.source)),
            Some((SEEDS_A, MASK))
        );
        for pair in draws.windows(2) {
            assert_eq!(pair[1].source, pair[0].target, "{pair:?}");
            assert_ne!(pair[1].target, pair[1].source, "{pair:?}");
        }
        let last = draws.last().expect("non-empty");
        assert_eq!((last.target, last.pipeline), (DISTANCE, DIST));
        // The first jump seeds itself from the mask: no pass of its own.
        assert_eq!(draws.len(), jumps(16).len() + 1);
        assert_eq!((draws[0].pipeline, draws[0].step), (SEED_JUMP, 8));
        assert!(draws[1..].iter().all(|d| d.pipeline != SEED_JUMP));
    }

    #[test]
    fn jumps_reach_the_span_and_stop_at_what_the_ramp_needs() {
        for span in 1..600 {
            let reach: i32 = jumps(span).iter().sum();
            assert!(reach >= span as i32, "{span}: {reach}");
        }
        // A 205-texel region with a 72-texel ramp floods over 74 texels.
        assert_eq!(flood_span(205, 72), 74);
        assert_eq!(jumps(74), vec![64, 32, 16, 8, 4, 2, 1, 1]);
        // A region smaller than the ramp floods over itself.
        assert_eq!(flood_span(40, 72), 40);
    }
}
