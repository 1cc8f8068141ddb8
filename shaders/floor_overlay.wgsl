// The floor overlay layer (METHOD.md section 1, eq. 3, 5 and 6; render/src/floor/overlay.rs): a
// world-anchored rectangle on the floor plane, added to the eye image (blend ONE, ONE), that
// carries the shadow inducer's light L_s = k alpha(d) L_r and the corrected caustics
// L'_c = G L_r. What the wearer then sees on the floor is
// L_o = L_r + L_s + L'_c = (1 + k alpha(d) + G) L_r (eq. 5); the shadow keeps L_r (+ L'_c).
//
// Only the rectangle around the shadow plus the ramp's width (and the caustics' extent) is
// drawn (computed on the CPU; on the frames that compute a live caustic map, joined here with
// that map's box, which only the GPU knows then). Each pixel sums the two gains itself, each only when switched
// on: k alpha(d) filtered from the inducer's field, G filtered from the caustic map; texels
// with no light are discarded before the photo is read.

struct Overlay {
    clip_from_plane: mat4x4<f32>,
    // The drawn part of the floor's unit square: min x, min y, max x, max y (plane-local;
    // nothing when min x > max x).
    rect: vec4<f32>,
    // x, y: weights of the inducer's gain and of the caustic gain G (1 on, 0 off); z: 1 to
    // draw also over the live caustic map's box in `live_bounds`; w: the share of the floor's
    // light the object's shadow takes away, written as alpha for a segmented dimmer
    // (render/src/dimmer; 0 without one).
    switches: vec4<f32>,
};

var<push_constant> overlay: Overlay;
// k alpha(d) (`gain_of` in inducer_distance.wgsl, R16F) over the floor's unit square.
@group(0) @binding(0) var gain: texture_2d<f32>;
// The registered photo of the real floor: L_r, decoded to linear light by the sRGB format.
@group(0) @binding(1) var floor_photo: texture_2d<f32>;
@group(0) @binding(2) var clamp_sampler: sampler;
// The caustic gain G (R32F, the bake's or the live map's size) over the floor's unit square.
@group(0) @binding(3) var caustic: texture_2d<f32>;
// The live caustic map's non-zero texels, x0, y0, x1, y1 (ends included; none when x0 > x1),
// written by the live computation earlier in the frame (render/src/floor/live.rs): on the
// frames that compute a map only the GPU knows it.
@group(0) @binding(4) var<storage, read> live_bounds: array<u32, 4>;
// The shadow mask (R8, 1 in the shadow) over the floor's unit square.
@group(0) @binding(5) var shadow_mask: texture_2d<f32>;

// The pipeline adds the caustic gain G (pipeline constant, so that the inducer's own pipeline
// has no caustic code: a branch on a uniform costs both of its sides on a CPU device).
override CAUSTICS: bool = false;
// G is sampled through the sampler's bilinear filter, where the device filters R32_SFLOAT
// (optional in Vulkan; render/src/floor/overlay.rs checks it), instead of four loads.
override FILTERED_CAUSTICS: bool = false;
// The pipeline writes the shadow's share of the floor's light as alpha (a display with a
// segmented dimmer: render/src/dimmer), so that the additive pipelines carry no mask code.
override SHADOW: bool = false;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

// The plane-local rectangle of the texels in `live_bounds` plus one texel on each side (as
// caustic_rect and texels_plane_rect on the CPU); `rect` when it holds none.
fn with_live_bounds(rect: vec4<f32>) -> vec4<f32> {
    let b = vec4<f32>(f32(live_bounds[0]), f32(live_bounds[1]), f32(live_bounds[2]),
        f32(live_bounds[3]));
    if live_bounds[0] > live_bounds[2] {
        return rect;
    }
    let size = vec2<f32>(textureDimensions(caustic));
    let u = (vec2<f32>(b.x, b.z) + vec2<f32>(-1.0, 2.0)) / size.x;
    let v = (vec2<f32>(b.y, b.w) + vec2<f32>(-1.0, 2.0)) / size.y;
    let live = vec4<f32>(max(u.x - 0.5, -0.5), max(0.5 - v.y, -0.5), min(u.y - 0.5, 0.5),
        min(0.5 - v.x, 0.5));
    if rect.x > rect.z {
        return live;
    }
    return vec4<f32>(min(rect.xy, live.xy), max(rect.zw, live.zw));
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    var r = overlay.rect;
    if overlay.switches.z > 0.0 {
        r = with_live_bounds(r);
    }
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(r.x, r.y), vec2<f32>(r.z, r.y), vec2<f32>(r.z, r.w),
        vec2<f32>(r.x, r.y), vec2<f32>(r.z, r.w), vec2<f32>(r.x, r.w),
    );
    // An empty rectangle: every corner at one point, so that nothing is drawn.
    let c = select(corners[index], r.xy, r.x > r.z);
    var out: VertexOut;
    out.clip = overlay.clip_from_plane * vec4<f32>(c, 0.0, 1.0);
    // As world.wgsl: the photo's top edge lies towards the plane's local +y.
    out.uv = vec2<f32>(c.x + 0.5, 0.5 - c.y);
    return out;
}

// G at uv, bilinear between texel centres and clamped at the edges, as the sampler would
// filter it; computed from four loads because linear filtering of R32_SFLOAT is optional in
// Vulkan. Same formula as Bake::sample on the CPU.
fn caustic_gain(uv: vec2<f32>) -> f32 {
    if FILTERED_CAUSTICS {
        return textureSampleLevel(caustic, clamp_sampler, uv, 0.0).r;
    }
    let size = vec2<i32>(textureDimensions(caustic));
    let last = vec2<f32>(size - 1);
    let t = clamp(uv * vec2<f32>(size) - 0.5, vec2<f32>(0.0), last);
    let base = floor(t);
    let f = t - base;
    let p = vec2<i32>(base);
    let q = min(p + 1, size - 1);
    let top = mix(textureLoad(caustic, p, 0).r, textureLoad(caustic, vec2<i32>(q.x, p.y), 0).r, f.x);
    let bottom = mix(textureLoad(caustic, vec2<i32>(p.x, q.y), 0).r, textureLoad(caustic, q, 0).r, f.x);
    return mix(top, bottom, f.y);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    var overlay_gain = 0.0;
    if overlay.switches.x > 0.0 {
        // eq. 4: alpha'(d) = k alpha(d).
        overlay_gain += overlay.switches.x * textureSampleLevel(gain, clamp_sampler, in.uv, 0.0).r;
    }
    if CAUSTICS && overlay.switches.y > 0.0 {
        // eq. 6: L'_c = max(0, L_c - L_r) = G L_r; G >= 0 is checked on loading.
        overlay_gain += overlay.switches.y * caustic_gain(in.uv);
    }
    if SHADOW {
        // The shadow's share of the floor's light, for the dimmer to take away.
        var shadow = 0.0;
        if overlay.switches.w > 0.0 {
            shadow = overlay.switches.w * textureSampleLevel(shadow_mask, clamp_sampler, in.uv, 0.0).r;
        }
        if overlay_gain <= 0.0 && shadow <= 0.0 {
            discard;
        }
        let l_r = textureSampleLevel(floor_photo, clamp_sampler, in.uv, 0.0).rgb;
        return vec4<f32>(overlay_gain * l_r, shadow);
    }
    if overlay_gain <= 0.0 {
        discard;
    }
    let l_r = textureSampleLevel(floor_photo, clamp_sampler, in.uv, 0.0).rgb;
    // eq. 3 and 6: L_s + L'_c = (alpha'(d) + G) L_r.
    return vec4<f32>(overlay_gain * l_r, 0.0);
}
