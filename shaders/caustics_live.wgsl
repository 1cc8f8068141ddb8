// Caustics of the glass object on the floor for the current pose (docs/caustics.md, eq. 6),
// by photon splatting: `cs_trace` sends one photon per cell of an equal-solid-angle grid over
// the cone from the light around the object, traces it through the mesh (Snell refraction,
// exact Fresnel weights, both branches followed) and adds its share of the relative gain G to
// the four floor texels around where it lands; a photon that meets the object also takes its
// straight continuation away (the shadow, E_blocked). The smoothing passes then take
// G = max(0, sum) per texel, as the bake stores it, and smooth it (density estimation: a lone
// photon's share spreads over the kernel, as a beam's does in the bake) with a box filter run
// three times along the rows, then three times along the columns, one dispatch each way
// (`cs_smooth_rows` and `cs_smooth_columns` for radii up to 2, `cs_smooth_wide` above); the
// last zeroes gains below MIN_GAIN (as in the bake) and bounds the non-zero texels, which the
// overlay covers (its vertex stage reads the bound on the frame that computes the map).
// Without smoothing a single dispatch along the columns does only the latter.
//
// On a CPU device (lavapipe) every access of a storage buffer is a loop over the SIMD lanes,
// so the passes read their parameters once into registers and move four texels per access
// where they can.
//
// Geometry is traced in the object's model space (the mesh never moves there); a uniform grid
// of triangle lists, built once on the CPU, finds the surfaces.

// #include shared/fresnel.wgsl

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
};

@group(0) @binding(0) var<storage, read> p: Params;
// The parameters, read once per invocation of the trace: on a CPU device each read of a
// storage buffer is a loop over the lanes, so reading them where they are used costs more
// than the tracing's arithmetic.
var<private> params: Params;
// The floor's plane, from the parameters once per invocation (`floor_once`): a point of it and
// its unit normal towards its visible side in model space, and that normal in world space.
var<private> floor_point_m: vec3<f32>;
var<private> floor_normal_m: vec3<f32>;
var<private> floor_normal_world: vec3<f32>;
// Per triangle the outward unit normals of its three vertices (xyz), in the triangle's order.
@group(0) @binding(1) var<storage, read> vertex_normals: array<vec4<f32>>;
// Per grid cell (x fastest): first entry in cell_tris and count.
@group(0) @binding(2) var<storage, read> cells: array<vec2<u32>>;
@group(0) @binding(3) var<storage, read> cell_tris: array<u32>;
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
// Per triangle its first corner and two edges (xyz, model units), gathered once so that a
// test reads three vectors instead of three indices and three positions.
@group(0) @binding(8) var<storage, read> corners: array<vec4<f32>>;
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
const PI: f32 = 3.14159265358979;
const STACK: u32 = 16u;

// A ray's hit with triangle `tri` at distance t, barycentric (u, v), and the triangle's
// geometric normal (edge 1 x edge 2, not normalised): kept from the test, so that the hit's
// shading reads only the vertex normals.
struct Hit {
    t: f32,
    tri: u32,
    u: f32,
    v: f32,
    normal: vec3<f32>,
};

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
    weight: f32,
    interactions: u32,
    inside: u32,
};

// Möller-Trumbore: the hit of the ray with triangle `tri`, t < 0 for none.
fn triangle_hit(o: vec3<f32>, d: vec3<f32>, tri: u32) -> Hit {
    let none = Hit(-1.0, NONE, 0.0, 0.0, vec3<f32>(0.0));
    let a = corners[3u * tri].xyz;
    let e1 = corners[3u * tri + 1u].xyz;
    let e2 = corners[3u * tri + 2u].xyz;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return none;
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = dot(tv, pv) * inv;
    if u < 0.0 || u > 1.0 {
        return none;
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return none;
    }
    return Hit(dot(e2, qv) * inv, tri, u, v, cross(e1, e2));
}

