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
    // xyz: the eye's position in the world, metres.
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

// The depth test before the shader (it writes no depth), so only the glass's pixels run it.
@fragment
@early_depth_test(force)
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let far = eye.world_from_clip * vec4<f32>(in.ndc, 1.0, 1.0);
    let origin = eye.position.xyz;
    let dir = normalize(far.xyz / far.w - origin);
    return vec4<f32>(seen_along(origin, dir), 0.0);
}
