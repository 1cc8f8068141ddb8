// Nearest shadow texel of every texel of the fields' region (METHOD.md section 1; the distance
// d of eq. 2; render/src/floor/distance_transform.rs): an exact Euclidean distance transform
// of the shadow mask in two compute passes (separable, as Felzenszwalb and Huttenlocher's):
//
// 1. cs_columns, one invocation per column of the region: the row of the nearest shadow
//    texel in the column (two sweeps).
// 2. cs_rows, one invocation per row: over the columns, the lower envelope of the parabolas
//    (x - q)^2 + ((row_q - y) ty / tx)^2, whose minimum at x is the squared distance (in
//    units of tx) to the nearest shadow texel; each texel gets that texel, packed as
//    x | y << 16, for fs_distance.
//
// Only the region is read and written; nothing outside it is a seed (the region holds the
// whole shadow).

struct Transform {
    // The region: x0, y0, x1, y1 (ends excluded), texels.
    region: vec4<i32>,
    // (ty / tx)^2 of the floor metres per texel along x (tx) and y (ty).
    aspect2: f32,
    // Side of the fields, texels.
    size: i32,
};

var<push_constant> transform: Transform;
@group(0) @binding(0) var mask: texture_2d<f32>;
// Per texel (y * size + x): the row of the nearest shadow texel in its column, NONE if none.
@group(0) @binding(1) var<storage, read_write> column_nearest: array<u32>;
// Per row (stride size + 1): the envelope's parabolas (their columns) ...
@group(0) @binding(2) var<storage, read_write> envelope: array<i32>;
// ... and where each begins along the row.
@group(0) @binding(3) var<storage, read_write> starts: array<f32>;
// Per texel: the nearest shadow texel, x | y << 16, NONE if none.
@group(0) @binding(4) var<storage, read_write> nearest: array<u32>;

const NONE: u32 = 0xffffffffu;
const INF: f32 = 1.0e30;

@compute @workgroup_size(64, 1, 1)
fn cs_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = transform.region.x + i32(id.x);
    if x >= transform.region.z {
        return;
    }
    let n = transform.size;
    // Downwards: the nearest shadow row at or above.
    var above = NONE;
    for (var y = transform.region.y; y < transform.region.w; y++) {
        if textureLoad(mask, vec2<i32>(x, y), 0).r > 0.5 {
            above = u32(y);
        }
        column_nearest[y * n + x] = above;
    }
    // Upwards: the nearest shadow row at or below, and the nearer of the two (above on a tie).
    var below = NONE;
    for (var y = transform.region.w - 1; y >= transform.region.y; y--) {
        let i = y * n + x;
        let up = column_nearest[i];
        if up == u32(y) {
            below = u32(y);
        }
        var best = up;
        if below != NONE && (up == NONE || below - u32(y) < u32(y) - up) {
            best = below;
        }
        column_nearest[i] = best;
    }
}

// The parabola of column q in row y at its vertex: ((row - y) ty / tx)^2, INF without a
// shadow texel in the column.
fn height(q: i32, y: i32) -> f32 {
    let row = column_nearest[y * transform.size + q];
    if row == NONE {
        return INF;
    }
    let dy = f32(row) - f32(y);
    return dy * dy * transform.aspect2;
}

@compute @workgroup_size(64, 1, 1)
fn cs_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let y = transform.region.y + i32(id.x);
    if y >= transform.region.w {
        return;
    }
    let n = transform.size;
    let base = y * (n + 1);
    // The lower envelope, left to right: parabola k of column envelope[k] is the lowest from
    // starts[k] to starts[k + 1].
    var k = -1;
    for (var q = transform.region.x; q < transform.region.z; q++) {
        let fq = height(q, y);
        if fq >= INF {
            continue;
        }
        var s = -INF;
        while k >= 0 {
            let p = envelope[base + k];
            let fp = height(p, y);
            s = ((fq + f32(q * q)) - (fp + f32(p * p))) / (2.0 * f32(q - p));
            if s <= starts[base + k] {
                k--;
            } else {
                break;
            }
        }
        k++;
        envelope[base + k] = q;
        starts[base + k] = select(s, -INF, k == 0);
        starts[base + k + 1] = INF;
    }
    var j = 0;
    for (var x = transform.region.x; x < transform.region.z; x++) {
        let i = y * n + x;
        if k < 0 {
            nearest[i] = NONE;
            continue;
        }
        while starts[base + j + 1] < f32(x) {
            j++;
        }
        let q = envelope[base + j];
        nearest[i] = u32(q) | (column_nearest[y * n + q] << 16u);
    }
}