// The nearest surface hit along the ray at a distance within [t_from, t_to], or `best` when
// that is nearer, walking the grid's cells in order over that stretch. Hits found in the
// cells walked beyond `t_to` are kept too (they are real, and nearer ones are found by a
// later walk that starts from `best`).
fn walk_grid(o: vec3<f32>, d: vec3<f32>, t_from: f32, t_to: f32, best_so_far: Hit) -> Hit {
    var best = best_so_far;
    let dims = vec3<i32>(params.grid_dims.xyz);
    let side = params.grid_origin.w;
    let lo = params.grid_origin.xyz;
    let hi = lo + vec3<f32>(dims) * side;
    let safe = select(d, vec3<f32>(1e-30), abs(d) < vec3<f32>(1e-30));
    let inv = 1.0 / safe;
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let t_in = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0)),
        t_from);
    let t_out = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), t_to);
    if t_in > min(t_out, best.t) {
        return best;
    }
    let start = o + d * t_in;
    var cell = clamp(vec3<i32>(floor((start - lo) / side)), vec3<i32>(0), dims - 1);
    let step = select(vec3<i32>(-1), vec3<i32>(1), safe >= vec3<f32>(0.0));
    let next_edge = lo + vec3<f32>(cell + max(step, vec3<i32>(0))) * side;
    var t_next = (next_edge - o) * inv;
    let t_delta = abs(side * inv);
    let limit = dims.x + dims.y + dims.z + 3;
    for (var k = 0; k < limit; k++) {
        let index = u32(cell.x + dims.x * (cell.y + dims.y * cell.z));
        let range = cells[index];
        for (var e = 0u; e < range.y; e++) {
            let tri = cell_tris[range.x + e];
            let h = triangle_hit(o, d, tri);
            if h.t > params.misc.x && h.t < best.t {
                best = h;
            }
        }
        let exit = min(min(t_next.x, t_next.y), t_next.z);
        if (best.tri != NONE && best.t <= exit) || exit > min(t_out, best.t) {
            break;
        }
        if t_next.x <= t_next.y && t_next.x <= t_next.z {
            cell.x += step.x;
            t_next.x += t_delta.x;
        } else if t_next.y <= t_next.z {
            cell.y += step.y;
            t_next.y += t_delta.y;
        } else {
            cell.z += step.z;
            t_next.z += t_delta.z;
        }
        if any(cell < vec3<i32>(0)) || any(cell >= dims) {
            break;
        }
    }
    return best;
}

// The nearest surface hit along the ray (unit `d`) before `t_max`. Every point of the mesh
// lies in the shell between two spheres about its centre (`shell`, `shell_outer`), so only
// the ray's one or two stretches inside that shell are walked: a ball-like mesh's hollow
// middle and the space around it cost no grid steps. With `past_inner` the ray is inside a
// convex body that holds the inner ball, so it meets the surface only past the ball, and the
// stretch before the ball is not walked.
fn closest_hit(o: vec3<f32>, d: vec3<f32>, t_max: f32, past_inner: bool) -> Hit {
    let none = Hit(t_max, NONE, 0.0, 0.0, vec3<f32>(0.0));
    let oc = o - params.shell.xyz;
    let b = dot(oc, d);
    // The ray's nearest approach to the centre, squared (stable far from the object).
    let q = oc - b * d;
    let q2 = dot(q, q);
    let outer = params.shell_outer.x;
    let h_out = outer * outer - q2;
    if h_out < 0.0 {
        return none;
    }
    let s_out = sqrt(h_out);
    let pad = params.shell_outer.y;
    let enter = max(-b - s_out - pad, 0.0);
    let leave = min(-b + s_out + pad, t_max);
    if enter > leave {
        return none;
    }
    let inner = params.shell.w;
    let h_in = inner * inner - q2;
    if inner <= 0.0 || h_in <= 0.0 {
        return walk_grid(o, d, enter, leave, none);
    }
    let s_in = sqrt(h_in);
    // The stretch before the inner ball, then the one after it.
    var best = none;
    let near_end = min(-b - s_in + pad, leave);
    if enter <= near_end && !past_inner {
        best = walk_grid(o, d, enter, near_end, best);
        if best.tri != NONE && best.t <= near_end {
            return best;
        }
    }
    let far_start = max(-b + s_in - pad, enter);
    if far_start <= leave {
        best = walk_grid(o, d, far_start, leave, best);
    }
    return best;
}

// Sets the floor's plane from the parameters (once per invocation, not per segment).
fn floor_once() {
    let plane = params.world_from_plane;
    floor_normal_world = normalize(cross(plane[0].xyz, plane[1].xyz));
    floor_point_m = (params.model_from_world * vec4<f32>(plane[3].xyz, 1.0)).xyz;
    floor_normal_m = normalize((params.model_from_world * vec4<f32>(floor_normal_world, 0.0)).xyz);
}

// Distance along the ray to the floor's visible side, model units; negative when it does not
// approach it.
fn floor_t(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let denom = dot(d, floor_normal_m);
    if denom >= 0.0 {
        return -1.0;
    }
    return dot(floor_point_m - o, floor_normal_m) / denom;
}

