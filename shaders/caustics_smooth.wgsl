// The smoothing of the live caustic map (docs/caustics.md, *Smoothing*;
// render/src/floor/smoothing.rs plans its dispatches): the photons' sums (caustics_live.wgsl)
// taken as G = max(0, sum) per texel, as the bake stores it, and smoothed (density
// estimation: a lone photon's share spreads over the kernel, as a beam's does in the bake)
// with a box filter run three times along the rows, then three times along the columns, one
// dispatch each way (`cs_smooth_rows` and `cs_smooth_columns` for radii up to 2, which skip
// the tiles `cs_smooth_tiles` finds certain to hold no gain; `cs_smooth_wide` above); the
// last zeroes gains below MIN_GAIN (as in the bake) and bounds the non-zero texels, which the
// overlay covers. Without smoothing a single dispatch along the columns does only the
// latter.
//
// On a CPU device (lavapipe) every access of a storage buffer is a loop over the SIMD lanes,
// so the passes move four texels per access where they can.

// #include shared/caustics_maps.wgsl

// Which smoothing pass a dispatch runs (`smooth_steps` in smoothing.rs): bit 0 clear along the
// rows, set along the columns; bit 1 set when a pass along the columns reads the photons'
// sums itself (no smoothing); bit 8 set on the last pass, which writes the gain map.
struct SmoothStep {
    bits: u32,
};
var<push_constant> smooth_step: SmoothStep;

const COLUMNS_STEP: u32 = 0x1u;
const FROM_SUMS_STEP: u32 = 0x2u;
const LAST_STEP: u32 = 0x100u;
// Most texels in one box: 2 x 64 + 1 (`MAX_SMOOTHING_PX` in live.rs).
const MAX_BOX: u32 = 129u;
// Largest radius the short kernel takes (`SHORT_KERNEL_PX` in smoothing.rs).
const SHORT_KERNEL_PX: u32 = 2u;

// Widens the bound of the non-zero gains by the box [lo, hi] (texels, ends included).
fn widen_bounds(lo: vec2<u32>, hi: vec2<u32>) {
    atomicMin(&bounds[0], lo.x);
    atomicMin(&bounds[1], lo.y);
    atomicMax(&bounds[2], hi.x);
    atomicMax(&bounds[3], hi.y);
}

// The kernel of the box of 2 radius + 1 texels applied three times, for a radius of 0, 1
// or 2, over a window of 13 texels (slot 6 the centre): integer weights over their sum (1, 27,
// 125).
fn short_kernel(radius: u32) -> array<vec4<f32>, 4> {
    if radius == 2u {
        let k = 1.0 / 125.0;
        return array<vec4<f32>, 4>(vec4<f32>(1.0, 3.0, 6.0, 10.0) * k,
            vec4<f32>(15.0, 18.0, 19.0, 18.0) * k, vec4<f32>(15.0, 10.0, 6.0, 3.0) * k,
            vec4<f32>(1.0, 0.0, 0.0, 0.0) * k);
    }
    if radius == 1u {
        let k = 1.0 / 27.0;
        return array<vec4<f32>, 4>(vec4<f32>(0.0, 0.0, 0.0, 1.0) * k,
            vec4<f32>(3.0, 6.0, 7.0, 6.0) * k, vec4<f32>(3.0, 1.0, 0.0, 0.0) * k,
            vec4<f32>(0.0));
    }
    return array<vec4<f32>, 4>(vec4<f32>(0.0), vec4<f32>(0.0, 0.0, 1.0, 0.0), vec4<f32>(0.0),
        vec4<f32>(0.0));
}

// The last 13 inputs of a stream of texels, oldest first (`w3` the newest), in registers.
struct Window {
    w0: vec4<f32>,
    w1: vec4<f32>,
    w2: vec4<f32>,
    w3: f32,
};

// Feeds the next input `v` to `w` (the inputs before the first count as 0); returns the
// smoothed value of the input 6 back (the window's centre).
fn window_feed(w: ptr<function, Window>, v: f32, k: array<vec4<f32>, 4>) -> f32 {
    (*w).w0 = vec4<f32>((*w).w0.yzw, (*w).w1.x);
    (*w).w1 = vec4<f32>((*w).w1.yzw, (*w).w2.x);
    (*w).w2 = vec4<f32>((*w).w2.yzw, (*w).w3);
    (*w).w3 = v;
    return dot((*w).w0, k[0]) + dot((*w).w1, k[1]) + dot((*w).w2, k[2]) + (*w).w3 * k[3].x;
}

