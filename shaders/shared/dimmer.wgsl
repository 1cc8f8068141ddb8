// Shared by the segmented dimmer's shaders (dimmer_panel.wgsl, dimmer_resolve.wgsl), which
// name it in a `// #include shared/dimmer.wgsl` line with shared/seen.wgsl: one eye's push
// constants and the bindings both read (render/src/dimmer).

struct Dimmer {
    world_from_clip: mat4x4<f32>,
    // xyz: the eye's position in the world, metres; w: the eye's layer.
    position: vec4<f32>,
    // x, y: the eye image's size in pixels; z, w: the panel's cells across and down.
    size: vec4<f32>,
    // x, y: the blur's standard deviation in cells, across and down; z, w: the spread in cells
    // (`Panel::spread`; negative: an erosion).
    blur: vec4<f32>,
    // x: the largest share a cell takes away; y: grid points per cell side (FINE).
    limits: vec4<f32>,
};

var<push_constant> dimmer: Dimmer;
@group(0) @binding(0) var<uniform> planes: Planes;
@group(0) @binding(1) var photos: texture_2d<f32>;
@group(0) @binding(2) var photo_sampler: sampler;
// What the eye passes drew, both eyes as layers: colour (linear) and alpha (the floor's share
// to take away), and depth (below 1 where the glass is).
@group(0) @binding(3) var drawn: texture_2d_array<f32>;
@group(0) @binding(4) var drawn_depth: texture_depth_2d_array;