// Adds `weight` photons' worth of G at the model-space floor point, split bilinearly between
// the four nearest texel centres. One photon's G is its flux over a texel's area and the bare
// floor's irradiance where it lands: (solid angle) r^2 / (area cos theta), taken at that point
// rather than at each texel centre (a texel away the two differ by 0.2 % at most on the
// shipped floors; the bake takes the texel's).
fn deposit(point_m: vec3<f32>, weight: f32) {
    let world = (params.world_from_model * vec4<f32>(point_m, 1.0)).xyz;
    let local = (params.plane_from_world * vec4<f32>(world, 1.0)).xy;
    if abs(local.x) > 0.5 || abs(local.y) > 0.5 {
        return;
    }
    let size = vec2<i32>(params.map.xy);
    let t = vec2<f32>(local.x + 0.5, 0.5 - local.y) * vec2<f32>(size) - 0.5;
    let base = vec2<i32>(floor(t));
    let f = t - floor(t);
    let to_light = params.light.xyz - world;
    let r2 = dot(to_light, to_light);
    let cos_theta = dot(to_light, floor_normal_world) * inverseSqrt(r2);
    if cos_theta <= 0.0 {
        return;
    }
    let g0 = weight * params.light.w * r2 / (params.basis_v.w * cos_theta) * params.misc.y;
    var positive = 0;
    for (var k = 0; k < 4; k++) {
        let texel = base + vec2<i32>(k & 1, k >> 1u);
        if any(texel < vec2<i32>(0)) || any(texel >= size) {
            continue;
        }
        let wx = select(1.0 - f.x, f.x, (k & 1) == 1);
        let wy = select(1.0 - f.y, f.y, (k >> 1u) == 1);
        let index = texel.y * i32(row_pitch(params.map.x)) + texel.x;
        let share = i32(round(g0 * wx * wy));
        atomicAdd(&sums[index], share);
        positive += max(share, 0);
    }
    if params.tiles.w != 0u && positive > 0 {
        // Its texels lie within [4c, 4c + 4] along each axis of its cell c (a first texel
        // just off the map's top or left edge counts in cell 0).
        let cell = vec2<u32>(max(base, vec2<i32>(0))) / 4u;
        atomicAdd(&cell_mass[cell.y * mass_pitch() + cell.x],
            (u32(positive) + MASS_UNIT - 1u) / MASS_UNIT);
    }
}

// Cells of 4 x 4 texels from one row of `cell_mass` to the next: the two per tile across,
// rounded up to whole vectors of four.
fn mass_pitch() -> u32 {
    return (2u * params.tiles.x + 3u) & ~3u;
}

// Snell refraction through a surface whose normal `facing` points back to the incident side;
// the zero vector on total internal reflection.
fn refract_dir(d: vec3<f32>, facing: vec3<f32>, eta: f32) -> vec3<f32> {
    let cos_i = -dot(d, facing);
    let sin_t2 = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    if sin_t2 >= 1.0 {
        return vec3<f32>(0.0);
    }
    let cos_t = sqrt(1.0 - sin_t2);
    return normalize(eta * d + (eta * cos_i - cos_t) * facing);
}

// The emission cone's direction for a point of the unit square: Shirley-Chiu concentric map
// to the disk, then the equal-area map of the disk onto the cone's cap.
fn cone_direction(s: f32, t: f32) -> vec3<f32> {
    let a = 2.0 * s - 1.0;
    let b = 2.0 * t - 1.0;
    var r = 0.0;
    var phi = 0.0;
    if abs(a) > abs(b) {
        r = a;
        phi = PI / 4.0 * (b / a);
    } else if b != 0.0 {
        r = b;
        phi = PI / 2.0 - PI / 4.0 * (a / b);
    }
    let k = r * r * params.axis.w;
    let cos_theta = 1.0 - k;
    let sin_theta = sign(r) * sqrt(max(k * (2.0 - k), 0.0));
    let d = sin_theta * (cos(phi) * params.basis_u.xyz + sin(phi) * params.basis_v.xyz)
        + cos_theta * params.axis.xyz;
    return normalize(d);
}

