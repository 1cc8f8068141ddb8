//! The smoothing of the live caustic map (docs/caustics.md, *Smoothing*): which compute
//! passes of shaders/caustics_live.wgsl run for a box radius, in what order, with which push
//! constant, and how the map's buffers lay out their rows. The box of 2 r + 1 texels runs
//! three times along the rows, then three times along the columns; radii up to
//! [`SHORT_KERNEL_PX`] apply the resulting 6 r + 1 weights from registers, four texels per
//! access of memory, wider ones stream each line through ring buffers.

/// Invocations per workgroup of the smoothing's passes.
pub(super) const SMOOTH_GROUP: u32 = 64;
/// Largest radius the smoothing's short kernel takes (`SHORT_KERNEL_PX` in
/// caustics_live.wgsl): its 6 r + 1 = 13 weights fit in registers.
const SHORT_KERNEL_PX: u32 = 2;
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
}

/// The smoothing's dispatches, in order, for a box of `radius` texels: its pass and push
/// constant. Along the rows, then along the columns (the last); without smoothing one pass
/// along the columns that reads the sums, clamps, zeroes and bounds.
pub(super) fn smooth_steps(radius: u32) -> Vec<(SmoothPass, u32)> {
    match radius {
        0 => vec![(
            SmoothPass::Columns,
            COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP,
        )],
        r if r <= SHORT_KERNEL_PX => vec![
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::floor::live::MAX_SMOOTHING_PX;

    #[test]
    fn smoothing_runs_along_rows_then_columns_or_once_without_a_box() {
        use SmoothPass::*;
        let once = COLUMNS_STEP | FROM_SUMS_STEP | LAST_STEP;
        assert_eq!(smooth_steps(0), vec![(Columns, once)]);
        let short = vec![(Rows, 0), (Columns, COLUMNS_STEP | LAST_STEP)];
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
}
