//! The smoothing of the live caustic map (docs/caustics.md, *Smoothing*): which compute
//! passes of shaders/caustics_live.wgsl run for a box radius, in what order, with which push
//! constant, and how the map's buffers lay out their rows. The box of 2 r + 1 texels runs
//! three times along the rows, then three times along the columns; radii up to
//! [`SHORT_KERNEL_PX`] apply the resulting 6 r + 1 weights from registers, four texels per
//! access of memory, wider ones stream each line through ring buffers.
//!
//! The short kernel's passes skip the tiles of [`TILE_PX`] texels whose smoothed gains are
//! certain to be stored as 0: each photon's deposit adds its positive share of G to the mass
//! of its cell of 4 x 4 texels, and a pass (`cs_smooth_tiles`) bounds each tile's gains by
//! the masses of the cells within the kernel's reach, weighted by the kernel's largest
//! weight between them, into bits of the tiles to write.

/// Invocations per workgroup of the smoothing's passes.
pub(super) const SMOOTH_GROUP: u32 = 64;
/// Largest radius the smoothing's short kernel takes (`SHORT_KERNEL_PX` in
/// caustics_live.wgsl): its 6 r + 1 = 13 weights fit in registers.
pub(super) const SHORT_KERNEL_PX: u32 = 2;
/// Side of the smoothing's tiles, texels (`TILE` in caustics_live.wgsl): a multiple of the
/// four texels a pass moves per access, and at least the short kernel's reach (3 r = 6), so
/// that a tile's gains depend on its own and its neighbours' texels only.
pub(super) const TILE_PX: u32 = 8;
// The passes' tile arithmetic: a tile is two cells of four texels along each axis, and the
// kernel reaches no further than the next tile.
const _: () = assert!(TILE_PX == 8 && 3 * SHORT_KERNEL_PX <= TILE_PX);
/// Flags of a smoothing step (`COLUMNS_STEP`, `FROM_SUMS_STEP`, `LAST_STEP` in
/// caustics_live.wgsl): along the columns; reading the photons' sums (no smoothing); the last.
pub(super) const COLUMNS_STEP: u32 = 0x1;
const FROM_SUMS_STEP: u32 = 0x2;
const LAST_STEP: u32 = 0x100;

/// A smoothing pass's shader (index into `shaders::CAUSTICS_SMOOTH_CS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SmoothPass {
    /// The short kernel along the rows, one row per invocation.
    Rows = 0,
    /// The short kernel along the columns, four columns per invocation.
    Columns = 1,
    /// Ring buffers, one row or column per invocation.
    Wide = 2,
    /// The tiles' bits from the cells' masses, one tile row per invocation.
    Tiles = 3,
}

/// The smoothing's dispatches, in order, for a box of `radius` texels: its pass and push
/// constant. The tiles' bits for the short kernel, then along the rows, then along the columns
/// (the last); without smoothing one pass along the columns that reads the sums, clamps,
/// zeroes and bounds.
pub(super) fn smooth_steps(radius: u32) -> Vec<(SmoothPass, u32)> {
    match radius {
        0 => vec![
            (SmoothPass::Tiles, 0),
            (
                SmoothPass::Columns,
                COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP,
            ),
        ],
        r if r <= SHORT_KERNEL_PX => vec![
            (SmoothPass::Tiles, 0),
            (SmoothPass::Rows, 0),
            (SmoothPass::Columns, COLUMNS_STEP | LAST_STEP),
        ],
        _ => vec![
            (SmoothPass::Wide, 0),
            (SmoothPass::Wide, COLUMNS_STEP | LAST_STEP),
        ],
    }
}

/// Texels from one row of the map's buffers to the next: the width rounded up to whole
/// vectors of four (`row_pitch` in caustics_live.wgsl).
pub(super) fn row_pitch(width: u32) -> u32 {
    width.next_multiple_of(4)
}

/// The tiles of a `width` x `height` map's buffers: across, down, and words of bits per tile
/// row (`tiles.xyz` in caustics_live.wgsl).
pub(super) fn tile_layout(width: u32, height: u32) -> [u32; 3] {
    let across = row_pitch(width).div_ceil(TILE_PX);
    [across, height.div_ceil(TILE_PX), across.div_ceil(32)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::floor::live::MAX_SMOOTHING_PX;

    #[test]
    fn smoothing_runs_along_rows_then_columns_or_once_without_a_box() {
        use SmoothPass::*;
        let once = COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP;
        assert_eq!(smooth_steps(0), vec![(Tiles, 0), (Columns, once)]);
        let short = vec![(Tiles, 0), (Rows, 0), (Columns, COLUMNS_STEP | LAST_STEP)];
        assert_eq!(smooth_steps(1), short);
        assert_eq!(smooth_steps(2), short);
        let wide = vec![(Wide, 0), (Wide, COLUMNS_STEP | LAST_STEP)];
        assert_eq!(smooth_steps(3), wide);
        assert_eq!(smooth_steps(MAX_SMOOTHING_PX), wide);
    }

    #[test]
    fn rows_are_padded_to_whole_vectors_of_four() {
        assert_eq!(row_pitch(990), 992);
        assert_eq!(row_pitch(992), 992);
        assert_eq!(row_pitch(1), 4);
    }

    #[test]
    fn tiles_cover_the_padded_rows_with_whole_words_of_bits() {
        assert_eq!(tile_layout(990, 990), [124, 124, 4]);
        assert_eq!(tile_layout(66, 66), [9, 9, 1]);
        assert_eq!(tile_layout(1, 1), [1, 1, 1]);
    }
}