@compute @workgroup_size(8, 8, 1)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>) {
    params = p;
    floor_once();
    let n = params.grid_dims.w;
    if id.x >= n || id.y >= n {
        return;
    }
    let world_dir = cone_direction((f32(id.x) + 0.5) / f32(n), (f32(id.y) + 0.5) / f32(n));
    let origin = (params.model_from_world * vec4<f32>(params.light.xyz, 1.0)).xyz;
    let dir = normalize((params.model_from_world * vec4<f32>(world_dir, 0.0)).xyz);
    let straight = floor_t(origin, dir);
    let first = closest_hit(origin, dir, select(1e30, straight, straight > 0.0), false);
    if first.tri == NONE {
        // Missed the object: the bare floor's light, which G is relative to.
        return;
    }
    if straight > 0.0 {
        deposit(origin + dir * straight, -1.0);
    }
    var stack: array<Ray, STACK>;
    var depth = 0u;
    // The ray a convex body's split keeps inside it: the next to follow, in registers.
    var carried: Ray;
    var carrying = false;
    var ray = Ray(origin, dir, 1.0, 0u, 0u);
    var hit = first;
    loop {
        if hit.tri != NONE {
            // Split at the surface into the reflected and the refracted part.
            if ray.interactions < params.map.z {
                let tri = hit.tri;
                let point = ray.origin + ray.dir * hit.t;
                let geometric = normalize(hit.normal);
                let shading = normalize((1.0 - hit.u - hit.v) * vertex_normals[3u * tri].xyz
                    + hit.u * vertex_normals[3u * tri + 1u].xyz
                    + hit.v * vertex_normals[3u * tri + 2u].xyz);
                let entering = dot(ray.dir, geometric) < 0.0;
                let side_g = select(-geometric, geometric, entering);
                var side_s = select(-shading, shading, entering);
                if !(dot(side_s, ray.dir) < 0.0 && dot(side_s, side_g) > 0.0) {
                    side_s = side_g;
                }
                let eta = select(params.basis_u.w, 1.0 / params.basis_u.w, entering);
                let reflectance = fresnel_exact(-dot(ray.dir, side_s), eta);
                var r = reflect(ray.dir, side_s);
                if dot(r, side_g) <= 0.0 {
                    r = reflect(ray.dir, side_g);
                }
                var t = refract_dir(ray.dir, side_s, eta);
                if dot(t, t) > 0.0 && dot(t, side_g) >= 0.0 {
                    let g = refract_dir(ray.dir, side_g, eta);
                    if dot(g, g) > 0.0 {
                        t = g;
                    }
                }
                let refracts = dot(t, t) > 0.0 && dot(t, side_g) < 0.0;
                let reflected_weight = select(ray.weight, ray.weight * reflectance, refracts);
                let refracted_weight = select(0.0, ray.weight * (1.0 - reflectance), refracts);
                let interactions = ray.interactions + 1u;
                let reflected = Ray(point + side_g * params.misc.x, r, reflected_weight,
                    interactions, ray.inside);
                let refracted = Ray(point - side_g * params.misc.x, t, refracted_weight,
                    interactions, 1u - ray.inside);
                if params.shell_outer.z > 0.0 {
                    // A convex body: of the two parts one leaves it (the reflected one outside,
                    // the refracted one inside) and meets no more of it, so it lands at once;
                    // the other is the only ray left, followed next without the stack, so
                    // that every turn of the loop walks the grid for every lane that has a
                    // ray left.
                    var leaving = refracted;
                    var staying = reflected;
                    if ray.inside == 0u {
                        leaving = reflected;
                        staying = refracted;
                    }
                    if staying.weight >= params.misc.z {
                        carried = staying;
                        carrying = true;
                    }
                    if leaving.weight >= params.misc.z {
                        let to_floor = floor_t(leaving.origin, leaving.dir);
                        if to_floor > 0.0 {
                            deposit(leaving.origin + leaving.dir * to_floor, leaving.weight);
                        }
                    }
                } else {
                    if reflected_weight >= params.misc.z && depth < STACK {
                        stack[depth] = reflected;
                        depth++;
                    }
                    if refracts && refracted_weight >= params.misc.z && depth < STACK {
                        stack[depth] = refracted;
                        depth++;
                    }
                }
            }
        }
        if carrying {
            ray = carried;
            carrying = false;
        } else if depth > 0u {
            depth--;
            ray = stack[depth];
        } else {
            break;
        }
        var to_floor = -1.0;
        if ray.inside == 0u {
            to_floor = floor_t(ray.origin, ray.dir);
        }
        hit = closest_hit(ray.origin, ray.dir, select(1e30, to_floor, to_floor > 0.0),
            ray.inside == 1u && params.shell_outer.w > 0.0);
        if hit.tri == NONE && to_floor > 0.0 {
            deposit(ray.origin + ray.dir * to_floor, ray.weight);
        }
    }
}

