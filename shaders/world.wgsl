// The real world as a photo on a registered plane (floor or background). Never part of an eye
// image: it is drawn only for the see-through preview, which shows what the wearer perceives
// (the display's light added to the real world).

struct Plane {
    clip_from_world: mat4x4<f32>,
    // Maps the unit square [-0.5, 0.5]^2 at z = 0 onto the plane in the world.
    world_from_plane: mat4x4<f32>,
};

var<push_constant> plane: Plane;
@group(0) @binding(0) var photo: texture_2d<f32>;
@group(0) @binding(1) var photo_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    // Two triangles covering the unit square.
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-0.5, -0.5), vec2<f32>(0.5, -0.5), vec2<f32>(0.5, 0.5),
        vec2<f32>(-0.5, -0.5), vec2<f32>(0.5, 0.5), vec2<f32>(-0.5, 0.5),
    );
    let c = corners[index];
    var out: VertexOut;
    out.clip = plane.clip_from_world * plane.world_from_plane * vec4<f32>(c, 0.0, 1.0);
    // The photo's top edge lies towards the plane's local +y.
    out.uv = vec2<f32>(c.x + 0.5, 0.5 - c.y);
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(photo, photo_sampler, in.uv).rgb, 1.0);
}
