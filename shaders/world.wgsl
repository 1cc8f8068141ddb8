// The real world as a photo on a registered plane (floor or background). Never part of an eye
// image's light: it is drawn for the see-through preview, which shows what the wearer
// perceives (the display's light added to the real world), and behind the glass on an opaque
// display. Each pixel samples its photo as the glass does: at its centre (`fs_main`), or with
// several positions per glass pixel over its footprint from the photos' ripmaps
// (`fs_footprint`), as eq. 6 over the glass takes the same world away.

// #include shared/ripmap.wgsl

struct Plane {
    clip_from_world: mat4x4<f32>,
    // Maps the unit square [-0.5, 0.5]^2 at z = 0 onto the plane in the world.
    world_from_plane: mat4x4<f32>,
};

var<push_constant> plane: Plane;
@group(0) @binding(0) var photo: texture_2d<f32>;
@group(0) @binding(1) var photo_sampler: sampler;
// Both photos' ripmaps and where their reductions lie (`fs_footprint`).
@group(1) @binding(0) var<uniform> levels: Levels;
@group(1) @binding(1) var ripmaps: texture_2d<f32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    // The plane's photo: 0 the floor, 1 the background (the draw's instance).
    @location(1) @interpolate(flat) photo: u32,
};

@vertex
fn vs_main(
    @builtin(vertex_index) index: u32, @builtin(instance_index) instance: u32,
) -> VertexOut {
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
    out.photo = instance;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(photo, photo_sampler, in.uv).rgb, 1.0);
}

@fragment
fn fs_footprint(in: VertexOut) -> @location(0) vec4<f32> {
    // The footprint: how far the neighbouring pixels' rays meet the plane, along each of the
    // photo's axes.
    let spread = max(abs(dpdx(in.uv)), abs(dpdy(in.uv)));
    return vec4<f32>(over_footprint(in.photo == 0u, in.uv, spread), 1.0);
}