// Which smoothing pass a dispatch runs (`smooth_steps` in smoothing.rs): bit 0 clear along the
// rows, set along the columns; bit 1 set when a pass along the columns reads the photons'
// sums itself (no smoothing); bit 8 set on the last pass, which writes the gain map.
struct SmoothStep {
    bits: u32,
};
var<push_constant> smooth_step: SmoothStep;

const COLUMNS_STEP: u32 = 0x1u;
const FROM_SUMS_STEP: u32 = 0x2u;
const LAST_STEP: u32 = 0x100u;
// Most texels in one box: 2 x 64 + 1 (`MAX_SMOOTHING_PX` in live.rs).
const MAX_BOX: u32 = 129u;
// Largest radius the short kernel takes (`SHORT_KERNEL_PX` in smoothing.rs).
const SHORT_KERNEL_PX: u32 = 2u;

// Texels from one row of the map's buffers to the next: the width rounded up to whole
// vectors of four, so that the short kernel's passes read and write four texels at a time
// (texels past the width stay 0 in the sums, and their gains are neither kept nor copied).
fn row_pitch(width: u32) -> u32 {
    return (width + 3u) & ~3u;
}

// Widens the bound of the non-zero gains by the box [lo, hi] (texels, ends included).
fn widen_bounds(lo: vec2<u32>, hi: vec2<u32>) {
    atomicMin(&bounds[0], lo.x);
    atomicMin(&bounds[1], lo.y);
    atomicMax(&bounds[2], hi.x);
    atomicMax(&bounds[3], hi.y);
}

// The kernel of the box of 2 radius + 1 texels applied three times, for a radius of 0, 1
// or 2, over a window of 13 texels (slot 6 the centre): integer weights over their sum (1, 27,
// 125).
fn short_kernel(radius: u32) -> array<vec4<f32>, 4> {
    if radius == 2u {
        let k = 1.0 / 125.0;
        return array<vec4<f32>, 4>(vec4<f32>(1.0, 3.0, 6.0, 10.0) * k,
            vec4<f32>(15.0, 18.0, 19.0, 18.0) * k, vec4<f32>(15.0, 10.0, 6.0, 3.0) * k,
            vec4<f32>(1.0, 0.0, 0.0, 0.0) * k);
    }
    if radius == 1u {
        let k = 1.0 / 27.0;
        return array<vec4<f32>, 4>(vec4<f32>(0.0, 0.0, 0.0, 1.0) * k,
            vec4<f32>(3.0, 6.0, 7.0, 6.0) * k, vec4<f32>(3.0, 1.0, 0.0, 0.0) * k,
            vec4<f32>(0.0));
    }
    return array<vec4<f32>, 4>(vec4<f32>(0.0), vec4<f32>(0.0, 0.0, 1.0, 0.0), vec4<f32>(0.0),
        vec4<f32>(0.0));
}

// The last 13 inputs of a stream of texels, oldest first (`w3` the newest), in registers.
struct Window {
    w0: vec4<f32>,
    w1: vec4<f32>,
    w2: vec4<f32>,
    w3: f32,
};

// Feeds the next input `v` to `w` (the inputs before the first count as 0); returns the
// smoothed value of the input 6 back (the window's centre).
fn window_feed(w: ptr<function, Window>, v: f32, k: array<vec4<f32>, 4>) -> f32 {
    (*w).w0 = vec4<f32>((*w).w0.yzw, (*w).w1.x);
    (*w).w1 = vec4<f32>((*w).w1.yzw, (*w).w2.x);
    (*w).w2 = vec4<f32>((*w).w2.yzw, (*w).w3);
    (*w).w3 = v;
    return dot((*w).w0, k[0]) + dot((*w).w1, k[1]) + dot((*w).w2, k[2]) + (*w).w3 * k[3].x;
}

// The weight of the box of 2 radius + 1 texels applied three times at `d` texels from the
// centre: the ways to write d as a sum of three integers in [-radius, radius], over their
// count (2 radius + 1)^3.
fn kernel_weight(radius: u32, d: i32) -> f32 {
    let r = i32(radius);
    var ways = 0;
    for (var a = -r; a <= r; a++) {
        ways += max(0, 2 * r + 1 - abs(d - a));
    }
    let n = f32(2 * r + 1);
    return f32(ways) / (n * n * n);
}

