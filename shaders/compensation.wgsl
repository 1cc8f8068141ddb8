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

// B over the pixel where the glass's light is the mean over several positions in it (`[output]
// glass_samples` above 1): the photo averaged over the pixel's footprint, read from its ripmap
// (render/src/ripmap.rs) in the reduction whose texels are about the footprint's size along
// each of the photo's axes, still one fetch. A pipeline constant (render/build.rs), so that the
// one-position pipeline keeps its fetch at the pixel's centre.
override FOOTPRINT: bool = false;

// Reductions along each axis in the ripmap (twin of render/src/ripmap.rs LEVELS).
const LEVELS: u32 = 6u;

struct Levels {
    // Per reduction k of the floor photo: xy the left edge and width of its column k, zw the
    // top edge and height of its row k, normalised to the atlas.
    floor: array<vec4<f32>, 6>,
    // The same for the background photo.
    background: array<vec4<f32>, 6>,
    // xy: the floor photo's size in texels; zw: the background's.
    sizes: vec4<f32>,
};

@group(0) @binding(3) var<uniform> levels: Levels;
@group(0) @binding(4) var ripmaps: texture_2d<f32>;

// The eye's ray through `ndc`, unit.
fn ray_through(ndc: vec2<f32>) -> vec3<f32> {
    let far = eye.world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(far.xyz / far.w - eye.position.xyz);
}

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

// What the eye sees of the real floor or background over the pixel at `ndc`, whose
// neighbours across and down are `dx` and `dy` away: the nearer photo its centre's ray meets,
// averaged over the footprint the pixel's rays make on that photo's plane.
fn seen_over_footprint(ndc: vec2<f32>, dx: vec2<f32>, dy: vec2<f32>) -> vec3<f32> {
    let origin = eye.position.xyz;
    let dir = ray_through(ndc);
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
    let across = abs(on_plane(plane, origin, ray_through(ndc + dx)) - uv);
    let down = abs(on_plane(plane, origin, ray_through(ndc + dy)) - uv);
    let i = reduction(max(across.x, down.x) * size.x);
    let j = reduction(max(across.y, down.y) * size.y);
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
    let at = clamp(lo + uv * extent, lo + half, lo + extent - half);
    let seen = textureSampleLevel(ripmaps, photo_sampler, at, 0.0).rgb;
    return seen * max(f.w, b.w);
}

// The depth test before the shader (it writes no depth), so only the glass's pixels run it.
@fragment
@early_depth_test(force)
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    var seen: vec3<f32>;
    if FOOTPRINT {
        seen = seen_over_footprint(in.ndc, dpdx(in.ndc), dpdy(in.ndc));
    } else {
        seen = seen_along(eye.position.xyz, ray_through(in.ndc));
    }
    return vec4<f32>(seen, 0.0);
}