// The weight of the box of 2 radius + 1 texels applied three times at `d` texels from the
// centre: the ways to write d as a sum of three integers in [-radius, radius], over their
// count (2 radius + 1)^3.
fn kernel_weight(radius: u32, d: i32) -> f32 {
    let r = i32(radius);
    var ways = 0;
    for (var a = -r; a <= r; a++) {
        ways += max(0, 2 * r + 1 - abs(d - a));
    }
    let n = f32(2 * r + 1);
    return f32(ways) / (n * n * n);
}

// The kernel's largest weights between the texels of a tile (8 along an axis, from 8t) and
// those of deposits in each of the six cells 2t - 2 .. 2t + 3 along that axis (texels
// [4c, 4c + 4]): 4, 0, 0, 0, 1 and 5 texels apart. Cells further off are 8 texels or more
// away, beyond the short kernel's reach.
struct CellWeights {
    near: vec4<f32>,
    far: vec2<f32>,
};

fn cell_weights(radius: u32) -> CellWeights {
    return CellWeights(
        vec4<f32>(kernel_weight(radius, 4), kernel_weight(radius, 0), kernel_weight(radius, 0),
            kernel_weight(radius, 0)),
        vec2<f32>(kernel_weight(radius, 1), kernel_weight(radius, 5)));
}

// The word of bits that holds tile `x` of tile row `y` (see `tile_bits`); 0 beyond the map.
fn tile_word(x: u32, y: i32) -> u32 {
    if y < 0 || y >= i32(p.tiles.y) {
        return 0u;
    }
    return tile_bits[u32(y) * p.tiles.z + x / 32u];
}

// The masses of cells 4g .. 4g + 3 in cell row y (0 beyond the map).
fn cell_row(y: i32, g: u32, pitch4: u32) -> vec4<f32> {
    if y < 0 || u32(y) >= 2u * p.tiles.y {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(cell_mass4[u32(y) * pitch4 + g]);
}

// The bits of the tiles the smoothing writes, one tile row per invocation: a tile's bound is
// the sum over the 6 x 6 cells around it of each cell's mass times the kernel's largest
// weight between their texels (the kernel is separable), and the tile is written when the
// bound reaches 0.999 MIN_GAIN (room for rounding: the bound and the passes' f32 sums are
// each good to about 1e-5 of the exact values, and the masses are exact integers). Along the
// row the cells are read four at a time: the sum of each column of four cells over the six
// cell rows, then each tile's six columns from the last two of those sums.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let row = id.x;
    let across = p.tiles.x;
    if row >= p.tiles.y {
        return;
    }
    let w = cell_weights(p.map.w);
    let pitch4 = mass_pitch(across) / 4u;
    let threshold = 0.999 * p.misc.w * p.misc.y / f32(MASS_UNIT);
    let top = i32(2u * row) - 2;
    var previous = vec4<f32>(0.0);
    var bits = 0u;
    for (var g = 0u; g <= pitch4; g++) {
        // The six cell rows' masses of cells 4g .. 4g + 3, weighted and summed.
        var column = vec4<f32>(0.0);
        if g < pitch4 {
            column = w.near.x * cell_row(top, g, pitch4) + w.near.y * cell_row(top + 1, g, pitch4)
                + w.near.z * cell_row(top + 2, g, pitch4) + w.near.w * cell_row(top + 3, g, pitch4)
                + w.far.x * cell_row(top + 4, g, pitch4) + w.far.y * cell_row(top + 5, g, pitch4);
        }
        // Tiles 2g - 1 (cells 4g - 4 .. 4g + 1) and 2g (cells 4g - 2 .. 4g + 3).
        for (var k = 0u; k < 2u; k++) {
            let tile = 2u * g + k;
            if tile == 0u || tile > across {
                continue;
            }
            let x = tile - 1u;
            var bound = 0.0;
            if k == 0u {
                bound = dot(previous, w.near) + dot(column.xy, w.far);
            } else {
                bound = dot(vec4<f32>(previous.zw, column.xy), w.near) + dot(column.zw, w.far);
            }
            if bound > 0.0 && bound >= threshold {
                bits |= 1u << (x % 32u);
            }
            if x % 32u == 31u || x + 1u == across {
                tile_bits[row * p.tiles.z + x / 32u] = bits;
                bits = 0u;
            }
        }
        previous = column;
    }
}