// The kernel's largest weights between the texels of a tile (8 along an axis, from 8t) and
// those of deposits in each of the six cells 2t - 2 .. 2t + 3 along that axis (texels
// [4c, 4c + 4]): 4, 0, 0, 0, 1 and 5 texels apart. Cells further off are 8 texels or more
// away, beyond the short kernel's reach.
struct CellWeights {
    near: vec4<f32>,
    far: vec2<f32>,
};

fn cell_weights(radius: u32) -> CellWeights {
    return CellWeights(
        vec4<f32>(kernel_weight(radius, 4), kernel_weight(radius, 0), kernel_weight(radius, 0),
            kernel_weight(radius, 0)),
        vec2<f32>(kernel_weight(radius, 1), kernel_weight(radius, 5)));
}

// The word of bits that holds tile `x` of tile row `y` (see `tile_bits`); 0 beyond the map.
fn tile_word(x: u32, y: i32) -> u32 {
    if y < 0 || y >= i32(p.tiles.y) {
        return 0u;
    }
    return tile_bits[u32(y) * p.tiles.z + x / 32u];
}

// The masses of cells 4g .. 4g + 3 in cell row y (0 beyond the map).
fn cell_row(y: i32, g: u32, pitch4: u32) -> vec4<f32> {
    if y < 0 || u32(y) >= 2u * p.tiles.y {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(cell_mass4[u32(y) * pitch4 + g]);
}

// The bits of the tiles the smoothing writes, one tile row per invocation: a tile's bound is
// the sum over the 6 x 6 cells around it of each cell's mass times the kernel's largest
// weight between their texels (the kernel is separable), and the tile is written when the
// bound reaches 0.999 MIN_GAIN (room for rounding: the bound and the passes' f32 sums are
// each good to about 1e-5 of the exact values, and the masses are exact integers). Along the
// row the cells are read four at a time: the sum of each column of four cells over the six
// cell rows, then each tile's six columns from the last two of those sums.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let row = id.x;
    let across = p.tiles.x;
    if row >= p.tiles.y {
        return;
    }
    let w = cell_weights(p.map.w);
    let pitch4 = (2u * across + 3u) / 4u;
    let threshold = 0.999 * p.misc.w * p.misc.y / f32(MASS_UNIT);
    let top = i32(2u * row) - 2;
    var previous = vec4<f32>(0.0);
    var bits = 0u;
    for (var g = 0u; g <= pitch4; g++) {
        // The six cell rows' masses of cells 4g .. 4g + 3, weighted and summed.
        var column = vec4<f32>(0.0);
        if g < pitch4 {
            column = w.near.x * cell_row(top, g, pitch4) + w.near.y * cell_row(top + 1, g, pitch4)
                + w.near.z * cell_row(top + 2, g, pitch4) + w.near.w * cell_row(top + 3, g, pitch4)
                + w.far.x * cell_row(top + 4, g, pitch4) + w.far.y * cell_row(top + 5, g, pitch4);
        }
        // Tiles 2g - 1 (cells 4g - 4 .. 4g + 1) and 2g (cells 4g - 2 .. 4g + 3).
        for (var k = 0u; k < 2u; k++) {
            let tile = 2u * g + k;
            if tile == 0u || tile > across {
                continue;
            }
            let x = tile - 1u;
            var bound = 0.0;
            if k == 0u {
                bound = dot(previous, w.near) + dot(column.xy, w.far);
            } else {
                bound = dot(vec4<f32>(previous.zw, column.xy), w.near) + dot(column.zw, w.far);
            }
            if bound > 0.0 && bound >= threshold {
                bits |= 1u << (x % 32u);
            }
            if x % 32u == 31u || x + 1u == across {
                tile_bits[row * p.tiles.z + x / 32u] = bits;
                bits = 0u;
            }
        }
        previous = column;
    }
}

