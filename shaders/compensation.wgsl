// Eq. 6 over the glass (`[display] compensation = "background"`): where the glass is drawn,
// the display should add only what the eye does not already see, max(T - B, 0), with T the
// glass's light and B the real floor or background the eye sees through the (virtual) glass.
// Drawn after the glass as a full-screen triangle at the far plane whose fragments pass the
// depth test only where something nearer was drawn (the glass: the floor overlay writes no
// depth), blended as destination minus source (clamped at 0 by the attachment). B is the
// nearer of the two photos along the eye's ray, both packed side by side in one texture, so
// each covered pixel fetches once.

struct Eye {
    world_from_clip: mat4x4<f32>,
    // xyz: the eye's position in the world, metres.
    position: vec4<f32>,
};

struct Planes {
    // Each maps the world into its plane's frame, where the photo covers [-0.5, 0.5]^2 at z = 0.
    floor_from_world: mat4x4<f32>,
    background_from_world: mat4x4<f32>,
    // Each photo's rectangle in the packed texture, normalised: u0, v0, u1, v1.
    floor_rect: vec4<f32>,
    background_rect: vec4<f32>,
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

// Where the ray origin + t dir meets a plane's photo: xy the photo coordinate (v down), z the
// distance t, w 1 on the photo and 0 on a miss.
fn hit(plane_from_world: mat4x4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec4<f32> {
    let o = (plane_from_world * vec4<f32>(origin, 1.0)).xyz;
    let d = (plane_from_world * vec4<f32>(dir, 0.0)).xyz;
    if abs(d.z) < 1e-12 {
        return vec4<f32>(0.0);
    }
    let t = -o.z / d.z;
    let p = o + d * t;
    if t <= 0.0 || abs(p.x) > 0.5 || abs(p.y) > 0.5 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(p.x + 0.5, 0.5 - p.y, t, 1.0);
}

// The depth test before the shader (it writes no depth), so only the glass's pixels run it.
@fragment
@early_depth_test(force)
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let far = eye.world_from_clip * vec4<f32>(in.ndc, 1.0, 1.0);
    let origin = eye.position.xyz;
    let dir = normalize(far.xyz / far.w - origin);
    let f = hit(planes.floor_from_world, origin, dir);
    let b = hit(planes.background_from_world, origin, dir);
    // The nearer photo the ray meets, as a rectangle of the packed texture and a coordinate.
    let floor_first = f.w > 0.0 && (b.w == 0.0 || f.z <= b.z);
    let uv = select(b.xy, f.xy, floor_first);
    let rect = select(planes.background_rect, planes.floor_rect, floor_first);
    // Clamped half a texel inside the photo's edges, as a photo of its own is sampled, so a
    // bilinear fetch never reaches the other photo.
    let half = 0.5 / vec2<f32>(textureDimensions(photos));
    let at = clamp(mix(rect.xy, rect.zw, uv), rect.xy + half, rect.zw - half);
    let seen = textureSampleLevel(photos, photo_sampler, at, 0.0).rgb;
    // Nothing to take away where the ray meets neither photo.
    return vec4<f32>(seen * max(f.w, b.w), 0.0);
}
