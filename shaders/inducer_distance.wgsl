// Nearest shadow texel of every texel of the fields' region (METHOD.md section 1; the distance
// d of eq. 2; render/src/floor/distance_transform.rs): an exact Euclidean distance transform
// of the shadow mask in two compute passes (separable, as Felzenszwalb and Huttenlocher's):
//
// 1. cs_columns, one invocation per column of the region: the row of the nearest shadow
//    texel in the column (two sweeps), four rows per access of memory.
// 2. cs_rows, one invocation per row of the area: over the columns, the lower envelope of the
//    parabolas (x - q)^2 + ((row_q - y) ty / tx)^2, whose minimum at x is the squared distance
//    (in units of tx) to the nearest shadow texel; each texel of the region gets that texel,
//    packed as x | y << 16 (for fs_distance, in shaders/inducer_field.wgsl, when the fields
//    are read back), and the inducer's gain k alpha(d) (eq. 2 and 4), packed as half floats,
//    which the CPU side copies into the gain texture the floor overlay filters. The envelope's
//    newest parabola is kept in registers, so that the common case (the newest parabola
//    stays) reads nothing back.
//
// Only the region is read, and nothing outside it is a seed (the region holds the whole
// shadow); the gain is 0 in the rest of the area (where the last computation wrote). Lavapipe
// compiles every access of a storage buffer into a loop over the SIMD lanes, so the passes
// access memory as rarely as they can.

// #include shared/inducer_ramp.wgsl

struct Transform {
    // The region: x0, y0, x1, y1 (ends excluded), texels.
    region: vec4<i32>,
    // The area the gain is written in (the region, and where the last computation wrote it):
    // x0, y0, x1, y1, texels.
    area: vec4<i32>,
    // (ty / tx)^2 of the floor metres per texel along x (tx) and y (ty).
    aspect2: f32,
    // Side of the fields, texels.
    size: i32,
    // Words per column of column_nearest and per row of nearest and gains: size rounded up to
    // a multiple of 4.
    pitch: i32,
    // D of eq. 2, metres.
    ramp_width_m: f32,
    // The floor metres per texel along x and y.
    texel_m: vec2<f32>,
    // k of eq. 4.
    k: f32,
};

var<push_constant> transform: Transform;
@group(0) @binding(0) var mask: texture_2d<f32>;
// Per column, four rows per entry (column x, rows 4c to 4c + 3 at x * pitch / 4 + c): the row
// of the nearest shadow texel in the column, NONE if none.
@group(0) @binding(1) var<storage, read_write> column_nearest: array<vec4<u32>>;
// Per row (stride size + 1): the envelope's parabolas (their columns) ...
@group(0) @binding(2) var<storage, read_write> envelope: array<i32>;
// ... and, per parabola, where it begins along the row and its height at its column plus the
// column squared (the term the intersection of two parabolas takes).
@group(0) @binding(3) var<storage, read_write> starts: array<vec2<f32>>;
// Per texel, four per entry (row y, columns 4c to 4c + 3 at y * pitch / 4 + c): the nearest
// shadow texel, x | y << 16, NONE if none.
@group(0) @binding(4) var<storage, read_write> nearest: array<vec4<u32>>;
// Per texel, four per entry (as `nearest`), the gain k alpha(d) as half floats, two per word.
@group(0) @binding(5) var<storage, read_write> gains: array<vec2<u32>>;

const NONE: u32 = 0xffffffffu;
const INF: f32 = 1.0e30;

// Whether texel (x, y) is in the shadow; rows outside the region are not.
fn shadow(x: i32, y: i32) -> bool {
    return y >= transform.region.y && y < transform.region.w
        && textureLoad(mask, vec2<i32>(x, y), 0).r > 0.5;
}

// Downwards: the nearest shadow row at or above row y, given that of the row before.
fn at_or_above(x: i32, y: i32, above: u32) -> u32 {
    return select(above, u32(y), shadow(x, y));
}

// Upwards: given the nearest shadow row at or above row y (`up`) and at or below it (`below`,
// updated), the nearer of the two (above on a tie).
fn nearer(y: i32, up: u32, below: ptr<function, u32>) -> u32 {
    if up == u32(y) {
        *below = u32(y);
    }
    if *below != NONE && (up == NONE || *below - u32(y) < u32(y) - up) {
        return *below;
    }
    return up;
}

@compute @workgroup_size(64, 1, 1)
fn cs_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = transform.region.x + i32(id.x);
    if x >= transform.region.z {
        return;
    }
    let base = x * (transform.pitch / 4);
    // The entries holding the region's rows.
    let first = transform.region.y / 4;
    let end = (transform.region.w + 3) / 4;
    var above = NONE;
    for (var c = first; c < end; c++) {
        let y = 4 * c;
        var rows: vec4<u32>;
        above = at_or_above(x, y, above);
        rows.x = above;
        above = at_or_above(x, y + 1, above);
        rows.y = above;
        above = at_or_above(x, y + 2, above);
        rows.z = above;
        above = at_or_above(x, y + 3, above);
        rows.w = above;
        column_nearest[base + c] = rows;
    }
    var below = NONE;
    for (var c = end - 1; c >= first; c--) {
        let y = 4 * c;
        let up = column_nearest[base + c];
        var best: vec4<u32>;
        best.w = nearer(y + 3, up.w, &below);
        best.z = nearer(y + 2, up.z, &below);
        best.y = nearer(y + 1, up.y, &below);
        best.x = nearer(y, up.x, &below);
        column_nearest[base + c] = best;
    }
}