// The short kernel (radius <= 2) along the rows, one row per invocation, four texels per
// step: reads G = max(0, sum) of the photons' sums (eq. 6's clamp, per texel as the bake
// stores it) and writes the row's smoothed values (fixed-point units) into `scratch`. On a
// CPU device each access of a storage buffer is a loop over the lanes, so a texel's cost
// is its share of the accesses: a quarter of a read and of a write here. When the smoothing
// skips tiles, only the tiles whose rows the pass along the columns reads (those it writes
// and those above and below them) are written: the row is walked tile by tile, and the
// window, fed the two vectors before a tile that follows a skipped one, holds the same inputs
// there as it would along the whole row.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.map.y {
        return;
    }
    let blocks = row_pitch(p.map.x) / 4u;
    let base = id.x * blocks;
    let k = short_kernel(p.map.w);
    let skip = p.tiles.w != 0u;
    // The spans walked: the tiles along the row, or the whole row as one.
    let spans = select(1u, p.tiles.x, skip);
    let span_blocks = select(blocks, u32(TILE) / 4u, skip);
    let tile_row = id.x / u32(TILE);
    var w = Window(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), 0.0);
    var previous = vec4<f32>(0.0);
    // The next block the window takes.
    var next = 0u;
    var bits = 0u;
    for (var s = 0u; s < spans; s++) {
        if skip {
            if s % 32u == 0u {
                // The pass along the columns reads the rows of the tiles it writes and of
                // those above and below them.
                let y = i32(tile_row);
                bits = tile_word(s, y - 1) | tile_word(s, y) | tile_word(s, y + 1);
            }
            if (bits & (1u << (s % 32u))) == 0u {
                continue;
            }
        }
        let first = s * span_blocks;
        let end = min(first + span_blocks, blocks);
        next = max(next, max(first, 2u) - 2u);
        // After block b (texels 4b..4b+3) the window yields texels 4b-6..4b-3, so block b-2
        // is the last two of the step before and the first two of this one.
        for (; next < end + 2u; next++) {
            var v = vec4<f32>(0.0);
            if next < blocks {
                v = vec4<f32>(max(sums4[base + next], vec4<i32>(0)));
            }
            let out = vec4<f32>(window_feed(&w, v.x, k), window_feed(&w, v.y, k),
                window_feed(&w, v.z, k), window_feed(&w, v.w, k));
            if next >= first + 2u {
                scratch[base + next - 2u] = vec4<f32>(previous.zw, out.xy);
            }
            previous = out;
        }
    }
}

// The short kernel along the columns, four adjacent columns per invocation, one row per
// step: reads the rows' result (or, without smoothing, G = max(0, sum) of the photons' sums
// directly), writes the gain map with gains below MIN_GAIN zeroed, and bounds the non-zero
// texels. When the smoothing skips tiles, only the tiles of `tile_bits` are written (the CPU
// has zeroed the map), walked as the rows' pass walks its tiles.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let blocks = row_pitch(p.map.x) / 4u;
    if id.x >= blocks {
        return;
    }
    let from_sums = (smooth_step.bits & FROM_SUMS_STEP) != 0u;
    let height = p.map.y;
    let k = short_kernel(p.map.w);
    let unit = p.misc.y;
    let min_gain = p.misc.w;
    let skip = p.tiles.w != 0u;
    let spans = select(1u, p.tiles.y, skip);
    let span_rows = select(height, u32(TILE), skip);
    let tile = id.x / (u32(TILE) / 4u);
    let x = vec4<u32>(4u * id.x) + vec4<u32>(0u, 1u, 2u, 3u);
    let on_map = x < vec4<u32>(p.map.x);
    let zero = Window(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), 0.0);
    var c0 = zero;
    var c1 = zero;
    var c2 = zero;
    var c3 = zero;
    var first = NONE;
    var final_row = 0u;
    var kept_columns = vec4<bool>(false);
    // The next row the windows take.
    var next = 0u;
    for (var s = 0u; s < spans; s++) {
        if skip && (tile_word(tile, i32(s)) & (1u << (tile % 32u))) == 0u {
            continue;
        }
        let top = s * span_rows;
        let end = min(top + span_rows, height);
        next = max(next, max(top, 6u) - 6u);
        for (; next < end + 6u; next++) {
            var v = vec4<f32>(0.0);
            if next < height {
                if from_sums {
                    v = vec4<f32>(max(sums4[next * blocks + id.x], vec4<i32>(0)));
                } else {
                    v = scratch[next * blocks + id.x];
                }
            }
            let mean = vec4<f32>(window_feed(&c0, v.x, k), window_feed(&c1, v.y, k),
                window_feed(&c2, v.z, k), window_feed(&c3, v.w, k));
            if next < top + 6u {
                continue;
            }
            let at = next - 6u;
            let g = mean / unit;
            let kept = g >= vec4<f32>(min_gain) & on_map;
            gain[at * blocks + id.x] = select(vec4<f32>(0.0), g, kept);
            if any(kept) {
                first = min(first, at);
                final_row = at;
                kept_columns = kept_columns | kept;
            }
        }
    }
    if first != NONE {
        // The first and last kept of the four columns.
        let lo = select(select(select(x.w, x.z, kept_columns.z), x.y, kept_columns.y), x.x,
            kept_columns.x);
        let hi = select(select(select(x.x, x.y, kept_columns.y), x.z, kept_columns.z), x.w,
            kept_columns.w);
        widen_bounds(vec2<u32>(lo, first), vec2<u32>(hi, final_row));
    }
}

