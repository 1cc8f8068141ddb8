// The segmented dimmer's panel for one eye (render/src/dimmer): what share of the real world's
// light each cell should take away, and what share the eye then loses through the soft panel.
// Three dispatches, in order:
//
// - `want`, one invocation per pixel of the eye image the eye passes drew (before the dimmer):
//   where the glass was drawn (the only depth writer) the target is the glass's light G over
//   the share k of the pixel it covers and the real world over the rest (less the floor's
//   shadow there), and the share to take away is what brings the real background B down to it
//   in the channel that needs most: with the glass's alpha A = k + (1 - k) s m (laid over the
//   overlay's, render/src/glass.rs), max_c (A - G_c / B_c) (A = 1 where the glass covers the
//   whole pixel); on the floor, the shadow's share the overlay wrote as alpha.
//   Clamped to the panel's largest attenuation, each cell keeps the largest its pixels want (an
//   atomic max on the bits of non-negative floats, which order as the floats do).
// - `spread`, one per cell: the largest want within the panel's spread (optics/src/display/
//   dimmer.rs `Panel::spread_wants`: one cell, less under a registration error), or with a
//   negative spread the least (an erosion); what the blurred patch takes away beyond the
//   target is given back as light by the resolve (dimmer_resolve.wgsl).
// - `soften`, one per point of the grid FINE times finer than the cells: the share the eye
//   loses through the panel, the cells' values weighted by the Gaussian's mass over each (as
//   `Panel::soften`).

// #include shared/seen.wgsl
// #include shared/dimmer.wgsl

// Per eye, one after the other: each cell's want (f32 bits), its spread value, and the grid.
@group(0) @binding(5) var<storage, read_write> wanted: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> panel: array<f32>;
@group(0) @binding(7) var<storage, read_write> soft: array<f32>;

fn cells() -> vec2<u32> {
    return vec2<u32>(dimmer.size.zw);
}

fn layer() -> u32 {
    return u32(dimmer.position.w);
}

// The eye's ray through the centre of pixel `p`.
fn ray(p: vec2<u32>) -> vec3<f32> {
    let ndc = (vec2<f32>(p) + 0.5) / dimmer.size.xy * 2.0 - 1.0;
    let far = dimmer.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(far.xyz / far.w - dimmer.position.xyz);
}

@compute @workgroup_size(8, 8)
fn want(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(dimmer.size.xy);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let l = i32(layer());
    let drawn_here = textureLoad(drawn, vec2<i32>(id.xy), l, 0);
    var share = drawn_here.a;
    if textureLoad(drawn_depth, vec2<i32>(id.xy), l, 0) < 1.0 {
        let b = seen_along(dimmer.position.xyz, ray(id.xy));
        let dark = select(vec3<f32>(0.0), drawn_here.a - drawn_here.rgb / max(b, vec3<f32>(1e-6)), b > vec3<f32>(1e-4));
        share = max(max(dark.r, dark.g), dark.b);
    }
    share = clamp(share, 0.0, dimmer.limits.x);
    if share > 0.0 {
        let c = min(id.xy * cells() / size, cells() - 1u);
        let n = cells().x * cells().y;
        atomicMax(&wanted[layer() * n + c.y * cells().x + c.x], bitcast<u32>(share));
    }
}

@compute @workgroup_size(64)
fn spread(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = cells().x * cells().y;
    if id.x >= n {
        return;
    }
    let c = vec2<i32>(vec2<u32>(id.x % cells().x, id.x / cells().x));
    // A negative reach erodes: the least want within it (cells beyond the panel want none).
    let erode = dimmer.blur.z < 0.0;
    let reach = abs(vec2<i32>(dimmer.blur.zw));
    let lo = c - reach;
    let hi = c + reach;
    var most = 0.0;
    var least = 1.0;
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            var w = 0.0;
            if x >= 0 && y >= 0 && x < i32(cells().x) && y < i32(cells().y) {
                w = bitcast<f32>(atomicLoad(&wanted[layer() * n + u32(y) * cells().x + u32(x)]));
            }
            most = max(most, w);
            least = min(least, w);
        }
    }
    panel[layer() * n + id.x] = select(most, least, erode);
}

// The error function (Abramowitz and Stegun 7.1.26), as optics/src/display/dimmer.rs `erf`.
fn erf(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.3275911 * abs(x));
    let poly = t * (0.2548296 + t * (-0.28449674 + t * (1.4214137 + t * (-1.4531521 + t * 1.0614054))));
    return sign(x) * (1.0 - poly * exp(-x * x));
}

// The Gaussian's mass (standard deviation `sigma`, centred at `u`) over the cell [c, c + 1).
fn cell_weight(c: i32, u: f32, sigma: f32) -> f32 {
    let s = max(sigma, 1e-3) * 1.4142135;
    return 0.5 * (erf((f32(c) + 1.0 - u) / s) - erf((f32(c) - u) / s));
}

@compute @workgroup_size(64)
fn soften(@builtin(global_invocation_id) id: vec3<u32>) {
    let fine = u32(dimmer.limits.y);
    let grid = cells() * fine;
    if id.x >= grid.x * grid.y {
        return;
    }
    let uv = (vec2<f32>(vec2<u32>(id.x % grid.x, id.x / grid.x)) + 0.5) / f32(fine);
    let sigma = dimmer.blur.xy;
    let reach = min(vec2<i32>(ceil(4.0 * sigma)) + 1, vec2<i32>(31));
    let at = vec2<i32>(floor(uv));
    let lo = max(at - reach, vec2<i32>(0));
    let hi = min(at + reach, vec2<i32>(cells()) - 1);
    let n = cells().x * cells().y;
    // Each column's weight once (the reach is at most 31 cells: optics/src/display/dimmer.rs).
    var wx: array<f32, 64>;
    for (var x = lo.x; x <= hi.x; x++) {
        wx[x - lo.x] = cell_weight(x, uv.x, sigma.x);
    }
    var d = 0.0;
    for (var y = lo.y; y <= hi.y; y++) {
        let wy = cell_weight(y, uv.y, sigma.y);
        for (var x = lo.x; x <= hi.x; x++) {
            let p = panel[layer() * n + u32(y) * cells().x + u32(x)];
            if p > 0.0 {
                d += p * wx[x - lo.x] * wy;
            }
        }
    }
    soft[layer() * grid.x * grid.y + id.x] = d;
}
