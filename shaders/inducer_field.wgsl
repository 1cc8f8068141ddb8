// Distance to the shadow edge and the inducer's gain, in floor space (METHOD.md section 1,
// eq. 2-4; render/src/floor/). Full-screen passes over the floor-space textures, drawn only
// where the fields can change (render/src/floor/pass.rs):
//
// 1. (shaders/inducer_distance.wgsl) every texel of the region gets its nearest shadow texel.
// 2. fs_ramp: k alpha(d) (eq. 2 and 4), the inducer's gain, which the floor overlay
//    (shaders/floor_overlay.wgsl) filters and adds to the caustic gain G; d, the distance
//    from a lit texel to the shadow edge in metres, from its nearest shadow texel (the pass
//    also draws where the region was before, where d is FAR_M).
// 3. fs_distance: d itself, -1 inside the shadow and FAR_M outside `region`: drawn only
//    when the fields are read back (nothing else reads it).
//
// Every fetch is a textureLoad of one texel.

struct Field {
    // Floor metres per texel along the texture's x (u) and y (v).
    texel_m: vec2<f32>,
    // Texels per row of `nearest` (the side of the floor-space textures rounded up to a
    // multiple of 4).
    nearest_pitch: i32,
    // D of eq. 2, metres.
    ramp_width_m: f32,
    // k of eq. 4.
    k: f32,
    // The texels the fields are computed in: x0, y0, x1, y1 (ends excluded).
    region: vec4<i32>,
};

var<push_constant> field: Field;
// The shadow mask.
@group(0) @binding(0) var shadow_mask: texture_2d<f32>;
// Each texel's nearest shadow texel, packed as x | y << 16, NO_SEED if none.
@group(0) @binding(1) var<storage, read> nearest: array<u32>;

// No shadow texel in the region.
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

fn unpack(seed: u32) -> vec2<f32> {
    return vec2<f32>(f32(seed & 0xffffu), f32(seed >> 16u));
}

// Distance from a lit texel to the shadow edge, metres, given the offset (texels) to its
// nearest shadow texel: the edge is taken halfway between that texel's centre and its lit
// neighbour's, i.e. half a texel short of the shadow texel's centre along the offset.
// Same formula as inducer::edge_distance_m on the CPU.
fn edge_distance_m(offset: vec2<f32>) -> f32 {
    let texels = length(offset);
    return length(offset * field.texel_m) * (1.0 - 0.5 / texels);
}

// d of texel p: -1 inside the shadow, FAR_M outside the region or without a shadow texel.
fn distance_at(p: vec2<i32>) -> f32 {
    if !in_region(p) {
        return FAR_M;
    }
    if textureLoad(shadow_mask, p, 0).r > 0.5 {
        return -1.0;
    }
    let seed = nearest[p.y * field.nearest_pitch + p.x];
    if seed == NO_SEED {
        return FAR_M;
    }
    return edge_distance_m(unpack(seed) - vec2<f32>(p));
}

@fragment
fn fs_distance(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(distance_at(vec2<i32>(frag.xy)), 0.0, 0.0, 0.0);
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
    let d_m = distance_at(vec2<i32>(frag.xy));
    // eq. 4: alpha'(d) = k alpha(d).
    return vec4<f32>(field.k * ramp(d_m, field.ramp_width_m), 0.0, 0.0, 0.0);
}
