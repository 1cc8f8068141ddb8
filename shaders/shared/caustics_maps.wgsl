// The parameters and the map buffers that the live caustics' passes share
// (shaders/caustics_live.wgsl traces the photons into the sums, shaders/caustics_smooth.wgsl
// smooths them into the gain map; render/src/floor/live.rs binds them). Rows of the maps lie
// `row_pitch` texels apart.

struct Params {
    // World to model space of the object (rotation, uniform scale, translation).
    model_from_world: mat4x4<f32>,
    // Model to world space.
    world_from_model: mat4x4<f32>,
    // Floor unit square [-0.5, 0.5]^2 (photo top at +y) to world, and back.
    world_from_plane: mat4x4<f32>,
    plane_from_world: mat4x4<f32>,
    // xyz: the light, world metres; w: solid angle per photon, steradians.
    light: vec4<f32>,
    // xyz: the emission cone's axis (unit, world); w: 1 - cos of its half-angle.
    axis: vec4<f32>,
    // xyz: a unit vector across the axis; w: the relative index of refraction.
    basis_u: vec4<f32>,
    // xyz: the third unit vector; w: area of one gain texel, square metres.
    basis_v: vec4<f32>,
    // xyz: the grid's lower corner, model units; w: its cell side, model units.
    grid_origin: vec4<f32>,
    // xyz: cells along each axis; w: photons along each side of the emission grid.
    grid_dims: vec4<u32>,
    // x, y: the gain map's width and height, texels; z: most interactions on one path;
    // w: the smoothing box's radius, texels (0: no smoothing).
    map: vec4<u32>,
    // x: self-intersection offset, model units; y: fixed-point units per unit of G;
    // z: paths below this weight end; w: gains below this are stored as 0.
    misc: vec4<f32>,
    // xyz: the centre of the shell every surface point lies in, model units; w: its inner
    // radius (0: a ball).
    shell: vec4<f32>,
    // x: the shell's outer radius; y: the slack added to its stretches, model units; z: 1 when
    // the mesh bounds one convex body (a ray leaving it outward meets no more of it), else 0;
    // w: 1 when, besides, the inner ball lies inside it (a ray inside the body meets no
    // surface before it has passed the ball), else 0.
    shell_outer: vec4<f32>,
    // The smoothing's tiles of TILE x TILE texels: x, y: tiles across and down the map's
    // buffers; z: words of tile bits per tile row; w: 1 when the smoothing skips the tiles
    // whose smoothed gains are certain to be below MIN_GAIN, else 0 (every texel smoothed).
    tiles: vec4<u32>,
    // x: the planes of a convex flat-faceted body's facets in `facet_planes`
    // (shaders/caustics_live.wgsl), 0 for any other mesh.
    facets: vec4<u32>,
};

@group(0) @binding(0) var<storage, read> p: Params;
// Fixed-point sums of G per texel (row 0 at the photo's top; rows `row_pitch` texels apart,
// as in the other maps below).
@group(0) @binding(4) var<storage, read_write> sums: array<atomic<i32>>;
// The smoothed gain map.
@group(0) @binding(5) var<storage, read_write> gain: array<vec4<f32>>;
// The box of the non-zero gains: smallest x, smallest y, largest x, largest y (texels; the
// CPU sets it to an empty box before each computation).
@group(0) @binding(6) var<storage, read_write> bounds: array<atomic<u32>, 4>;
// The gains smoothed along the rows, fixed-point units (between the two smoothing passes).
@group(0) @binding(7) var<storage, read_write> scratch: array<vec4<f32>>;
// The sums again, four texels at a time, for the smoothing (which runs after the trace's
// atomics have finished and writes none).
@group(0) @binding(9) var<storage, read> sums4: array<vec4<i32>>;
// Per cell of 4 x 4 texels (`mass_pitch` cells a row), the positive shares of G deposited with
// their first texel in it, in units of MASS_UNIT fixed-point units, each deposit's rounded
// up: no texel's G = max(0, sum) exceeds the shares it was dealt. The CPU zeroes it before
// each computation.
@group(0) @binding(10) var<storage, read_write> cell_mass: array<atomic<u32>>;
// Per tile row, `tiles.z` words of bits of the tiles the smoothing writes (tile x in bit
// x % 32 of word x / 32): those whose smoothed gains can reach MIN_GAIN (`cs_smooth_tiles`).
@group(0) @binding(11) var<storage, read_write> tile_bits: array<u32>;
// The cells' masses again, four cells at a time, for `cs_smooth_tiles`.
@group(0) @binding(12) var<storage, read> cell_mass4: array<vec4<u32>>;

const NONE: u32 = 0xffffffffu;
// Fixed-point units per unit of `cell_mass` (`MASS_UNIT` in live.rs): room for the masses of
// 16 times more light than whole fixed-point units would leave, for less than 16 units
// (G = 2.4e-4) more per deposit.
const MASS_UNIT: u32 = 16u;
// Side of the smoothing's tiles, texels (`TILE_PX` in smoothing.rs): whole vectors of four,
// and at least the short kernel's reach, so that a tile's gains depend on its own and its
// neighbours' texels only.
const TILE: i32 = 8;

// Texels from one row of the map's buffers to the next: the width rounded up to whole
// vectors of four, so that the short kernel's passes read and write four texels at a time
// (texels past the width stay 0 in the sums, and their gains are neither kept nor copied).
fn row_pitch(width: u32) -> u32 {
    return (width + 3u) & ~3u;
}

// Cells of 4 x 4 texels from one row of `cell_mass` to the next, for `tiles_x` tiles across:
// two per tile, rounded up to whole vectors of four.
fn mass_pitch(tiles_x: u32) -> u32 {
    return (2u * tiles_x + 3u) & ~3u;
}
