// The frame's defocused image (eq. 10-14): a blur stack's two slices around the frame's K_g,
// blended into a 2-D image once per frame (render/src/blur_blend.rs), so that the glass pass
// reads it with one bilinear fetch per pixel instead of a trilinear fetch of the 3-D stack.
// Each texel of the target sits on a texel centre of the stack's slices, so the blend is the
// stack's own filtering along its depth and nothing else.

struct Blend {
    // The stack's texture coordinate along its depth (`glass::stack_coordinate`).
    depth: f32,
};

var<push_constant> blend: Blend;
@group(0) @binding(0) var stack: texture_3d<f32>;
@group(0) @binding(1) var stack_sampler: sampler;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the whole target.
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<f32>(textureDimensions(stack).xy);
    return textureSampleLevel(stack, stack_sampler, vec3<f32>(frag.xy / size, blend.depth), 0.0);
}
