// Caustics of the glass object on the floor for the current pose (docs/caustics.md, eq. 6),
// by photon splatting: `cs_trace` sends one photon per cell of an equal-solid-angle grid over
// the cone from the light around the object, traces it through the mesh (Snell refraction,
// exact Fresnel weights, both branches followed) and adds its share of the relative gain G to
// the four floor texels around where it lands; a photon that meets the object also takes its
// straight continuation away (the shadow, E_blocked). `cs_smooth` then takes G = max(0, sum)
// per texel, as the bake stores it, and smooths it (density estimation: a lone photon's share
// spreads over the kernel, as a beam's does in the bake) with a box filter run three times
// along the rows, then three times along the columns, one dispatch each way; the last zeroes
// gains below MIN_GAIN (as in the bake) and bounds the non-zero texels, which the overlay
// covers (its vertex stage reads the bound on the frame that computes the map). Without
// smoothing a single dispatch of a one-texel box does only the latter.
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
    // the mesh bounds one convex body (a ray leaving it outward meets no more of it), else 0.
    shell_outer: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> p: Params;
// Model-space positions (xyz) and outward unit vertex normals (xyz).
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> normals: array<vec4<f32>>;
// Triangle list.
@group(0) @binding(3) var<storage, read> indices: array<u32>;
// Per grid cell (x fastest): first entry in cell_tris and count.
@group(0) @binding(4) var<storage, read> cells: array<vec2<u32>>;
@group(0) @binding(5) var<storage, read> cell_tris: array<u32>;
// Fixed-point sums of G per texel (row 0 at the photo's top).
@group(0) @binding(6) var<storage, read_write> sums: array<atomic<i32>>;
// The smoothed gain map.
@group(0) @binding(7) var<storage, read_write> gain: array<f32>;
// The box of the non-zero gains: smallest x, smallest y, largest x, largest y (texels; the
// CPU sets it to an empty box before each computation).
@group(0) @binding(8) var<storage, read_write> bounds: array<atomic<u32>, 4>;
// The fixed-point gains smoothed along the rows (between the two smoothing passes).
@group(0) @binding(9) var<storage, read_write> scratch: array<u32>;
// Per triangle its first corner and two edges (xyz, model units), gathered once so that a
// test reads three vectors instead of three indices and three positions.
@group(0) @binding(10) var<storage, read> corners: array<vec4<f32>>;

const NONE: u32 = 0xffffffffu;
const PI: f32 = 3.14159265358979;
const STACK: u32 = 16u;

struct Hit {
    t: f32,
    tri: u32,
    u: f32,
    v: f32,
};

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
    weight: f32,
    interactions: u32,
    inside: u32,
};

// Möller-Trumbore: (t, u, v) of the hit of the ray with triangle `tri`, t < 0 for none.
fn triangle_hit(o: vec3<f32>, d: vec3<f32>, tri: u32) -> vec3<f32> {
    let a = corners[3u * tri].xyz;
    let e1 = corners[3u * tri + 1u].xyz;
    let e2 = corners[3u * tri + 2u].xyz;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = dot(tv, pv) * inv;
    if u < 0.0 || u > 1.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    return vec3<f32>(dot(e2, qv) * inv, u, v);
}

