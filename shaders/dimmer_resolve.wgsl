// The segmented dimmer's eye image (render/src/dimmer): from what the eye passes drew and the
// panel (dimmer_panel.wgsl), the light and alpha handed to the display, so that what the eye
// sees, B (1 - D) + L, is the target T as nearly as the panel allows (Itoh et al., "Occlusion
// leak compensation for optical see-through displays using a single-layer transmissive spatial
// light modulator", IEEE TVCG 2017; radiometric compensation as in Grossberg et al., CVPR
// 2004): L = max(T - B (1 - D), 0), with B the real world behind the pixel, D the share the
// soft panel takes away there, and T the real world with the share a taken away and the light
// E drawn added, T = B (1 - a) + E: on the floor a is the shadow's share and E the overlay's
// light; under the glass E is its light and a the share of the pixel it covers (over the
// floor's share beneath), all of it where it covers the whole pixel. Where
// the panel takes away more than the target needs (the soft edge's halo) the light gives it
// back; where it takes away less (inside a small dark patch) the eye sees the leak. The alpha
// is the pixel's cell of the panel: what the display's dimmer should take away.

// #include shared/seen.wgsl
// #include shared/dimmer.wgsl

@group(0) @binding(6) var<storage, read> panel: array<f32>;
@group(0) @binding(7) var<storage, read> soft: array<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    var corners = array<vec2<f32>, 3>(vec2<f32>(-1.0, -1.0), vec2<f32>(3.0, -1.0), vec2<f32>(-1.0, 3.0));
    return vec4<f32>(corners[index], 1.0, 1.0);
}

// The grid's value at pixel centre `p`, bilinear between its points, clamped at its edges (as
// `Panel::at_pixel`).
fn soft_at(p: vec2<f32>) -> f32 {
    let fine = u32(dimmer.limits.y);
    let grid = vec2<u32>(dimmer.size.zw) * fine;
    let last = vec2<f32>(grid - 1u);
    let t = clamp(p / dimmer.size.xy * vec2<f32>(grid) - 0.5, vec2<f32>(0.0), last);
    let base = vec2<u32>(floor(t));
    let f = t - floor(t);
    let q = min(base + 1u, grid - 1u);
    let at = u32(dimmer.position.w) * grid.x * grid.y;
    let top = mix(soft[at + base.y * grid.x + base.x], soft[at + base.y * grid.x + q.x], f.x);
    let bottom = mix(soft[at + q.y * grid.x + base.x], soft[at + q.y * grid.x + q.x], f.x);
    return mix(top, bottom, f.y);
}

struct Resolved {
    @location(0) light: vec4<f32>,
    // The depth the eye passes drew (the glass's), handed on to the frame's depth image.
    @builtin(frag_depth) depth: f32,
};

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> Resolved {
    let px = vec2<u32>(frag.xy);
    let l = i32(dimmer.position.w);
    let drawn_here = textureLoad(drawn, vec2<i32>(px), l, 0);
    let depth = textureLoad(drawn_depth, vec2<i32>(px), l, 0);
    // What the target takes away from B: the floor's shadow share, under the glass the share
    // of the pixel it covers laid over that (dimmer_panel.wgsl), all of it where it covers the
    // whole pixel (its light all of T).
    let a = drawn_here.a;
    let d = soft_at(frag.xy);
    let cells = vec2<u32>(dimmer.size.zw);
    let c = min(px * cells / vec2<u32>(dimmer.size.xy), cells - 1u);
    let alpha = panel[u32(l) * cells.x * cells.y + c.y * cells.x + c.x];
    if d == a {
        // Nothing to take away or give back: the light drawn (0 where nothing was).
        return Resolved(vec4<f32>(drawn_here.rgb, alpha), depth);
    }
    // B over the pixel's footprint (four positions), as the eye sees the world through it.
    var b = vec3<f32>(0.0);
    for (var i = 0; i < 4; i++) {
        let at = frag.xy + vec2<f32>(f32(i & 1) - 0.5, f32(i >> 1) - 0.5) * 0.5;
        let ndc = at / dimmer.size.xy * 2.0 - 1.0;
        let far = dimmer.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
        b += 0.25 * seen_along(dimmer.position.xyz, normalize(far.xyz / far.w - dimmer.position.xyz));
    }
    return Resolved(vec4<f32>(max(drawn_here.rgb + b * (d - a), vec3<f32>(0.0)), alpha), depth);
}
