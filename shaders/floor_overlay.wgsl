// The floor overlay layer (METHOD.md section 1, eq. 3 and 5; render/src/inducer.rs): a
// world-anchored rectangle on the floor plane, added to the eye image (blend ONE, ONE), that
// carries the shadow inducer's light L_s = k alpha(d) L_r. What the wearer then sees on the
// floor is L_o = L_r + L_s = (1 + k alpha(d)) L_r (eq. 5); the shadow keeps L_r.
//
// Only the rectangle around the shadow plus the ramp's width (and the caustics' extent) is drawn (computed on the CPU),
// and texels with no inducer light are discarded before the photo is read: at most two
// texture fetches per covered pixel (the precomputed gain, the floor photo).

struct Overlay {
    clip_from_plane: mat4x4<f32>,
    // The drawn part of the floor's unit square: min x, min y, max x, max y (plane-local).
    rect: vec4<f32>,
};

var<push_constant> overlay: Overlay;
// k alpha(d) (fs_ramp of inducer_field.wgsl) when the caustics are off, k alpha(d) + G
// (fs_combine) when they are on, over the floor's unit square.
@group(0) @binding(0) var gain: texture_2d<f32>;
// The registered photo of the real floor: L_r, decoded to linear light by the sRGB format.
@group(0) @binding(1) var floor_photo: texture_2d<f32>;
@group(0) @binding(2) var clamp_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    let r = overlay.rect;
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(r.x, r.y), vec2<f32>(r.z, r.y), vec2<f32>(r.z, r.w),
        vec2<f32>(r.x, r.y), vec2<f32>(r.z, r.w), vec2<f32>(r.x, r.w),
    );
    let c = corners[index];
    var out: VertexOut;
    out.clip = overlay.clip_from_plane * vec4<f32>(c, 0.0, 1.0);
    // As world.wgsl: the photo's top edge lies towards the plane's local +y.
    out.uv = vec2<f32>(c.x + 0.5, 0.5 - c.y);
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let overlay_gain = textureSampleLevel(gain, clamp_sampler, in.uv, 0.0).r;
    if overlay_gain <= 0.0 {
        discard;
    }
    let l_r = textureSampleLevel(floor_photo, clamp_sampler, in.uv, 0.0).rgb;
    // eq. 3 and 6: L_s + L'_c = (alpha'(d) + G) L_r.
    return vec4<f32>(overlay_gain * l_r, 0.0);
}