// The short kernel (radius <= 2) along the rows, one row per invocation, four texels per
// step: reads G = max(0, sum) of the photons' sums (eq. 6's clamp, per texel as the bake
// stores it) and writes the row's smoothed values (fixed-point units) into `scratch`. On a
// CPU device each access of a storage buffer is a loop over the lanes, so a texel's cost
// is its share of the accesses: a quarter of a read and of a write here. When the smoothing
// skips tiles, only the tiles whose rows the pass along the columns reads (those it writes
// and those above and below them) are written: the row is walked tile by tile, and the
// window, fed the two vectors before a tile that follows a skipped one, holds the same inputs
// there as it would along the whole row.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.map.y {
        return;
    }
    let blocks = row_pitch(p.map.x) / 4u;
    let base = id.x * blocks;
    let k = short_kernel(p.map.w);
    let skip = p.tiles.w != 0u;
    // The spans walked: the tiles along the row, or the whole row as one.
    let spans = select(1u, p.tiles.x, skip);
    let span_blocks = select(blocks, u32(TILE) / 4u, skip);
    let tile_row = id.x / u32(TILE);
    var w = Window(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), 0.0);
    var previous = vec4<f32>(0.0);
    // The next block the window takes.
    var next = 0u;
    var bits = 0u;
    for (var s = 0u; s < spans; s++) {
        if skip {
            if s % 32u == 0u {
                // The pass along the columns reads the rows of the tiles it writes and of
                // those above and below them.
                let y = i32(tile_row);
                bits = tile_word(s, y - 1) | tile_word(s, y) | tile_word(s, y + 1);
            }
            if (bits & (1u << (s % 32u))) == 0u {
                continue;
            }
        }
        let first = s * span_blocks;
        let end = min(first + span_blocks, blocks);
        next = max(next, max(first, 2u) - 2u);
        // After block b (texels 4b..4b+3) the window yields texels 4b-6..4b-3, so block b-2
        // is the last two of the step before and the first two of this one.
        for (; next < end + 2u; next++) {
            var v = vec4<f32>(0.0);
            if next < blocks {
                v = vec4<f32>(max(sums4[base + next], vec4<i32>(0)));
            }
            let out = vec4<f32>(window_feed(&w, v.x, k), window_feed(&w, v.y, k),
                window_feed(&w, v.z, k), window_feed(&w, v.w, k));
            if next >= first + 2u {
                scratch[base + next - 2u] = vec4<f32>(previous.zw, out.xy);
            }
            previous = out;
        }
    }
}

// The short kernel along the columns, four adjacent columns per invocation, one row per
// step: reads the rows' result (or, without smoothing, G = max(0, sum) of the photons' sums
// directly), writes the gain map with gains below MIN_GAIN zeroed, and bounds the non-zero
// texels. When the smoothing skips tiles, only the tiles of `tile_bits` are written (the CPU
// has zeroed the map), walked as the rows' pass walks its tiles.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let blocks = row_pitch(p.map.x) / 4u;
    if id.x >= blocks {
        return;
    }
    let from_sums = (smooth_step.bits & FROM_SUMS_STEP) != 0u;
    let height = p.map.y;
    let k = short_kernel(p.map.w);
    let unit = p.misc.y;
    let min_gain = p.misc.w;
    let skip = p.tiles.w != 0u;
    let spans = select(1u, p.tiles.y, skip);
    let span_rows = select(height, u32(TILE), skip);
    let tile = id.x / (u32(TILE) / 4u);
    let x = vec4<u32>(4u * id.x) + vec4<u32>(0u, 1u, 2u, 3u);
    let on_map = x < vec4<u32>(p.map.x);
    let zero = Window(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), 0.0);
    var c0 = zero;
    var c1 = zero;
    var c2 = zero;
    var c3 = zero;
    var first = NONE;
    var final_row = 0u;
    var kept_columns = vec4<bool>(false);
    // The next row the windows take.
    var next = 0u;
    for (var s = 0u; s < spans; s++) {
        if skip && (tile_word(tile, i32(s)) & (1u << (tile % 32u))) == 0u {
            continue;
        }
        let top = s * span_rows;
        let end = min(top + span_rows, height);
        next = max(next, max(top, 6u) - 6u);
        for (; next < end + 6u; next++) {
            var v = vec4<f32>(0.0);
            if next < height {
                if from_sums {
                    v = vec4<f32>(max(sums4[next * blocks + id.x], vec4<i32>(0)));
                } else {
                    v = scratch[next * blocks + id.x];
                }
            }
            let mean = vec4<f32>(window_feed(&c0, v.x, k), window_feed(&c1, v.y, k),
                window_feed(&c2, v.z, k), window_feed(&c3, v.w, k));
            if next < top + 6u {
                continue;
            }
            let at = next - 6u;
            let g = mean / unit;
            let kept = g >= vec4<f32>(min_gain) & on_map;
            gain[at * blocks + id.x] = select(vec4<f32>(0.0), g, kept);
            if any(kept) {
                first = min(first, at);
                final_row = at;
                kept_columns = kept_columns | kept;
            }
        }
    }
    if first != NONE {
        // The first and last kept of the four columns.
        let lo = select(select(select(x.w, x.z, kept_columns.z), x.y, kept_columns.y), x.x,
            kept_columns.x);
        let hi = select(select(select(x.x, x.y, kept_columns.y), x.z, kept_columns.z), x.w,
            kept_columns.w);
        widen_bounds(vec2<u32>(lo, first), vec2<u32>(hi, final_row));
    }
}

