// Shared by the shaders that name it in a `// #include shared/seen.wgsl` line (render/build.rs
// appends it to their source): the real floor or background the eye sees along a ray, from the
// scene's registered photos packed side by side in one texture. The including shader declares
// `planes: Planes` (a uniform), `photos` and `photo_sampler`.

struct Planes {
    // Each maps the world into its plane's frame, where the photo covers [-0.5, 0.5]^2 at z = 0.
    floor_from_world: mat4x4<f32>,
    background_from_world: mat4x4<f32>,
    // Each photo's rectangle in the packed texture, normalised: u0, v0, u1, v1.
    floor_rect: vec4<f32>,
    background_rect: vec4<f32>,
};

// Where the ray origin + t dir meets a plane's photo: xy the photo coordinate (v down), z the
// distance t, w 1 on the photo and 0 on a miss.
fn photo_hit(plane_from_world: mat4x4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec4<f32> {
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

// The linear light of the nearer photo the ray meets; 0 where it meets neither. One fetch.
fn seen_along(origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let f = photo_hit(planes.floor_from_world, origin, dir);
    let b = photo_hit(planes.background_from_world, origin, dir);
    let floor_first = f.w > 0.0 && (b.w == 0.0 || f.z <= b.z);
    let uv = select(b.xy, f.xy, floor_first);
    let rect = select(planes.background_rect, planes.floor_rect, floor_first);
    // Clamped half a texel inside the photo's edges, as a photo of its own is sampled, so a
    // bilinear fetch never reaches the other photo.
    let half = 0.5 / vec2<f32>(textureDimensions(photos));
    let at = clamp(mix(rect.xy, rect.zw, uv), rect.xy + half, rect.zw - half);
    let seen = textureSampleLevel(photos, photo_sampler, at, 0.0).rgb;
    return seen * max(f.w, b.w);
}
