//! The distance field by jump flooding (shaders/inducer_field.wgsl `fs_seed`, `fs_jump`,
//! `fs_distance`): a seed pass writes each shadow texel's own coordinates, then
//! ceil(log2 N) passes with halving jumps plus one of jump 1 (JFA+1, which mends most of plain
//! jump flooding's rare misses) ping-pong two RG32F images of nearest-shadow-texel
//! coordinates (nearest in metres), and a last pass turns them into the distance d to the
//! shadow edge in metres for every lit texel, -1 inside the shadow (`edge_distance_m` in
//! [`super::reference`] on the CPU).
//!
//! The schedule is plain data ([`distance_passes`]); the floor pass records it.

use super::fields::{DISTANCE, MASK, SEEDS_A, SEEDS_B};

/// Indices into the floor pass's full-screen pipelines.
pub(crate) const SEED: usize = 0;
pub(crate) const JUMP: usize = 1;
pub(crate) const DIST: usize = 2;
pub(crate) const RAMP: usize = 3;
pub(crate) const COMBINE: usize = 4;

/// One full-screen pass over a floor-space field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FieldDraw {
    /// The field image written (an index of [`super::fields::FIELDS`]).
    pub target: usize,
    /// The pipeline ([`SEED`] ..= [`COMBINE`]).
    pub pipeline: usize,
    /// The field image read as the source (binding 0; the mask is always binding 1).
    pub source: usize,
    /// The jump, texels (0 outside jump passes).
    pub step: i32,
}

/// The jump of each jump-flooding pass over a region `span_px` texels across (the field's
/// side, or the side of the part of it the passes draw): halving jumps from half the next
/// power of two down to 1, then one more of 1.
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

/// The passes from the shadow mask to the distance field, in recording order: the seed pass
/// into [`SEEDS_A`], the jumps ping-ponging between [`SEEDS_A`] and [`SEEDS_B`], and the
/// distance pass into [`DISTANCE`] reading the last seeds written; `span_px` as in [`jumps`].
pub(crate) fn distance_passes(span_px: u32) -> Vec<FieldDraw> {
    let mut draws = vec![FieldDraw {
        target: SEEDS_A,
        pipeline: SEED,
        source: MASK,
        step: 0,
    }];
    let mut source = SEEDS_A;
    for step in jumps(span_px) {
        let target = if source == SEEDS_A { SEEDS_B } else { SEEDS_A };
        draws.push(FieldDraw {
            target,
            pipeline: JUMP,
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
        assert_eq!(draws.len(), 1 + jumps(16).len() + 1);
    }
}