// The row of the nearest shadow texel to (q, y) in column q, NONE if none.
fn column_row(q: i32, y: i32) -> u32 {
    let rows = column_nearest[q * (transform.pitch / 4) + y / 4];
    return rows[y % 4];
}

// Writes gain 0 to the row's entries c0 .. c1 - 1 of `gains`.
fn no_gain(row: i32, c0: i32, c1: i32) {
    for (var c = c0; c < c1; c++) {
        gains[row + c] = vec2<u32>(0u);
    }
}

// The gain k alpha(d) (eq. 2 and 4) of texel (x, y) whose nearest shadow texel is `texel`: 0
// outside the region, in the shadow (its own nearest) and without a shadow texel.
fn gain_of(x: i32, y: i32, texel: u32) -> f32 {
    if x < transform.region.x || x >= transform.region.z || texel == NONE {
        return 0.0;
    }
    let offset = vec2<f32>(f32(texel & 0xffffu), f32(texel >> 16u)) - vec2<f32>(f32(x), f32(y));
    if all(offset == vec2<f32>(0.0)) {
        return 0.0;
    }
    return transform.k * ramp(edge_distance_m(offset, transform.texel_m), transform.ramp_width_m);
}

@compute @workgroup_size(64, 1, 1)
fn cs_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let y = transform.area.y + i32(id.x);
    if y >= transform.area.w {
        return;
    }
    // The row's entries of `gains` over the area, and those over the region.
    let row = y * (transform.pitch / 4);
    let area0 = transform.area.x / 4;
    let area1 = (transform.area.z + 3) / 4;
    let first = transform.region.x / 4;
    let end = (transform.region.z + 3) / 4;
    if y < transform.region.y || y >= transform.region.w {
        no_gain(row, area0, area1);
        return;
    }
    no_gain(row, area0, first);
    no_gain(row, end, area1);
    let base = y * (transform.size + 1);
    // The lower envelope, left to right: parabola k of column envelope[k] is the lowest from
    // starts[k].x to starts[k + 1].x. Its newest parabola (k) is also in top_*.
    var k = -1;
    var top_q = 0;
    var top = vec2<f32>(-INF, 0.0);
    for (var q = transform.region.x; q < transform.region.z; q++) {
        let nearest_row = column_row(q, y);
        if nearest_row == NONE {
            continue;
        }
        // The parabola's height at its vertex, ((nearest_row - y) ty / tx)^2, plus q^2.
        let dy = f32(nearest_row) - f32(y);
        let value = dy * dy * transform.aspect2 + f32(q * q);
        var s = -INF;
        while k >= 0 {
            s = (value - top.y) / (2.0 * f32(q - top_q));
            if s > top.x {
                break;
            }
            k--;
            if k >= 0 {
                top_q = envelope[base + k];
                top = starts[base + k];
            }
        }
        k++;
        top_q = q;
        top = vec2<f32>(select(s, -INF, k == 0), value);
        envelope[base + k] = top_q;
        starts[base + k] = top;
    }
    // The row's entries of four texels (row y, columns 4c to 4c + 3 at y * pitch / 4 + c)
    // that hold the region; the texels of an entry outside the region get their nearest
    // shadow texel too (fs_distance does not read them), and gain 0.
    if k < 0 {
        for (var c = first; c < end; c++) {
            nearest[row + c] = vec4<u32>(NONE);
        }
        no_gain(row, first, end);
        return;
    }
    // Along the row, parabola j (whose nearest shadow texel is `texel`) until `next`, where
    // parabola j + 1 begins.
    var along = Along(0, INF, 0u);
    begin(&along, base, k, y, 0);
    for (var c = first; c < end; c++) {
        let x = 4 * c;
        var texels: vec4<u32>;
        texels.x = at(&along, base, k, y, x);
        texels.y = at(&along, base, k, y, x + 1);
        texels.z = at(&along, base, k, y, x + 2);
        texels.w = at(&along, base, k, y, x + 3);
        nearest[row + c] = texels;
        gains[row + c] = vec2<u32>(
            pack2x16float(vec2<f32>(gain_of(x, y, texels.x), gain_of(x + 1, y, texels.y))),
            pack2x16float(vec2<f32>(gain_of(x + 2, y, texels.z), gain_of(x + 3, y, texels.w))));
    }
}

// A walk along a row's envelope: parabola j, where parabola j + 1 begins, and the nearest
// shadow texel of parabola j, packed.
struct Along {
    j: i32,
    next: f32,
    texel: u32,
};

// Moves `along` to parabola j of the envelope at `base` (k + 1 parabolas) of row y.
fn begin(along: ptr<function, Along>, base: i32, k: i32, y: i32, j: i32) {
    let q = envelope[base + j];
    (*along).j = j;
    (*along).texel = u32(q) | (column_row(q, y) << 16u);
    (*along).next = INF;
    if j < k {
        (*along).next = starts[base + j + 1].x;
    }
}

// The nearest shadow texel of texel x of row y, `along` moved on to x's parabola.
fn at(along: ptr<function, Along>, base: i32, k: i32, y: i32, x: i32) -> u32 {
    while (*along).next < f32(x) {
        begin(along, base, k, y, (*along).j + 1);
    }
    return (*along).texel;
}
