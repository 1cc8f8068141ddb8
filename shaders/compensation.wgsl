// Eq. 6 over the glass (`[display] compensation = "background"`): where the glass is drawn,
// the display should add only what the eye does not already see, max(T - B, 0), with T the
// glass's light and B the real floor or background the eye sees through the (virtual) glass.
// Drawn after the glass as a full-screen triangle at the far plane whose fragments pass the
// depth test only where something nearer was drawn (the glass: the floor overlay writes no
// depth), blended as destination minus source (clamped at 0 by the attachment). B is the
// nearer of the two photos along the eye's ray, both packed side by side in one texture, so
// each covered pixel fetches once.

// #include shared/seen.wgsl

struct Eye {
    world_from_clip: mat4x4<f32>,
    // xyz: the eye's position in the world, metres; w: positions along each side of a pixel.
    position: vec4<f32>,
};

var<push_constant> eye: Eye;
@group(0) @binding(0) var<uniform> planes: Planes;
@group(0) @binding(1) var photos: texture_2d<f32>;
@group(0) @binding(2) var photo_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    // One triangle covering the viewport, at the far plane (depth 1).
    var corners = array<vec2<f32>, 3>(vec2<f32>(-1.0, -1.0), vec2<f32>(3.0, -1.0), vec2<f32>(-1.0, 3.0));
    var out: VertexOut;
    out.clip = vec4<f32>(corners[index], 1.0, 1.0);
    out.ndc = corners[index];
    return out;
}

// B over the pixel where the glass's light is the mean over several positions in it (`[output]
// glass_samples`): the mean over the same n x n grid (n = `eye.position.w`), one fetch each. A
// pipeline constant (render/build.rs), so that the one-position pipeline keeps its one fetch.
override SUPERSAMPLED: bool = false;

// What the eye sees of the real floor or background along its ray through `ndc`.
fn seen_at(ndc: vec2<f32>) -> vec3<f32> {
    let far = eye.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    let origin = eye.position.xyz;
    return seen_along(origin, normalize(far.xyz / far.w - origin));
}

// The depth test before the shader (it writes no depth), so only the glass's pixels run it.
@fragment
@early_depth_test(force)
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if SUPERSAMPLED {
        let n = max(u32(eye.position.w), 1u);
        let dx = dpdx(in.ndc);
        let dy = dpdy(in.ndc);
        var sum = vec3<f32>(0.0);
        for (var i = 0u; i < n * n; i++) {
            let offset = (vec2<f32>(f32(i % n), f32(i / n)) + 0.5) / f32(n) - 0.5;
            sum += seen_at(in.ndc + dx * offset.x + dy * offset.y);
        }
        return vec4<f32>(sum / f32(n * n), 0.0);
    }
    return vec4<f32>(seen_at(in.ndc), 0.0);
}
