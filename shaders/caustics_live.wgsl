// Caustics of the glass object on the floor for the current pose (docs/caustics.md, eq. 6),
// by photon splatting: `cs_trace` sends one photon per cell of an equal-solid-angle grid over
// the cone from the light around the object, traces it through the mesh (Snell refraction,
// exact Fresnel weights, both branches followed) and adds its share of the relative gain G to
// the four floor texels around where it lands; a photon that meets the object also takes its
// straight continuation away (the shadow, E_blocked). Each deposit also adds its positive
// share to its cell's mass, which the smoothing (caustics_smooth.wgsl) bounds its tiles with.
//
// On a CPU device (lavapipe) every access of a storage buffer is a loop over the SIMD lanes,
// so the trace reads its parameters once into registers.
//
// Geometry is traced in the object's model space (the mesh never moves there); a uniform grid
// of triangle lists, built once on the CPU, finds the surfaces.

// #include shared/fresnel.wgsl
// #include shared/caustics_maps.wgsl

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
// Per triangle its first corner and two edges (xyz, model units), gathered once so that a
// test reads three vectors instead of three indices and three positions.
@group(0) @binding(8) var<storage, read> corners: array<vec4<f32>>;
// The planes of a convex flat-faceted body's facets, `params.facets.x` of them (0 for any other
// mesh): xyz the outward unit normal, w the distance from the shell's centre. A ray inside
// such a body leaves it through the nearest plane ahead (`facet_exit`).
@group(0) @binding(13) var<storage, read> facet_planes: array<vec4<f32>>;
// Counting the work (`COUNTED`, a pipeline constant: only the pipeline that counts pays for
// the atomics): the photons that met the object and were traced through it, and the deposits
// that landed on the map (each path's, and each photon's shadow), one global atomic per photon
// traced (render/src/floor/live.rs `PhotonWork`).
override COUNTED: bool = false;
@group(0) @binding(14) var<storage, read_write> photon_counts: array<atomic<u32>, 2>;
// This invocation's deposits on the map.
var<private> splats: u32;
// A hit's `tri` when it was found on a facet plane: its normal is the facet's, which the
// shading takes too (the mesh is flat-shaded).
const FACET: u32 = 0xfffffffeu;
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

// Where a ray from inside a convex flat-faceted body (unit `d`) leaves it: the nearest facet
// plane ahead. Every lane reads the same plane at each step, so on a CPU device each plane
// is one load for all of them, where the grid's cells are loads per lane.
fn facet_exit(o: vec3<f32>, d: vec3<f32>) -> Hit {
    var best = Hit(1e30, NONE, 0.0, 0.0, vec3<f32>(0.0));
    let q = o - params.shell.xyz;
    for (var i = 0u; i < params.facets.x; i++) {
        let plane = facet_planes[i];
        let along = dot(plane.xyz, d);
        if along > 1e-7 {
            let t = max((plane.w - dot(plane.xyz, q)) / along, 0.0);
            if t < best.t {
                best = Hit(t, FACET, 0.0, 0.0, plane.xyz);
            }
        }
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
    splats += 1u;
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
        atomicAdd(&cell_mass[cell.y * mass_pitch(params.tiles.x) + cell.x],
            (u32(positive) + MASS_UNIT - 1u) / MASS_UNIT);
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
    splats = 0u;
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
                var shading = geometric;
                if tri != FACET {
                    shading = normalize((1.0 - hit.u - hit.v) * vertex_normals[3u * tri].xyz
                        + hit.u * vertex_normals[3u * tri + 1u].xyz
                        + hit.v * vertex_normals[3u * tri + 2u].xyz);
                }
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
        if ray.inside == 1u && params.facets.x > 0u {
            hit = facet_exit(ray.origin, ray.dir);
        } else {
            hit = closest_hit(ray.origin, ray.dir, select(1e30, to_floor, to_floor > 0.0),
                ray.inside == 1u && params.shell_outer.w > 0.0);
        }
        if hit.tri == NONE && to_floor > 0.0 {
            deposit(ray.origin + ray.dir * to_floor, ray.weight);
        }
    }
    if COUNTED {
        atomicAdd(&photon_counts[0], 1u);
        if splats > 0u {
            atomicAdd(&photon_counts[1], splats);
        }
    }
}
