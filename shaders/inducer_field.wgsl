// The distance to the shadow edge in floor space (METHOD.md section 1, the d of eq. 2;
// render/src/floor/), for a read back of the fields: a full-screen pass over the distance
// field. The frames do not draw it: the rows pass of the distance transform
// (shaders/inducer_distance.wgsl) finds each texel's nearest shadow texel and writes the gain
// k alpha(d) itself. fs_distance writes d, -1 inside the shadow and FAR_M outside `region`.

// #include shared/inducer_ramp.wgsl

struct Field {
    // Floor metres per texel along the texture's x (u) and y (v).
    texel_m: vec2<f32>,
    // Texels per row of `nearest` (the side of the floor-space textures rounded up to a
    // multiple of 4).
    nearest_pitch: i32,
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
    return edge_distance_m(unpack(seed) - vec2<f32>(p), field.texel_m);
}

@fragment
fn fs_distance(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(distance_at(vec2<i32>(frag.xy)), 0.0, 0.0, 0.0);
}