// A box mean over a stream of texels: the last 2 radius + 1 inputs and their sum, exactly in
// 64 bits (low and high words), so that nothing drifts along a line.
struct RunningBox {
    ring: array<u32, MAX_BOX>,
    low: u32,
    high: u32,
    slot: u32,
};

// Feeds the next input `v` of the stream to `b` (the inputs before the first count as 0);
// returns the mean of the 2 radius + 1 inputs centred `radius` inputs back.
fn box_feed(b: ptr<function, RunningBox>, v: u32, radius: u32) -> f32 {
    let span = 2u * radius + 1u;
    let slot = (*b).slot;
    let old = (*b).ring[slot];
    (*b).ring[slot] = v;
    (*b).slot = select(slot + 1u, 0u, slot + 1u == span);
    (*b).low += v;
    (*b).high += select(0u, 1u, (*b).low < v);
    (*b).high -= select(0u, 1u, (*b).low < old);
    (*b).low -= old;
    return (f32((*b).high) * 4294967296.0 + f32((*b).low)) / f32(span);
}

// Radii above SHORT_KERNEL_PX: the smoothing along one line (a row or a column) per
// invocation, the box of 2 radius + 1 texels three times over, streamed through ring buffers
// (each box's means feed the next, rounded to fixed point, and texels beyond the map's edge
// count as 0 at every box: their light is lost, as off the floor), so that the cost does not
// grow with the radius. Along the rows it reads G = max(0, sum) of the photons' sums; the
// last pass, along the columns, zeroes gains below MIN_GAIN and bounds the non-zero texels.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_wide(@builtin(global_invocation_id) id: vec3<u32>) {
    let columns = (smooth_step.bits & COLUMNS_STEP) != 0u;
    let last = (smooth_step.bits & LAST_STEP) != 0u;
    let width = p.map.x;
    let pitch = row_pitch(p.map.x);
    let lines = select(p.map.y, width, columns);
    let length = select(width, p.map.y, columns);
    if id.x >= lines {
        return;
    }
    let stride = select(1u, pitch, columns);
    let start = select(id.x * pitch, id.x, columns);
    let radius = p.map.w;
    let unit = p.misc.y;
    let min_gain = p.misc.w;
    var box1: RunningBox;
    var box2: RunningBox;
    var box3: RunningBox;
    var first = NONE;
    var final_texel = 0u;
    // Texel n of the line enters the first box; each box's mean for a texel comes out radius
    // inputs after the texel entered it, so the third's for texel i at input i + 3 radius.
    for (var n = 0u; n < length + 3u * radius; n++) {
        var v = 0u;
        if n < length {
            let index = start + n * stride;
            if columns {
                v = u32(scratch[index / 4u][index % 4u]);
            } else {
                v = u32(max(sums4[index / 4u][index % 4u], 0));
            }
        }
        let mean1 = box_feed(&box1, v, radius);
        if n < radius {
            continue;
        }
        let at1 = n - radius;
        let mean2 = box_feed(&box2, select(0u, u32(round(mean1)), at1 < length), radius);
        if at1 < radius {
            continue;
        }
        let at2 = at1 - radius;
        let mean = box_feed(&box3, select(0u, u32(round(mean2)), at2 < length), radius);
        if at2 < radius {
            continue;
        }
        let at = at2 - radius;
        let index = start + at * stride;
        if last {
            let g = mean / unit;
            let kept = g >= min_gain;
            gain[index / 4u][index % 4u] = select(0.0, g, kept);
            if kept {
                first = min(first, at);
                final_texel = at;
            }
        } else {
            scratch[index / 4u][index % 4u] = round(mean);
        }
    }
    if first != NONE {
        // Along the line from `first` to `final_texel`; across it, the line itself.
        widen_bounds(select(vec2<u32>(first, id.x), vec2<u32>(id.x, first), columns),
            select(vec2<u32>(final_texel, id.x), vec2<u32>(id.x, final_texel), columns));
    }
}
