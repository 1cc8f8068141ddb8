// Shared by the shaders that name it in a `// #include shared/compensation.wgsl` line: eq. 6 over
// the glass (`[display] compensation = "background"`), B the real floor or background the eye
// already sees through the (virtual) glass, for the display to add only max(T - B, 0). The
// including shader also includes shared/seen.wgsl and declares `planes: Planes`, `photos`,
// `photo_sampler` (shared/seen.wgsl), `levels: Levels` (a uniform) and `ripmaps`.

// Reductions along each axis in the ripmap (twin of render/src/ripmap.rs LEVELS).
const LEVELS: u32 = 6u;

// Where each photo's reductions lie in the ripmap atlas (render/src/ripmap.rs).
struct Levels {
    // Per reduction k of the floor photo: xy the left edge and width of its column k, zw the
    // top edge and height of its row k, normalised to the atlas.
    floor: array<vec4<f32>, 6>,
    // The same for the background photo.
    background: array<vec4<f32>, 6>,
    // xy: the floor photo's size in texels; zw: the background's.
    sizes: vec4<f32>,
};

// Where the ray from `origin` along `dir` meets the plane, in its photo's coordinates (v
// down), on the photo or not.
fn on_plane(plane_from_world: mat4x4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    let o = (plane_from_world * vec4<f32>(origin, 1.0)).xyz;
    let d = (plane_from_world * vec4<f32>(dir, 0.0)).xyz;
    let p = o + d * (-o.z / select(d.z, 1e-12, abs(d.z) < 1e-12));
    return vec2<f32>(p.x + 0.5, 0.5 - p.y);
}

// The reduction (0 to LEVELS - 1) whose bilinear read best stands for a box `extent` photo
// texels wide: a reduction by `r` read bilinearly spreads a texel about `r / 2` (standard
// deviation), a box `extent / sqrt(12)`: `r` about 0.58 `extent`.
fn reduction(extent: f32) -> u32 {
    return u32(clamp(round(log2(max(0.58 * extent, 1.0))), 0.0, f32(LEVELS - 1u)));
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
    var size = levels.sizes.zw;
    if floor_first {
        plane = planes.floor_from_world;
        size = levels.sizes.xy;
    }
    let uv = select(b.xy, f.xy, floor_first);
    let spread_across = abs(on_plane(plane, origin, normalize(at + across - origin)) - uv);
    let spread_down = abs(on_plane(plane, origin, normalize(at + down - origin)) - uv);
    let i = reduction(max(spread_across.x, spread_down.x) * size.x);
    let j = reduction(max(spread_across.y, spread_down.y) * size.y);
    var column = levels.background[i];
    var row = levels.background[j];
    if floor_first {
        column = levels.floor[i];
        row = levels.floor[j];
    }
    // Half a texel inside the reduction's edges, so a bilinear fetch never reaches another.
    let half = 0.5 / vec2<f32>(textureDimensions(ripmaps));
    let lo = vec2<f32>(column.x, row.z);
    let extent = vec2<f32>(column.y, row.w);
    let texel = clamp(lo + uv * extent, lo + half, lo + extent - half);
    let seen = textureSampleLevel(ripmaps, photo_sampler, texel, 0.0).rgb;
    return seen * max(f.w, b.w);
}
