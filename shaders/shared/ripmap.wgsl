// Shared by the shaders that name it in a `// #include shared/ripmap.wgsl` line: a real photo
// averaged over a pixel's footprint, read from the photos' ripmaps (render/src/ripmap.rs) in
// the reduction whose texels are about the footprint's size along each of the photo's axes.
// The including shader declares `levels: Levels` (a uniform), `ripmaps` and `photo_sampler`.

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

// The reduction (0 to LEVELS - 1) whose bilinear read best stands for a box `extent` photo
// texels wide: a reduction by `r` read bilinearly spreads a texel about `r / 2` (standard
// deviation), a box `extent / sqrt(12)`: `r` about 0.58 `extent`.
fn reduction(extent: f32) -> u32 {
    return u32(clamp(round(log2(max(0.58 * extent, 1.0))), 0.0, f32(LEVELS - 1u)));
}

// The floor photo (`floor_photo` true) or the background's, at photo coordinate `uv` (v down)
// averaged over a footprint `spread` wide along each of the photo's axes (in photo
// coordinates, 1 the photo's side). One fetch.
fn over_footprint(floor_photo: bool, uv: vec2<f32>, spread: vec2<f32>) -> vec3<f32> {
    var size = levels.sizes.zw;
    if floor_photo {
        size = levels.sizes.xy;
    }
    let i = reduction(spread.x * size.x);
    let j = reduction(spread.y * size.y);
    var column = levels.background[i];
    var row = levels.background[j];
    if floor_photo {
        column = levels.floor[i];
        row = levels.floor[j];
    }
    // Half a texel inside the reduction's edges, so a bilinear fetch never reaches another.
    let half = 0.5 / vec2<f32>(textureDimensions(ripmaps));
    let lo = vec2<f32>(column.x, row.z);
    let extent = vec2<f32>(column.y, row.w);
    let texel = clamp(lo + uv * extent, lo + half, lo + extent - half);
    return textureSampleLevel(ripmaps, photo_sampler, texel, 0.0).rgb;
}
