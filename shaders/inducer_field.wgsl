// Distance to the shadow edge and the inducer's gain, in floor space (METHOD.md section 1,
// eq. 2-4; render/src/floor/). Full-screen passes over the floor-space textures, drawn only
// inside the region that can change (render/src/floor/jump_flood.rs):
//
// 1. fs_seed_jump: the first jump of the flood straight from the mask: each texel keeps, of
//    the shadow texels at itself and at its 8 neighbours `step` texels away, the one nearest
//    in metres (every shadow texel is its own nearest seed; the same as a seed pass followed
//    by a jump).
// 2. fs_jump (jump flooding, halving steps down to 1, then one more of step 1): each texel
//    keeps, of the seeds stored at itself and at its 8 neighbours `step` texels away, the one
//    nearest in metres. Neighbours outside `region` count as none: the passes draw nothing
//    there.
// 3. fs_distance: d, the distance from a lit texel to the shadow edge in metres; -1 inside
//    the shadow; FAR_M outside `region` (the pass also draws where the region was before).
// 4. fs_ramp: k alpha(d) (eq. 2 and 4), the inducer's gain.
// 5. fs_combine (caustics, eq. 6): the floor overlay's gain at the caustic map's resolution,
//    k alpha(d) (if the inducer is on) + G (if the caustics are on), what the floor overlay
//    multiplies the floor photo by. Rerun when those switches change.
//
// Every fetch is a textureLoad of one texel, except fs_combine's bilinear read of the gain.

struct Field {
    // Floor metres per texel along the texture's x (u) and y (v).
    texel_m: vec2<f32>,
    // fs_jump: the jump of this pass, texels.
    step: i32,
    // Side of the floor-space textures, texels.
    size: i32,
    // D of eq. 2, metres.
    ramp_width_m: f32,
    // k of eq. 4.
    k: f32,
    // fs_combine: weights of the inducer's gain and of the caustic gain G (1 on, 0 off).
    switches: vec2<f32>,
    // The texels the fields are computed in: x0, y0, x1, y1 (ends excluded).
    region: vec4<i32>,
};

var<push_constant> field: Field;
// The pass's input: the mask (fs_seed_jump), the distances (fs_ramp) or the gain
// (fs_combine).
@group(0) @binding(0) var source: texture_2d<f32>;
// The shadow mask, for fs_distance; the caustic gain G (R32F), for fs_combine.
@group(0) @binding(1) var shadow_mask: texture_2d<f32>;
// fs_combine: bilinear between texel centres, clamped at the edges (the overlay's sampler).
@group(0) @binding(2) var clamp_sampler: sampler;
// The seeds (fs_jump, fs_distance): each texel's nearest shadow texel found so far, packed as
// x | y << 16 (one 32-bit fetch per neighbour), NO_SEED where none is yet.
@group(0) @binding(3) var seeds: texture_2d<u32>;

// "No seed found yet": it unpacks to (65535, 65535), farther from every texel (fields are at
// most 4096 texels across) than any real seed.
const NO_SEED: u32 = 0xffffffffu;
// Distance written where the floor has no shadow at all, metres.
const FAR_M: f32 = 1.0e9;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the whole target.
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

// Whether texel q lies in the region the fields are computed in.
fn in_region(q: vec2<i32>) -> bool {
    return all(q >= field.region.xy) && all(q < field.region.zw);
}

fn pack(q: vec2<i32>) -> u32 {
    return u32(q.x) | (u32(q.y) << 16u);
}

fn unpack(seed: u32) -> vec2<f32> {
    return vec2<f32>(f32(seed & 0xffffu), f32(seed >> 16u));
}

// Squared distance in metres between texel centres.
fn distance2_m(seed: vec2<f32>, p: vec2<f32>) -> f32 {
    let v = (seed - p) * field.texel_m;
    return dot(v, v);
}

@fragment
fn fs_seed_jump(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<u32> {
    let p = vec2<i32>(frag.xy);
    let pf = vec2<f32>(p);
    var best = NO_SEED;
    if textureLoad(source, p, 0).r > 0.5 {
        best = pack(p);
    }
    var best_d = distance2_m(unpack(best), pf);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy) * field.step;
            if (dx != 0 || dy != 0) && in_region(q) && textureLoad(source, q, 0).r > 0.5 {
                let d = distance2_m(vec2<f32>(q), pf);
                if d < best_d {
                    best = pack(q);
                    best_d = d;
                }
            }
        }
    }
    return vec4<u32>(best, 0u, 0u, 0u);
}

@fragment
fn fs_jump(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<u32> {
    let p = vec2<i32>(frag.xy);
    let pf = vec2<f32>(p);
    var best = textureLoad(seeds, p, 0).r;
    var best_d = distance2_m(unpack(best), pf);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy) * field.step;
            if (dx != 0 || dy != 0) && in_region(q) {
                let seed = textureLoad(seeds, q, 0).r;
                let d = distance2_m(unpack(seed), pf);
                if d < best_d {
                    best = seed;
                    best_d = d;
                }
            }
        }
    }
    return vec4<u32>(best, 0u, 0u, 0u);
}

// Distance from a lit texel to the shadow edge, metres, given the offset (texels) to its
// nearest shadow texel: the edge is taken halfway between that texel's centre and its lit
// neighbour's, i.e. half a texel short of the shadow texel's centre along the offset.
// Same formula as inducer::edge_distance_m on the CPU.
fn edge_distance_m(offset: vec2<f32>) -> f32 {
    let texels = length(offset);
    return length(offset * field.texel_m) * (1.0 - 0.5 / texels);
}

@fragment
fn fs_distance(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    if !in_region(p) {
        return vec4<f32>(FAR_M, 0.0, 0.0, 0.0);
    }
    if textureLoad(shadow_mask, p, 0).r > 0.5 {
        return vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    }
    let seed = textureLoad(seeds, p, 0).r;
    if seed == NO_SEED {
        return vec4<f32>(FAR_M, 0.0, 0.0, 0.0);
    }
    return vec4<f32>(edge_distance_m(unpack(seed) - vec2<f32>(p)), 0.0, 0.0, 0.0);
}

// eq. 2: alpha(d) = (D - d) / D for 0 <= d < D, 0 beyond D and inside the shadow (d < 0).
fn ramp(d_m: f32, width_m: f32) -> f32 {
    if d_m < 0.0 || d_m >= width_m {
        return 0.0;
    }
    return (width_m - d_m) / width_m;
}

@fragment
fn fs_ramp(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let d_m = textureLoad(source, vec2<i32>(frag.xy), 0).r;
    // eq. 4: alpha'(d) = k alpha(d).
    return vec4<f32>(field.k * ramp(d_m, field.ramp_width_m), 0.0, 0.0, 0.0);
}

@fragment
fn fs_combine(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    // The target has the caustic map's size, texel for texel.
    let p = vec2<i32>(frag.xy);
    let uv = frag.xy / vec2<f32>(textureDimensions(shadow_mask));
    var gain = 0.0;
    if field.switches.x > 0.0 {
        // k alpha(d) at the texel's floor point, bilinear as the overlay samples it.
        gain += field.switches.x * textureSampleLevel(source, clamp_sampler, uv, 0.0).r;
    }
    if field.switches.y > 0.0 {
        // eq. 6: L'_c = max(0, L_c - L_r) = G L_r; G >= 0 is checked on loading.
        gain += field.switches.y * textureLoad(shadow_mask, p, 0).r;
    }
    return vec4<f32>(gain, 0.0, 0.0, 0.0);
}