// The nearest surface hit along the ray at a distance within [t_from, t_to], or `best` when
// that is nearer, walking the grid's cells in order over that stretch. Hits found in the
// cells walked beyond `t_to` are kept too (they are real, and nearer ones are found by a
// later walk that starts from `best`).
fn walk_grid(o: vec3<f32>, d: vec3<f32>, t_from: f32, t_to: f32, best_so_far: Hit) -> Hit {
    var best = best_so_far;
    let dims = vec3<i32>(p.grid_dims.xyz);
    let side = p.grid_origin.w;
    let lo = p.grid_origin.xyz;
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
            if h.x > p.misc.x && h.x < best.t {
                best = Hit(h.x, tri, h.y, h.z);
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
// middle and the space around it cost no grid steps.
fn closest_hit(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    let none = Hit(t_max, NONE, 0.0, 0.0);
    let oc = o - p.shell.xyz;
    let b = dot(oc, d);
    // The ray's nearest approach to the centre, squared (stable far from the object).
    let q = oc - b * d;
    let q2 = dot(q, q);
    let outer = p.shell_outer.x;
    let h_out = outer * outer - q2;
    if h_out < 0.0 {
        return none;
    }
    let s_out = sqrt(h_out);
    let pad = p.shell_outer.y;
    let enter = max(-b - s_out - pad, 0.0);
    let leave = min(-b + s_out + pad, t_max);
    if enter > leave {
        return none;
    }
    let inner = p.shell.w;
    let h_in = inner * inner - q2;
    if inner <= 0.0 || h_in <= 0.0 {
        return walk_grid(o, d, enter, leave, none);
    }
    let s_in = sqrt(h_in);
    // The stretch before the inner ball, then the one after it.
    var best = none;
    let near_end = min(-b - s_in + pad, leave);
    if enter <= near_end {
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

// Distance along the ray to the floor's visible side, model units; negative when it does not
// approach it.
fn floor_t(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let point = (p.model_from_world * vec4<f32>(p.world_from_plane[3].xyz, 1.0)).xyz;
    let world_normal = normalize(cross(p.world_from_plane[0].xyz, p.world_from_plane[1].xyz));
    let normal = normalize((p.model_from_world * vec4<f32>(world_normal, 0.0)).xyz);
    let denom = dot(d, normal);
    if denom >= 0.0 {
        return -1.0;
    }
    return dot(point - o, normal) / denom;
}

// Adds `weight` photons' worth of G at the model-space floor point, split bilinearly between
// the four nearest texel centres. One photon's G is its flux over a texel's area and the bare
// floor's irradiance where it lands: (solid angle) r^2 / (area cos theta), taken at that point
// rather than at each texel centre (a texel away the two differ by 0.2 % at most on the
// shipped floors; the bake takes the texel's).
fn deposit(point_m: vec3<f32>, weight: f32) {
    let world = (p.world_from_model * vec4<f32>(point_m, 1.0)).xyz;
    let local = (p.plane_from_world * vec4<f32>(world, 1.0)).xy;
    if abs(local.x) > 0.5 || abs(local.y) > 0.5 {
        return;
    }
    let size = vec2<i32>(p.map.xy);
    let t = vec2<f32>(local.x + 0.5, 0.5 - local.y) * vec2<f32>(size) - 0.5;
    let base = vec2<i32>(floor(t));
    let f = t - floor(t);
    let normal = normalize(cross(p.world_from_plane[0].xyz, p.world_from_plane[1].xyz));
    let to_light = p.light.xyz - world;
    let r2 = dot(to_light, to_light);
    let cos_theta = dot(to_light, normal) * inverseSqrt(r2);
    if cos_theta <= 0.0 {
        return;
    }
    let g0 = weight * p.light.w * r2 / (p.basis_v.w * cos_theta) * p.misc.y;
    for (var k = 0; k < 4; k++) {
        let texel = base + vec2<i32>(k & 1, k >> 1u);
        if any(texel < vec2<i32>(0)) || any(texel >= size) {
            continue;
        }
        let wx = select(1.0 - f.x, f.x, (k & 1) == 1);
        let wy = select(1.0 - f.y, f.y, (k >> 1u) == 1);
        let index = texel.y * size.x + texel.x;
        atomicAdd(&sums[index], i32(round(g0 * wx * wy)));
    }
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
    let k = r * r * p.axis.w;
    let cos_theta = 1.0 - k;
    let sin_theta = sign(r) * sqrt(max(k * (2.0 - k), 0.0));
    let d = sin_theta * (cos(phi) * p.basis_u.xyz + sin(phi) * p.basis_v.xyz)
        + cos_theta * p.axis.xyz;
    return normalize(d);
}

@compute @workgroup_size(8, 8, 1)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = p.grid_dims.w;
    if id.x >= n || id.y >= n {
        return;
    }
    let world_dir = cone_direction((f32(id.x) + 0.5) / f32(n), (f32(id.y) + 0.5) / f32(n));
    let origin = (p.model_from_world * vec4<f32>(p.light.xyz, 1.0)).xyz;
    let dir = normalize((p.model_from_world * vec4<f32>(world_dir, 0.0)).xyz);
    let straight = floor_t(origin, dir);
    let first = closest_hit(origin, dir, select(1e30, straight, straight > 0.0));
    if first.tri == NONE {
        // Missed the object: the bare floor's light, which G is relative to.
        return;
    }
    if straight > 0.0 {
        deposit(origin + dir * straight, -1.0);
    }
    var stack: array<Ray, STACK>;
    var depth = 0u;
    var ray = Ray(origin, dir, 1.0, 0u, 0u);
    var hit = first;
    loop {
        if hit.tri != NONE {
            // Split at the surface into the reflected and the refracted part.
            if ray.interactions < p.map.z {
                let tri = hit.tri;
                let i0 = indices[3u * tri];
                let i1 = indices[3u * tri + 1u];
                let i2 = indices[3u * tri + 2u];
                let a = positions[i0].xyz;
                let point = ray.origin + ray.dir * hit.t;
                let geometric = normalize(cross(positions[i1].xyz - a, positions[i2].xyz - a));
                let shading = normalize((1.0 - hit.u - hit.v) * normals[i0].xyz
                    + hit.u * normals[i1].xyz + hit.v * normals[i2].xyz);
                let entering = dot(ray.dir, geometric) < 0.0;
                let side_g = select(-geometric, geometric, entering);
                var side_s = select(-shading, shading, entering);
                if !(dot(side_s, ray.dir) < 0.0 && dot(side_s, side_g) > 0.0) {
                    side_s = side_g;
                }
                let eta = select(p.basis_u.w, 1.0 / p.basis_u.w, entering);
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
                let interactions = ray.interactions + 1u;
                if reflected_weight >= p.misc.z && depth < STACK {
                    stack[depth] = Ray(point + side_g * p.misc.x, r, reflected_weight,
                        interactions, ray.inside);
                    depth++;
                }
                let refracted_weight = ray.weight * (1.0 - reflectance);
                if refracts && refracted_weight >= p.misc.z && depth < STACK {
                    stack[depth] = Ray(point - side_g * p.misc.x, t, refracted_weight,
                        interactions, 1u - ray.inside);
                    depth++;
                }
            }
        }
        if depth == 0u {
            break;
        }
        depth--;
        ray = stack[depth];
        var to_floor = -1.0;
        if ray.inside == 0u {
            to_floor = floor_t(ray.origin, ray.dir);
        }
        if ray.inside == 0u && p.shell_outer.z > 0.0 {
            // Leaving a convex body outward: nothing of it lies ahead.
            hit = Hit(0.0, NONE, 0.0, 0.0);
        } else {
            hit = closest_hit(ray.origin, ray.dir, select(1e30, to_floor, to_floor > 0.0));
        }
        if hit.tri == NONE && to_floor > 0.0 {
            deposit(ray.origin + ray.dir * to_floor, ray.weight);
        }
    }
}

// Which smoothing pass a dispatch runs (`smooth_steps` in live.rs): bit 0 clear along the
// rows (reading the photons' sums), set along the columns (reading the rows' result); bit 8
// set on the last pass, which writes the gain map.
struct SmoothStep {
    bits: u32,
};
var<push_constant> smooth_step: SmoothStep;

const LAST_STEP: u32 = 0x100u;
// Most texels in one box: 2 x 64 + 1 (`MAX_SMOOTHING_PX` in live.rs).
const MAX_BOX: u32 = 129u;

// A box mean over a stream of texels: the last 2 radius + 1 inputs and their sum, exactly in
// 64 bits (low and high words), so that nothing drifts along a line.
struct RunningBox {
    ring: array<u32, MAX_BOX>,
    low: u32,
    high: u32,
    count: u32,
};

// Feeds the next input `v` of the stream to `b` (the inputs before the first count as 0);
// returns the mean of the 2 radius + 1 inputs centred `radius` inputs back.
fn box_feed(b: ptr<function, RunningBox>, v: u32, radius: u32) -> f32 {
    let span = 2u * radius + 1u;
    let slot = (*b).count % span;
    let old = (*b).ring[slot];
    (*b).ring[slot] = v;
    (*b).count += 1u;
    (*b).low += v;
    (*b).high += select(0u, 1u, (*b).low < v);
    (*b).high -= select(0u, 1u, (*b).low < old);
    (*b).low -= old;
    return (f32((*b).high) * 4294967296.0 + f32((*b).low)) / f32(span);
}

// The smoothing along one line (a row or a column) per invocation: the box of 2 radius + 1
// texels three times over, streamed (each box's means feed the next, rounded to fixed point,
// and texels beyond the map's edge count as 0 at every box: their light is lost, as off the
// floor). Along the rows it reads G = max(0, sum) of the photons' sums (eq. 6's clamp, per
// texel as the bake stores it). The last pass also zeroes gains below MIN_GAIN and bounds
// the non-zero texels.
@compute @workgroup_size(64, 1, 1)
fn cs_smooth(@builtin(global_invocation_id) id: vec3<u32>) {
    let columns = (smooth_step.bits & 1u) != 0u;
    let last = (smooth_step.bits & LAST_STEP) != 0u;
    let width = p.map.x;
    let lines = select(p.map.y, width, columns);
    let length = select(width, p.map.y, columns);
    if id.x >= lines {
        return;
    }
    let stride = select(1u, width, columns);
    let start = select(id.x * width, id.x, columns);
    let radius = p.map.w;
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
                v = scratch[index];
            } else {
                v = u32(max(atomicLoad(&sums[index]), 0));
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
            let g = mean / p.misc.y;
            let kept = g >= p.misc.w;
            gain[index] = select(0.0, g, kept);
            if kept {
                first = min(first, at);
                final_texel = at;
            }
        } else {
            scratch[index] = u32(round(mean));
        }
    }
    if first != NONE {
        // Along the line from `first` to `final_texel`; across it, the line itself.
        let lo = select(vec2<u32>(first, id.x), vec2<u32>(id.x, first), columns);
        let hi = select(vec2<u32>(final_texel, id.x), vec2<u32>(id.x, final_texel), columns);
        atomicMin(&bounds[0], lo.x);
        atomicMin(&bounds[1], lo.y);
        atomicMax(&bounds[2], hi.x);
        atomicMax(&bounds[3], hi.y);
    }
}