// A box mean over a stream of texels: the last 2 radius + 1 inputs and their sum, exactly in
// 64 bits (low and high words), so that nothing drifts along a line.
struct RunningBox {
    ring: array<u32, MAX_BOX>,
    low: u32,
    high: u32,
    slot: u32,
};

// Feeds the next input `v` of the stream to `b` (the inputs before the first count as 0);
// returns the mean of the 2 radius + 1 inputs centred `radius` inputs back.
fn box_feed(b: ptr<function, RunningBox>, v: u32, radius: u32) -> f32 {
    let span = 2u * radius + 1u;
    let slot = (*b).slot;
    let old = (*b).ring[slot];
    (*b).ring[slot] = v;
    (*b).slot = select(slot + 1u, 0u, slot + 1u == span);
    (*b).low += v;
    (*b).high += select(0u, 1u, (*b).low < v);
    (*b).high -= select(0u, 1u, (*b).low < old);
    (*b).low -= old;
    return (f32((*b).high) * 4294967296.0 + f32((*b).low)) / f32(span);
}

// Radii above SHORT_KERNEL_PX: the smoothing along one line (a row or a column) per
// invocation, the box of 2 radius + 1 texels three times over, streamed through ring buffers
// (each box's means feed the next, rounded to fixed point, and texels beyond the map's edge
// count as 0 at every box: their light is lost, as off the floor), so that the cost does not
// grow with the radius. Along the rows it reads G = max(0, sum) of the photons' sums; the
// last pass, along the columns, zeroes gains below MIN_GAIN and bounds the non-zero texels.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth_wide(@builtin(global_invocation_id) id: vec3<u32>) {
    let columns = (smooth_step.bits & COLUMNS_STEP) != 0u;
    let last = (smooth_step.bits & LAST_STEP) != 0u;
    let width = p.map.x;
    let pitch = row_pitch(p.map.x);
    let lines = select(p.map.y, width, columns);
    let length = select(width, p.map.y, columns);
    if id.x >= lines {
        return;
    }
    let stride = select(1u, pitch, columns);
    let start = select(id.x * pitch, id.x, columns);
    let radius = p.map.w;
    let unit = p.misc.y;
    let min_gain = p.misc.w;
    var box1: RunningBox;
    var box2: RunningBox;
    var box3: RunningBox;
    var first = NONE;
    var final_texel = 0u;
    // Texel n of the line enters the first box; each box's mean for a texel comes out radius
    // inputs after the texel entered it, so the third's for texel i at input i + 3 radius.
    for (var n = 0u; n < length + 3u * radius; n++) {
        var v = 0u;
        if n < length {
            let index = start + n * stride;
            if columns {
                v = u32(scratch[index / 4u][index % 4u]);
            } else {
                v = u32(max(sums4[index / 4u][index % 4u], 0));
            }
        }
        let mean1 = box_feed(&box1, v, radius);
        if n < radius {
            continue;
        }
        let at1 = n - radius;
        let mean2 = box_feed(&box2, select(0u, u32(round(mean1)), at1 < length), radius);
        if at1 < radius {
            continue;
        }
        let at2 = at1 - radius;
        let mean = box_feed(&box3, select(0u, u32(round(mean2)), at2 < length), radius);
        if at2 < radius {
            continue;
        }
        let at = at2 - radius;
        let index = start + at * stride;
        if last {
            let g = mean / unit;
            let kept = g >= min_gain;
            gain[index / 4u][index % 4u] = select(0.0, g, kept);
            if kept {
                first = min(first, at);
                final_texel = at;
            }
        } else {
            scratch[index / 4u][index % 4u] = round(mean);
        }
    }
    if first != NONE {
        // Along the line from `first` to `final_texel`; across it, the line itself.
        widen_bounds(select(vec2<u32>(first, id.x), vec2<u32>(id.x, first), columns),
            select(vec2<u32>(final_texel, id.x), vec2<u32>(id.x, final_texel), columns));
    }
}
