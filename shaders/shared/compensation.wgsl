// Shared by the shaders that name it in a `// #include shared/compensation.wgsl` line: eq. 6 over
// the glass (`[display] compensation = "background"`), B the real floor or background the eye
// already sees through the (virtual) glass, for the display to add only max(T - B, 0). The
// including shader also includes shared/seen.wgsl and shared/ripmap.wgsl and declares what they
// read.

// Where the ray from `origin` along `dir` meets the plane, in its photo's coordinates (v
// down), on the photo or not.
fn on_plane(plane_from_world: mat4x4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    let o = (plane_from_world * vec4<f32>(origin, 1.0)).xyz;
    let d = (plane_from_world * vec4<f32>(dir, 0.0)).xyz;
    let p = o + d * (-o.z / select(d.z, 1e-12, abs(d.z) < 1e-12));
    return vec2<f32>(p.x + 0.5, 0.5 - p.y);
}

// What the eye at `origin` sees of the real floor or background over the pixel whose ray passes
// through `at`, the neighbouring pixels' rays through `at + across` and `at + down`: the nearer
// photo the pixel's ray meets, averaged over the footprint the pixel's rays make on that
// photo's plane, read from the photos' ripmaps in the reduction whose texels are about the
// footprint's size along each of the photo's axes. One fetch.
fn seen_over_footprint(
    origin: vec3<f32>, at: vec3<f32>, across: vec3<f32>, down: vec3<f32>,
) -> vec3<f32> {
    let dir = normalize(at - origin);
    let f = photo_hit(planes.floor_from_world, origin, dir);
    let b = photo_hit(planes.background_from_world, origin, dir);
    let floor_first = f.w > 0.0 && (b.w == 0.0 || f.z <= b.z);
    var plane = planes.background_from_world;
    if floor_first {
        plane = planes.floor_from_world;
    }
    let uv = select(b.xy, f.xy, floor_first);
    let spread_across = abs(on_plane(plane, origin, normalize(at + across - origin)) - uv);
    let spread_down = abs(on_plane(plane, origin, normalize(at + down - origin)) - uv);
    let seen = over_footprint(floor_first, uv, max(spread_across, spread_down));
    return seen * max(f.w, b.w);
}
