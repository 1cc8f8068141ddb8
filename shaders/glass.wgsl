// The glass object: the surface image, the refracted image and the reflected image of one
// eye, added together as linear light on black (on an additive display black adds nothing).
//
// Baseline ("conventional method", METHOD.md section 6, The Cg Tutorial ch. 7): reflection and
// refraction looked up in a latitude-longitude environment map at infinity, blended by an
// empirical Fresnel term. The refracted image then has the disparity of infinity.
//
// Disparity (METHOD.md section 3, eq. 7-8 in Heckbert's form): each eye refracts its own view
// ray at the surface and follows T to the registered background plane, where the photo of the
// real background is sampled at (u_c, v_c). The refracted image gets the disparity of the real
// background seen through the glass. Where T misses the plane, the environment map is used.
//
// The surface image (texture with its transmittance) is blended by eq. 9.
//
// Gaze-dependent defocus (eq. 9-14): the refracted and surface images are read from the frame's
// blend of their blur stacks at the blur it asks for (render/src/blur_blend.rs); one bilinear
// fetch each, whatever the blur.
//
// Two-surface refraction (`[object] refraction = "two-surface"`, beyond the paper,
// docs/equations.md): the ray refracts in at the front, crosses the glass and refracts out at
// the back, total internal reflection followed for up to MAX_INTERNAL_REFLECTIONS bounces
// (then the environment), with exact Fresnel at both interfaces and Beer-Lambert absorption
// over the path inside (glTF KHR_materials_volume). The exit is found on the object's own
// triangles (`mesh_hit`: a bounding-volume hierarchy in a storage buffer, render/src/glass/mesh.rs),
// and a ray that leaves an object that is not convex is followed into it again where it meets
// it (a torus's far side, a goblet's stem); a ball and a convex gem leave analytically (the
// sphere, the facet planes).
//
// Texture fetches per covered pixel: baseline 3 (refracted and reflected environment, surface);
// with background refraction (disparity and/or defocus) and Phong reflection 2 (background
// stack or environment, surface stack); with environment reflection 3. Two-surface adds one
// radial-map fetch per exit step (one for a ball).
//
// The room (`[environment] room`, beyond the paper): the floor and background photos are what
// the glass refracts and reflects, exactly, in every variant: a ray leaving the glass takes the
// photo it meets first (the floor sharp, the background at the frame's blur), the environment
// map only where it meets neither; one fetch per image. Two-surface refraction then also
// follows the light the exit reflects back inside to its next two meetings with the surface
// (partial internal reflections, the faint further images of a real ball): two more exits and
// two more fetches of the room.
//
// Supersampling (`[output] glass_samples`, beyond the paper): the pixel's light is the mean over
// an n x n grid of view rays inside it (`supersampled`, shared/glass_positions.wgsl), so that the
// glass's image is what the eye averages over the pixel where the glass minifies the room, where
// its image jumps from the wall to the floor and at a ball's outline; a ball in the room shades
// its first image over the whole grid and the rest of its light over the positions it needs.
//
// Eq. 6 over the glass (`[display] compensation = "background"`, beyond the paper): the display
// should add only what the eye does not already see, max(T - B, 0), with T the glass's light
// and B the real floor or background the eye sees through the (virtual) glass along the
// pixel's ray (`COMPENSATED`): one more fetch per covered pixel, from both photos packed in one
// texture (shared/seen.wgsl), or with several positions per pixel from their ripmaps over the
// pixel's footprint (shared/compensation.wgsl).

// #include shared/fresnel.wgsl
// #include shared/seen.wgsl
// #include shared/ripmap.wgsl
// #include shared/compensation.wgsl
// #include shared/glass_positions.wgsl

struct Eye {
    clip_from_world: mat4x4<f32>,
    // xyz: the eye's position in the world (metres); w: eye index (0 left, 1 right).
    position: vec4<f32>,
    // xyz: where refraction to the background plane is seen from: this eye (disparity), or
    // the point between the eyes (defocus without disparity); w: the frame's slot, where the
    // positions shaded are counted (`COUNTED`).
    refraction_origin: vec4<f32>,
};

struct Globals {
    world_from_model: mat4x4<f32>,
    // Inverse-transpose of world_from_model, for normals.
    normal_from_model: mat4x4<f32>,
    // Maps the world into the background plane's frame, where its photo covers the unit
    // square [-0.5, 0.5]^2 at z = 0 (top edge towards +y).
    background_from_world: mat4x4<f32>,
    // x: relative index of refraction n; y, z, w: Fresnel bias, scale and power.
    optics: vec4<f32>,
    // xyz: point light position in the world (metres); w: intensity.
    light: vec4<f32>,
    // rgb: light colour (linear); w: Phong exponent.
    light_colour: vec4<f32>,
    // x: exposure of environment radiance; y: surface opacity (1 - transmittance, 0 without a
    // surface texture); z: Phong specular strength; w: positions along each side of a pixel
    // (`SUPERSAMPLED`; the refraction model is the pipeline's entry point).
    shading: vec4<f32>,
    // Inverse of world_from_model.
    model_from_world: mat4x4<f32>,
    // xyz: the object's centre, its bounding box's (model units), the origin of the frame the
    // exit is found in; w: the largest distance of a vertex from it (a ball's radius).
    radial: vec4<f32>,
    // xyz: the object's centre in the world (metres); w: the light's share of the floor's
    // light that the floor seen through a mesh takes lit by `floor_light` (0: the bare photo).
    center_world: vec4<f32>,
    // rgb: absorption inside the glass, halvings per model unit (Beer-Lambert, 2^(-rgb L):
    // the coefficient per world metre times the model's scale over ln 2; 0 in a channel that
    // absorbs nothing, where 2^0 = 1 leaves it exactly as it was); w: 1 where the object is a
    // ball (`front_surface` takes the sphere through its vertices), else 0.
    absorption: vec4<f32>,
    // Maps the world into the floor plane's frame, where its photo covers the unit square
    // [-0.5, 0.5]^2 at z = 0 (top edge away from the viewer).
    floor_from_world: mat4x4<f32>,
};

// The object absorbs (Beer-Lambert, two-surface refraction): a pipeline constant, so that the
// pipeline of clear glass, the usual case, has the exponentials folded away (render/build.rs
// compiles the fs_two_surface_* entry points with it set too).
override ABSORBING: bool = false;

// The object is a ball about its centre (the sphere of radius `g.radial.w` with radial normals,
// optics/src/radial_map.rs `RadialMap::ball`): a pipeline constant, so that a ball's pipeline
// finds its surface analytically.
override BALL: bool = false;

// The object is a flat-shaded convex polyhedron (a cut gem) whose facet planes are `facet_planes`
// (optics/src/convex.rs `facet_planes`): a pipeline constant, so that its pipeline finds
// where a ray leaves exactly, without a search of its triangles.
override CONVEX: bool = false;

// The floor and background photos are the room the glass refracts and reflects (`[environment]
// room`): rays leaving the glass take the photo they meet first, the environment map only where
// they meet neither. A pipeline constant (render/build.rs compiles every entry point with it set
// too), so that the paper's pipelines keep their targets and their cost.
override ROOM: bool = false;

// The glass's light is the mean over several positions inside each pixel (`[output]
// glass_samples`, beyond the paper): a pipeline constant (render/build.rs compiles every glass
// entry point with it set too), so that one position's pipelines, the paper's, keep their code
// and cost.
override SUPERSAMPLED: bool = false;

// Each pixel's light loses what the eye already sees there (eq. 6 over the glass): a pipeline
// constant (render/build.rs compiles every glass entry point with it set too), and the code it
// guards left out of the pipelines without it (with set 1, which only it reads), so that those
// keep their code, cost and descriptor sets.
override COMPENSATED: bool = false;

// Every ray the pixels drawn with this pipeline refract towards the background reaches its
// photo: the frame proved it on the CPU for the part of the eye's image drawn with it
// (render/src/coverage.rs), so the environment map that a ray beside the photo would see is
// left out. A pipeline constant: render/build.rs compiles the background entry points of the
// models that can be proved (the paper's, and two surfaces through a ball) with it set too.
override COVERED: bool = false;

// The positions a ball's pixel shades, or the nodes and triangles a mesh's searches visit and
// test, are counted on the device (`vitreous bench`, the frames that count their work;
// render/src/glass/counted.rs): a pipeline constant, so that ordinary frames neither pay for
// the atomics nor declare the buffer.
override COUNTED: bool = false;

var<push_constant> eye: Eye;
@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var env_map: texture_2d<f32>;
@group(0) @binding(2) var wrap_sampler: sampler;
// The background photo and the surface texture at the frame's blur (eq. 10-14), blended from
// their blur stacks before the eye passes (shaders/blur_blend.wgsl).
@group(0) @binding(3) var background: texture_2d<f32>;
@group(0) @binding(4) var clamp_sampler: sampler;
@group(0) @binding(5) var surface: texture_2d<f32>;
// The object's triangles in a bounding-volume hierarchy (two-surface refraction through a mesh,
// model frame about `g.radial.xyz`; render/src/glass/mesh.rs writes it, one word otherwise):
// element 0 x the first triangle's element (bitcast); node i at 1 + 2i: (low corner, first
// child or triangle slot), (high corner, triangle count, 0 for an inner node); triangle slot k
// at that first element + 6k: corner 0, edge 1, edge 2, the corners' outward unit normals.
@group(0) @binding(6) var<storage, read> mesh: array<vec4<f32>>;
// The facet planes of a convex object (model frame, about the object's centre): xyz the
// outward unit normal, w the plane's distance from the centre. One unused plane otherwise.
@group(0) @binding(7) var<storage, read> facet_planes: array<vec4<f32>>;
// The floor photo (sharp), seen through the glass when the room is a refraction target.
@group(0) @binding(8) var floor_photo: texture_2d<f32>;
// Per frame slot (`eye.refraction_origin.w`), four words (`COUNTED`): a ball's positions of the
// rest and of the first image, then the fragments that shaded them; or a mesh's nodes visited,
// triangles tested, and the fragments.
@group(0) @binding(9) var<storage, read_write> shaded: array<atomic<u32>>;
// The point light's irradiance on the floor with the object over that without it (the caustic
// bake's `E_with / E_without`, the floor photo's uvs): its shadow and its caustic. One texel of
// 1 without a bake that holds it.
@group(0) @binding(10) var floor_light: texture_2d<f32>;
// What the eye already sees (`COMPENSATED`, render/src/compensation.rs): the floor and
// background planes and both photos packed side by side (shared/seen.wgsl), and with several
// positions per pixel their ripmaps (shared/ripmap.wgsl).
@group(1) @binding(0) var<uniform> planes: Planes;
@group(1) @binding(1) var photos: texture_2d<f32>;
@group(1) @binding(2) var photo_sampler: sampler;
@group(1) @binding(3) var<uniform> levels: Levels;
@group(1) @binding(4) var ripmaps: texture_2d<f32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // x: the vertex's distance from the object's centre (world metres); y: 1 where the object
    // is a ball and the vertex normal points away from the centre, else 0. Interpolated: see
    // `front_surface`.
    @location(3) curve: vec2<f32>,
    // Positions along each side of a pixel (`SUPERSAMPLED`), `g.shading.w` at every vertex: the
    // end of `supersampled`'s loop, which must not be read from `g` (lavapipe compiles a shader
    // whose loop ends on a uniform again at each bind and keeps every copy:
    // render/build/uniform_loops.rs).
    @location(4) @interpolate(flat) samples: u32,
};

// Cosine above which a vertex normal counts as pointing away from the object's centre (twin
// of optics/src/two_surface.rs RADIAL_NORMAL_COS).
const RADIAL_NORMAL_COS: f32 = 0.9999;

@vertex
fn vs_main(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> VertexOut {
    return vertex_out(position, normal, uv);
}

// The vertex shader of a ball drawn on its proxy (render/src/glass/proxy.rs: a coarse
// polyhedron about the ball, every face outside its sphere): `vs_main`'s outputs but for
// `curve`, the sphere's own radius (world metres; the object's transform is a similarity)
// wherever the proxy lies, and 1 (a ball).
@vertex
fn vs_ball_proxy(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> VertexOut {
    var out = vertex_out(position, normal, uv);
    let radius = (g.world_from_model * vec4<f32>(g.radial.w, 0.0, 0.0, 0.0)).xyz;
    out.curve = vec2<f32>(length(radius), 1.0);
    return out;
}

fn vertex_out(position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>) -> VertexOut {
    var out: VertexOut;
    let world = g.world_from_model * vec4<f32>(position, 1.0);
    out.world_pos = world.xyz;
    out.world_normal = (g.normal_from_model * vec4<f32>(normal, 0.0)).xyz;
    out.uv = uv;
    let centred = position - g.radial.xyz;
    var radial = 0.0;
    if g.absorption.w > 0.5
        && dot(normal, centred) > RADIAL_NORMAL_COS * length(normal) * length(centred) {
        radial = 1.0;
    }
    out.curve = vec2<f32>(length(world.xyz - g.center_world.xyz), radial);
    out.samples = max(u32(g.shading.w), 1u);
    out.clip = eye.clip_from_world * world;
    return out;
}

const PI: f32 = 3.14159265358979;

// Direction -> latitude-longitude texture coordinate. u = 0.5 looks down -z (forward),
// u grows towards +x; v = 0 is straight up (+y).
fn latlong_uv(d: vec3<f32>) -> vec2<f32> {
    let u = atan2(d.x, -d.z) / (2.0 * PI) + 0.5;
    let v = acos(clamp(d.y / max(length(d), 1e-20), -1.0, 1.0)) / PI;
    return vec2<f32>(u, v);
}

fn environment(d: vec3<f32>) -> vec3<f32> {
    // Explicit LOD: the atan2 seam would otherwise make screen derivatives explode.
    return textureSampleLevel(env_map, wrap_sampler, latlong_uv(d), 0.0).rgb * g.shading.x;
}

// eq. 7-8, Heckbert's form (twin of optics/src/optics.rs refract_heckbert): incident I unit
// from the eye, normal N unit facing the eye, n relative index. xyz: T (not normalised);
// w: 1, or 0 for total internal reflection (non-positive radicand).
fn refract_heckbert(incident: vec3<f32>, normal: vec3<f32>, n: f32) -> vec4<f32> {
    let v = incident / abs(dot(incident, normal));
    let w = v + normal;
    let radicand = n * n * dot(v, v) - dot(w, w);
    if radicand <= 0.0 {
        return vec4<f32>(0.0);
    }
    let k_f = inverseSqrt(radicand);
    return vec4<f32>(k_f * (normal + v) - normal, 1.0);
}

// Where the ray origin + t * dir (t > 0) meets the plane whose frame `plane_from_world` maps
// the world into (its photo on the unit square at z = 0): xy photo coordinates, z the distance
// t, w: 1 on the photo, 0 on a miss.
fn plane_hit(plane_from_world: mat4x4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec4<f32> {
    let o = (plane_from_world * vec4<f32>(origin, 1.0)).xyz;
    let d = (plane_from_world * vec4<f32>(dir, 0.0)).xyz;
    if abs(d.z) < 1e-12 {
        return vec4<f32>(0.0);
    }
    let t = -o.z / d.z;
    let hit = o + d * t;
    if t <= 0.0 || abs(hit.x) > 0.5 || abs(hit.y) > 0.5 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(hit.x + 0.5, 0.5 - hit.y, t, 1.0);
}

// Where the ray origin + t * dir (t > 0) meets the background plane: xy photo coordinates,
// z: 1 on the photo, 0 on a miss (twin of optics/src/optics.rs plane_uv).
fn background_uv(origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let hit = plane_hit(g.background_from_world, origin, dir);
    return vec3<f32>(hit.xy, hit.w);
}

// What a ray leaving the glass sees of the room (`ROOM`): the floor or background photo
// it meets first, else the environment map; one fetch either way. The background is read at
// the frame's blur (defocus), the floor sharp.
fn room(origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let wall = plane_hit(g.background_from_world, origin, dir);
    let floor = plane_hit(g.floor_from_world, origin, dir);
    if floor.w > 0.0 && (wall.w == 0.0 || floor.z < wall.z) {
        return textureSampleLevel(floor_photo, clamp_sampler, floor.xy, 0.0).rgb;
    }
    if wall.w > 0.0 {
        return textureSampleLevel(background, clamp_sampler, wall.xy, 0.0).rgb;
    }
    return environment(dir);
}

// What light that passed through an object other than a ball (two-surface refraction), or was
// reflected off it, sees of the room where it leaves: as `room`, but the floor under the object
// shows its shadow and caustic (the bake's `floor_light`, for the light's share of the floor's
// light while it holds, `g.center_world.w`, else 0). A ball's images and the paper's model keep
// the bare photo.
fn room_through(origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let floor = plane_hit(g.floor_from_world, origin, dir);
    let wall = plane_hit(g.background_from_world, origin, dir);
    if floor.w > 0.0 && (wall.w == 0.0 || floor.z < wall.z) {
        let photo = textureSampleLevel(floor_photo, clamp_sampler, floor.xy, 0.0).rgb;
        let ratio = textureSampleLevel(floor_light, clamp_sampler, floor.xy, 0.0).r;
        // No branch on the share: lavapipe compiles a copy of a shader for the uniform values
        // its branches read at every bind, and keeps them all (render/build/uniform_loops.rs).
        let share = g.center_world.w;
        return photo * (1.0 - share + share * ratio);
    }
    return room(origin, dir);
}

// What a two-surface passage sees beyond the glass where the background plane is not its
// target: the room from where it left (`ROOM`), else, or when given up inside, the environment.
fn beyond_passage(passage: Passage) -> vec3<f32> {
    if ROOM {
        if !BALL {
            return room_through(passage.exit, passage.direction);
        }
        return room(passage.exit, passage.direction);
    }
    return environment(passage.direction);
}

// What a ray leaving the glass sees where the paper's model shows the environment map: the
// room when the scene registers it as such, else the map.
fn beyond(origin: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    if ROOM {
        return room(origin, dir);
    } else {
        return environment(dir);
    }
}

// Total internal reflections followed each time the light is inside (twin of
// optics/src/two_surface.rs MAX_INTERNAL_REFLECTIONS: a torus's ring guides light far around).
const MAX_INTERNAL_REFLECTIONS: i32 = 48;
// Partial internal reflections after the exit followed with the room (`ROOM`): at a ball's rim,
// where the exit reflects most, the second still shows (ꟻLIP in glass-sphere-real's disc 0.274
// with one, 0.268 with two, 0.267 with three or six: docs/realism.md).
const ECHOES: i32 = 2;
// A convex gem's: a brilliant (ior 2.42) returns most of its light after several internal
// reflections, each exit passing a share out (the diamond in glass-sphere-real's settings: disc
// gap 0.50 with 2, 0.42 with 8; docs/realism.md).
const CONVEX_ECHOES: i32 = 8;
// Entries into the object along one path at most (`MESH`, an object that is not convex: the
// first and the re-entries after it leaves, as a ray through a torus's hole or past a goblet's
// cup into its stem; then the room beyond, whatever the object).
const MAX_ENTRIES: i32 = 4;

// Far crossing of the ray p + t d (d unit) with the sphere of radius r about the origin.
fn sphere_exit(p: vec3<f32>, d: vec3<f32>, r: f32) -> f32 {
    let b = dot(p, d);
    let c = dot(p, p) - r * r;
    return -b + sqrt(max(b * b - c, 0.0));
}

// Where the ray p + t d (from inside, d unit) leaves the convex object of `facet_planes`: x the
// distance t, yzw the outward unit normal (twin of optics/src/convex.rs convex_exit).
fn convex_exit(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    var exit = vec4<f32>(3.0e38, 0.0, 0.0, 0.0);
    // Eight planes a round (optics/src/convex.rs `in_eights`: lavapipe's loop limit, `mesh_hit`).
    let count = arrayLength(&facet_planes);
    for (var i = 0u; i < count; i += 8u) {
        exit_through(&exit, facet_planes[i], p, d);
        exit_through(&exit, facet_planes[i + 1u], p, d);
        exit_through(&exit, facet_planes[i + 2u], p, d);
        exit_through(&exit, facet_planes[i + 3u], p, d);
        exit_through(&exit, facet_planes[i + 4u], p, d);
        exit_through(&exit, facet_planes[i + 5u], p, d);
        exit_through(&exit, facet_planes[i + 6u], p, d);
        exit_through(&exit, facet_planes[i + 7u], p, d);
    }
    return exit;
}

// `exit` (`convex_exit`) where `plane` lies nearer ahead of p along d.
fn exit_through(exit: ptr<function, vec4<f32>>, plane: vec4<f32>, p: vec3<f32>, d: vec3<f32>) {
    let along = dot(plane.xyz, d);
    if along > 1e-7 {
        let t = max((plane.w - dot(plane.xyz, p)) / along, 0.0);
        if t < (*exit).x {
            *exit = vec4<f32>(t, plane.xyz);
        }
    }
}

struct Passage {
    // Where the ray left the object (or was given up), world metres.
    exit: vec3<f32>,
    // Unit direction after it, world.
    direction: vec3<f32>,
    // Exact Fresnel transmittance of both interfaces times the Beer-Lambert transmittance of
    // the path inside, per linear RGB channel.
    transmission: vec3<f32>,
    // 1 when it left the object, 0 when given up inside (environment).
    escaped: f32,
    // With the room (`ROOM`): the room's light that the exit reflects back inside and that
    // leaves at the next ECHOES meetings with the surface (the partial internal reflections,
    // which a real ball shows as faint further images), linear RGB.
    echoes: vec3<f32>,
};

// Where the ray p + t d (from inside, d unit; model frame about the object's centre) leaves
// the object: x the distance t, yzw the outward unit normal there. Exact for a convex
// polyhedron (`CONVEX`, its planes), a ball and any closed mesh (its triangles, `mesh_exit`).
fn find_exit(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    // Each model's way in a branch of its own, none after another's return: what a pipeline
    // constant rules out is no code of its pipeline, nor of its counted cost.
    if CONVEX {
        return convex_exit(p, d);
    } else if BALL {
        // The entry lies on the ball (`front_surface`): the exit of the sphere through it is
        // the exit (a device that runs a loop's first pass for every lane, as lavapipe does,
        // would still pay for a secant step of the search below).
        let t = sphere_exit(p, d, length(p));
        return vec4<f32>(t, normalize(p + d * t));
    } else {
        return mesh_exit(p, d);
    }
}

// Where a search of the object's triangles (`mesh_hit`) meets none.
const NO_HIT: f32 = 3.0e38;

// Offset along a ray leaving a point of the surface before the next search, model units (the
// models are about one unit across): the triangle it leaves is not met again.
const MESH_EPS: f32 = 1e-5;

// Depth of the hierarchy's search stack: render/src/glass/mesh.rs refuses a deeper hierarchy.
const MESH_STACK: u32 = 32u;

// Nodes one search visits at most: a guard against a malformed buffer (a search through a
// shipped model visits a few dozen).
const MESH_VISITS: u32 = 4096u;

// The nodes and triangles this invocation's searches visited and tested (`COUNTED`).
var<private> mesh_nodes: u32;
var<private> mesh_triangles: u32;

// The positions of this pixel's grid whose view ray passed beside a mesh or a gem
// (`SUPERSAMPLED`, `front_surface`).
var<private> missed_positions: u32;

// The positions of this pixel's grids shaded through a mesh or a gem (`SUPERSAMPLED`,
// `supersampled`).
var<private> positions_shaded: u32;
// The share of the pixel the glass covers, where its pipeline knows it (a ball's over several
// positions: `ball_parts`, `supersampled`): the alpha it outputs, and the share of the real
// world eq. 6 takes away.
var<private> covered_share: f32 = 1.0;

// Distance along the ray p + t / inv (t >= 0) to the box [lo, hi], or NO_HIT where it passes
// beside it.
fn box_entry(lo: vec3<f32>, hi: vec3<f32>, p: vec3<f32>, inv: vec3<f32>) -> f32 {
    let t0 = (lo - p) * inv;
    let t1 = (hi - p) * inv;
    let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    return select(NO_HIT, near, near <= far);
}

// Where the ray p + t d (t > 0) meets the triangle whose elements start at `at` in `mesh`, either
// side (Möller-Trumbore): x the distance t, NO_HIT where it passes beside; yz the barycentric
// weights of corners 1 and 2.
fn triangle_hit(at: u32, p: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let e1 = mesh[at + 1u].xyz;
    let e2 = mesh[at + 2u].xyz;
    let q = cross(d, e2);
    let det = dot(e1, q);
    let s = p - mesh[at].xyz;
    let u = dot(s, q) / det;
    let r = cross(s, e1);
    let v = dot(d, r) / det;
    let t = dot(e2, r) / det;
    let hit = det != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0;
    return vec3<f32>(select(NO_HIT, t, hit), u, v);
}

// Distances along the ray p + t / inv to the boxes of the children of the inner node whose left
// child is `first` (`box_entry`): x the left's, y the right's.
fn children_entries(first: u32, p: vec3<f32>, inv: vec3<f32>) -> vec2<f32> {
    let left = box_entry(mesh[1u + 2u * first].xyz, mesh[2u + 2u * first].xyz, p, inv);
    let right = box_entry(mesh[3u + 2u * first].xyz, mesh[4u + 2u * first].xyz, p, inv);
    return vec2<f32>(left, right);
}

// A search of the object's triangles under way (`mesh_hit`): the nearest meeting so far (its
// distance, NO_HIT while none, its triangle's first element and barycentric weights), the nodes
// still to visit, and the nodes visited.
struct Search {
    best: f32,
    best_at: u32,
    best_uv: vec2<f32>,
    stack: array<u32, MESH_STACK>,
    depth: u32,
    visits: u32,
};

// Triangles per leaf of the hierarchy at most (optics/src/solid/bvh.rs LEAF_SIZE; render/src/
// glass/mesh.rs refuses a larger leaf): `visit` tests them without a loop.
const LEAF_TRIANGLES: u32 = 4u;

// The triangle whose elements start at `at`, tested against the ray p + t d (`triangle_hit`):
// the search's nearest meeting where it is nearer.
fn test_triangle(s: ptr<function, Search>, at: u32, p: vec3<f32>, d: vec3<f32>) {
    let hit = triangle_hit(at, p, d);
    if hit.x < (*s).best {
        (*s).best = hit.x;
        (*s).best_at = at;
        (*s).best_uv = hit.yz;
    }
}

// The search's next node, where one is left: passed over where its box lies beyond the nearest
// meeting so far; a leaf's triangles tested; an inner node's children put on the stack, the
// nearer last (searched first), each only where its box lies nearer than the nearest meeting.
fn visit(s: ptr<function, Search>, p: vec3<f32>, d: vec3<f32>, inv: vec3<f32>, base: u32) {
    if (*s).depth == 0u {
        return;
    }
    (*s).visits += 1u;
    (*s).depth -= 1u;
    let node = (*s).stack[(*s).depth];
    let low = mesh[1u + 2u * node];
    let high = mesh[2u + 2u * node];
    if box_entry(low.xyz, high.xyz, p, inv) >= (*s).best {
        return;
    }
    let first = bitcast<u32>(low.w);
    let count = bitcast<u32>(high.w);
    if count > 0u {
        // One triangle at least, LEAF_TRIANGLES at most.
        let at = base + 6u * first;
        test_triangle(s, at, p, d);
        if count > 1u {
            test_triangle(s, at + 6u, p, d);
        }
        if count > 2u {
            test_triangle(s, at + 12u, p, d);
        }
        if count > 3u {
            test_triangle(s, at + 18u, p, d);
        }
        mesh_triangles += count;
    } else {
        let entries = children_entries(first, p, inv);
        // The farther child first, so that the nearer is searched first.
        let near_first = entries.x <= entries.y;
        if max(entries.x, entries.y) < (*s).best && (*s).depth < MESH_STACK {
            (*s).stack[(*s).depth] = select(first, first + 1u, near_first);
            (*s).depth += 1u;
        }
        if min(entries.x, entries.y) < (*s).best && (*s).depth < MESH_STACK {
            (*s).stack[(*s).depth] = select(first + 1u, first, near_first);
            (*s).depth += 1u;
        }
    }
}

// The nearest meeting of the ray p + t d (t > 0, d unit; model frame about the object's centre)
// with the object's triangles (twin of optics/src/solid/bvh.rs `Bvh::closest` and
// optics/src/two_surface.rs `MeshBody::hit`, either side of a triangle): x the distance t (NO_HIT
// where it meets none), yzw the corners' outward normals interpolated there, as the rasteriser
// interpolates them over the front surface.
fn mesh_hit(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    // A direction along an axis: its reciprocal large rather than infinite (the boxes' slabs
    // then still order correctly).
    let inv = 1.0 / select(d, vec3<f32>(1e-30), abs(d) < vec3<f32>(1e-30));
    let base = bitcast<u32>(mesh[0].x);
    var s: Search;
    s.best = NO_HIT;
    s.stack[0] = 0u;
    s.depth = 1u;
    // Four visits a round, and a leaf's triangles tested without a loop: lavapipe ends every
    // loop of an invocation once its loops together have run 65,535 rounds (gallivm's loop
    // limiter, counted over a SIMD vector of invocations), silently, and a pixel's positions then
    // go unshaded (docs/realism.md, "lavapipe's loop limit").
    while s.depth > 0u && s.visits < MESH_VISITS {
        visit(&s, p, d, inv, base);
        visit(&s, p, d, inv, base);
        visit(&s, p, d, inv, base);
        visit(&s, p, d, inv, base);
    }
    mesh_nodes += s.visits;
    if s.best >= NO_HIT {
        return vec4<f32>(NO_HIT, 0.0, 0.0, 0.0);
    }
    let normal = mesh[s.best_at + 3u].xyz * (1.0 - s.best_uv.x - s.best_uv.y)
        + mesh[s.best_at + 4u].xyz * s.best_uv.x + mesh[s.best_at + 5u].xyz * s.best_uv.y;
    return vec4<f32>(s.best, normalize(normal));
}

// Where the ray p + t d from inside the mesh leaves it (`find_exit`; twin of
// optics/src/two_surface.rs `MeshBody::leave`): searched from MESH_EPS along, past the triangle
// the ray starts on; the normal there turned to face along the ray, as the physical reference
// turns it (where shading normals bend a grazing ray's reflection out through the surface, the
// next triangle it meets faces it). Where the search meets nothing (such a ray out in the open),
// x is -1: the light is lost, as in the reference.
fn mesh_exit(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let hit = mesh_hit(p + d * MESH_EPS, d);
    if hit.x >= NO_HIT {
        return vec4<f32>(-1.0, d);
    }
    return vec4<f32>(hit.x + MESH_EPS, select(-hit.yzw, hit.yzw, dot(hit.yzw, d) >= 0.0));
}

// The cost of one node a search visits and of one triangle it tests (render/src/glass.rs charges
// each the device counted, `COUNTED`): entry points no pipeline draws with.
@fragment
fn fs_two_surface_mesh_node(in: VertexOut) -> @location(0) vec4<f32> {
    let node = u32(in.uv.x);
    let inv = 1.0 / in.world_normal;
    let low = mesh[1u + 2u * node];
    let high = mesh[2u + 2u * node];
    let entry = box_entry(low.xyz, high.xyz, in.world_pos, inv);
    let entries = children_entries(bitcast<u32>(low.w), in.world_pos, inv);
    return vec4<f32>(entry, entries, bitcast<f32>(high.w));
}

@fragment
fn fs_two_surface_mesh_triangle(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(triangle_hit(u32(in.uv.x), in.world_pos, in.world_normal), 1.0);
}

// Light inside the glass on its way to the surface (`two_surface`), model frame about the
// object's centre.
struct Inside {
    // Where it is, and its unit direction.
    p: vec3<f32>,
    d: vec3<f32>,
    // The share of the light the interfaces passed so far (exact Fresnel).
    transmission: f32,
    // Length of the path inside so far, model units.
    path: f32,
    // 1 once it left the object (p the exit, d the direction after it), 0 while inside or
    // given up inside.
    escaped: f32,
    // At the last exit: the light arriving there, its reflectance, and the direction of what it
    // reflects back inside (the echoes').
    arriving: f32,
    reflectance: f32,
    echo_d: vec3<f32>,
};

// `light` followed to where it leaves the object: at each meeting with the surface it refracts
// out, or beyond the critical angle is reflected totally, MAX_INTERNAL_REFLECTIONS times at most
// (then given up inside).
fn to_the_outside(light: Inside, ior: f32) -> Inside {
    var s = light;
    for (var bounce = 0; bounce <= MAX_INTERNAL_REFLECTIONS; bounce++) {
        let exit = find_exit(s.p, s.d);
        if !BALL {
            if !CONVEX {
                if exit.x < 0.0 {
                    // Out of the mesh already, meeting nothing (`mesh_exit`): lost.
                    s.transmission = 0.0;
                    s.arriving = 0.0;
                    s.escaped = 1.0;
                    break;
                }
            }
        }
        s.p += s.d * exit.x;
        s.path += exit.x;
        let outward = exit.yzw;
        let leaving = refract(s.d, -outward, ior);
        if dot(leaving, leaving) > 0.0 {
            s.arriving = s.transmission;
            s.reflectance = fresnel_exact(dot(s.d, outward), ior);
            s.echo_d = reflect(s.d, outward);
            s.transmission *= 1.0 - s.reflectance;
            s.d = leaving;
            s.escaped = 1.0;
            break;
        }
        s.d = reflect(s.d, outward);
    }
    return s;
}

// Meetings with the surface a branch of the light through a mesh is followed to at most
// (`follow`): most of a thin wall's or a stem's reflections leave within a few; a ring guides
// some further (16 rather than 6: the torus's disc gap 0.372 -> 0.368 at 640 x 480, 3 % more
// nodes searched).
const BRANCH_MEETINGS: i32 = 16;

// A branch of the light through a mesh (`follow`, `follow_once`): where it is and its unit
// direction (model frame about the object's centre), whether it is inside, the share of its
// light that passed the meetings so far, and its length inside.
struct Branch {
    p: vec3<f32>,
    d: vec3<f32>,
    inside: bool,
    passed: f32,
    path: f32,
};

// The branch `b`'s next meeting with the surface: inside, refracted out (or reflected totally
// beyond the critical angle); outside, refracted in where it meets the object again. Returns the
// direction of the share the meeting splits off (back inside after an exit, away after an entry)
// and that share (w; 0 where it reflects totally), or w -1 where the branch ends: still inside
// and meeting nothing (`mesh_exit`: lost), or outside and meeting nothing more.
fn meet(b: ptr<function, Branch>, ior: f32) -> vec4<f32> {
    let d = (*b).d;
    // One search whether inside or out (lavapipe inlines every call: one copy of the search
    // here, not one for each side).
    let hit = mesh_hit((*b).p + d * MESH_EPS, d);
    if hit.x >= NO_HIT {
        return vec4<f32>(d, -1.0);
    }
    (*b).p += d * (hit.x + MESH_EPS);
    // The normal there turned to face along the ray (`mesh_exit`).
    let along = select(-hit.yzw, hit.yzw, dot(hit.yzw, d) >= 0.0);
    if (*b).inside {
        (*b).path += hit.x + MESH_EPS;
        let leaving = refract(d, -along, ior);
        if dot(leaving, leaving) > 0.0 {
            let reflected = fresnel_exact(dot(d, along), ior);
            (*b).passed *= 1.0 - reflected;
            (*b).d = normalize(leaving);
            (*b).inside = false;
            return vec4<f32>(reflect(d, along), reflected);
        }
        (*b).d = reflect(d, along);
        return vec4<f32>(d, 0.0);
    }
    let facing = -along;
    let reflected = fresnel_exact(-dot(d, facing), 1.0 / ior);
    (*b).passed *= 1.0 - reflected;
    (*b).d = normalize(refract(d, facing, 1.0 / ior));
    (*b).inside = true;
    return vec4<f32>(reflect(d, facing), reflected);
}

// The room where the branch `b` left the object for good (times the share that passed and,
// absorbing, the path's absorption); nothing while it is still inside.
fn left_for_good(b: Branch) -> vec3<f32> {
    if b.inside {
        return vec3<f32>(0.0);
    }
    var light = vec3<f32>(b.passed);
    if ABSORBING {
        light *= exp2(-g.absorption.rgb * b.path);
    }
    let leaves_at = (g.world_from_model * vec4<f32>(b.p + g.radial.xyz, 1.0)).xyz;
    let towards = normalize((g.world_from_model * vec4<f32>(b.d, 0.0)).xyz);
    return room_through(leaves_at, towards) * light;
}

// The room's light along a branch of a branch of the light through a mesh in the room:
// from `start` (model frame about the object's centre) along the unit `dir`, inside the glass
// or out of it, followed without splitting (at each meeting with the surface the share that
// passes, all of it reflected beyond the critical angle) to BRANCH_MEETINGS meetings at most;
// the room where it leaves for good (times the share that passed and, absorbing, the path's
// absorption), nothing where it is still inside then, or lost (`mesh_exit`).
fn follow_once(start: vec3<f32>, dir: vec3<f32>, from_inside: bool, ior: f32) -> vec3<f32> {
    var b = Branch(start, dir, from_inside, 1.0, 0.0);
    for (var k = 0; k < BRANCH_MEETINGS; k++) {
        if meet(&b, ior).w < 0.0 {
            break;
        }
    }
    return left_for_good(b);
}

// A branch's own split-offs (`follow`) carrying less than this share of the eye's light are
// not followed: most carry a few thousandths, and the few near grazing and the critical angle,
// where the surface reflects most, carry the light that matters (the goblet's disc gap at 640 x
// 480: 0.356 with none, 0.330 at this share, 0.327 with every one).
const MIN_SPLIT: f32 = 0.002;

// The room's light along a branch of the light through a mesh in the room, which carries
// `weight` of the eye's light: from `start` (model frame about the object's centre) along the
// unit `dir`, inside the glass or out of it, to BRANCH_MEETINGS meetings at most; at each meeting
// with the surface the share that passes goes on (all of it beyond the critical angle), and the
// share it splits off (an exit's reflection back inside, a re-entry's reflection away) is
// followed without splitting again (`follow_once`) where it carries MIN_SPLIT of the eye's light
// or more. The room where the branch leaves for good (times the share that passed and,
// absorbing, the path's absorption), nothing where it is still inside then or lost
// (`mesh_exit`), and the split-offs' light.
fn follow(start: vec3<f32>, dir: vec3<f32>, from_inside: bool, ior: f32, weight: f32)
    -> vec3<f32> {
    var b = Branch(start, dir, from_inside, 1.0, 0.0);
    var split = vec3<f32>(0.0);
    for (var k = 0; k < BRANCH_MEETINGS; k++) {
        let passed = b.passed;
        let away = meet(&b, ior);
        if away.w < 0.0 {
            break;
        }
        if weight * passed * away.w >= MIN_SPLIT {
            // The split-off starts where the branch now goes the other way: back inside after
            // an exit, outside after an entry.
            var share = vec3<f32>(passed * away.w);
            if ABSORBING {
                share *= exp2(-g.absorption.rgb * b.path);
            }
            split += follow_once(b.p, away.xyz, !b.inside, ior) * share;
        }
    }
    return split + left_for_good(b);
}

// The share of the light of `s` that is still left after its path inside, per channel (its
// absorption, `ABSORBING`).
fn absorbed(s: Inside) -> vec3<f32> {
    var left = vec3<f32>(1.0);
    if ABSORBING {
        left = exp2(-g.absorption.rgb * s.path);
    }
    return left;
}

// The light the exit of `s` reflects back inside (a ball or a convex gem in the room), followed
// to its next ECHOES meetings with the surface: at each, the share that leaves sees the room,
// the rest goes on inside.
fn echoes_of(s: Inside, ior: f32) -> vec3<f32> {
    var echoes = vec3<f32>(0.0);
    var q = s.p;
    var e = s.echo_d;
    var carried = s.arriving * s.reflectance;
    var path = s.path;
    let meetings = select(ECHOES, CONVEX_ECHOES, CONVEX);
    for (var k = 0; k < meetings; k++) {
        let exit = find_exit(q, e);
        q += e * exit.x;
        path += exit.x;
        let leaving = refract(e, -exit.yzw, ior);
        if dot(leaving, leaving) > 0.0 {
            let reflected = fresnel_exact(dot(e, exit.yzw), ior);
            var share = vec3<f32>(carried * (1.0 - reflected));
            if ABSORBING {
                share *= exp2(-g.absorption.rgb * path);
            }
            let leaves_at = (g.world_from_model * vec4<f32>(q + g.radial.xyz, 1.0)).xyz;
            let towards = normalize((g.world_from_model * vec4<f32>(leaving, 0.0)).xyz);
            if BALL {
                echoes += room(leaves_at, towards) * share;
            } else {
                echoes += room_through(leaves_at, towards) * share;
            }
            carried *= reflected;
        }
        e = reflect(e, exit.yzw);
    }
    return echoes;
}

// Two-surface refraction (twin of optics/src/two_surface.rs pass_through): the unit ray
// `incident` meets the front surface at `entry` (world) with unit normal `normal` facing it.
// Through a mesh in the room, the light each later meeting with the surface splits off (the
// share an exit reflects back inside, the share a re-entry reflects away) is followed too
// (`follow`), as the echoes of a ball's exit are.
fn two_surface(entry: vec3<f32>, incident: vec3<f32>, normal: vec3<f32>, ior: f32) -> Passage {
    var out: Passage;
    let inside_world = refract(incident, normal, 1.0 / ior);
    let p = (g.model_from_world * vec4<f32>(entry, 1.0)).xyz - g.radial.xyz;
    let d = normalize((g.model_from_world * vec4<f32>(inside_world, 0.0)).xyz);
    let entered = 1.0 - fresnel_exact(-dot(incident, normal), 1.0 / ior);
    var s = Inside(p, d, entered, 0.0, 0.0, 0.0, 0.0, d);
    out.echoes = vec3<f32>(0.0);
    if BALL {
        s = to_the_outside(s, ior);
        if ROOM && s.escaped > 0.0 {
            out.echoes = echoes_of(s, ior);
        }
    } else if CONVEX {
        s = to_the_outside(s, ior);
        if ROOM && s.escaped > 0.0 {
            out.echoes = echoes_of(s, ior);
        }
    } else {
        // Out of an object that is not convex, the ray may meet it again: in there, and on to
        // where it leaves again. Its meetings in turn, each splitting a share off: an exit (even
        // k, after the way to it inside) reflects one back inside, a re-entry (odd k) one away;
        // each written once (lavapipe inlines every call: one copy of `to_the_outside` and of
        // `follow` with their searches, not two).
        for (var k = 0; k < 2 * MAX_ENTRIES - 1; k++) {
            let entering = k % 2 == 1;
            var facing = vec3<f32>(0.0);
            var reflects = 0.0;
            if entering {
                let again = mesh_hit(s.p + s.d * MESH_EPS, s.d);
                if again.x >= NO_HIT {
                    break;
                }
                s.p += s.d * (again.x + MESH_EPS);
                facing = select(-again.yzw, again.yzw, dot(s.d, again.yzw) < 0.0);
                reflects = fresnel_exact(-dot(s.d, facing), 1.0 / ior);
            } else {
                s = to_the_outside(s, ior);
                if s.escaped == 0.0 {
                    break;
                }
            }
            if ROOM {
                let weight = select(s.arriving * s.reflectance, s.transmission * reflects, entering);
                let split = select(s.echo_d, reflect(s.d, facing), entering);
                out.echoes += follow(s.p, split, !entering, ior, weight) * weight * absorbed(s);
            }
            if entering {
                s.transmission *= 1.0 - reflects;
                s.d = normalize(refract(s.d, facing, 1.0 / ior));
                s.escaped = 0.0;
            }
        }
    }
    out.escaped = s.escaped;
    out.transmission = vec3<f32>(s.transmission) * absorbed(s);
    out.exit = (g.world_from_model * vec4<f32>(s.p + g.radial.xyz, 1.0)).xyz;
    out.direction = normalize((g.world_from_model * vec4<f32>(s.d, 0.0)).xyz);
    return out;
}

// Two surfaces through a ball (`BALL`; render/src/coverage.rs `pass_ball` is its twin): in at
// the entry, across, and out at the first meeting with the surface. A ray that enters a ball
// meets the surface inside as steeply as it left the entry, below the critical angle, so none
// is reflected inside but by rounding at a grazing exit, where the ray goes on straight (both
// surfaces pass under 1e-4 of the light there). In the world: the object's transform is a
// similarity, so the ball is one about its world centre through the entry. A room's ball keeps
// `two_surface`, whose echoes follow the light the exit reflects back inside.
fn ball_passage(entry: vec3<f32>, incident: vec3<f32>, normal: vec3<f32>, ior: f32) -> Passage {
    var out: Passage;
    let inside = refract(incident, normal, 1.0 / ior);
    let from_centre = entry - g.center_world.xyz;
    let radius = length(from_centre);
    let across = sphere_exit(from_centre, inside, radius);
    let exit = from_centre + inside * across;
    let outward = exit / radius;
    let leaving = refract(inside, -outward, ior);
    // A ball meets the ray inside at the exit as steeply as the refracted ray left the entry,
    // and the reflectance there is the entry's (Stokes): both surfaces pass (1 - F)^2.
    let passed = 1.0 - fresnel_exact(-dot(incident, normal), 1.0 / ior);
    out.transmission = vec3<f32>(passed * passed);
    if ABSORBING {
        // `g.absorption` is per model unit: the model's radius over the world's.
        out.transmission *= exp2(-g.absorption.rgb * (across * g.radial.w / radius));
    }
    out.escaped = 1.0;
    out.echoes = vec3<f32>(0.0);
    out.exit = exit + g.center_world.xyz;
    out.direction = select(inside, leaving, dot(leaving, leaving) > 0.0);
    return out;
}

// The front surface under a fragment: world position and unit normal (not yet facing the
// eye). Where the object is a ball (its vertex normals point away from its centre), the
// surface between the vertices is taken as the sphere about the centre through them (radius
// interpolated) rather than the flat triangle, and the eye's ray is intersected with it: a
// tessellated ball then refracts as the ball itself (a 96 x 48 sphere's flat triangles
// misplaced refracted images by pixels near the fold). Elsewhere (faceted stones, any other
// mesh, even where a vertex normal happens to point away from the centre, as on a torus's outer
// equator) the triangle and its interpolated normal, as the CPU's mesh tracer takes it.
struct Front {
    position: vec3<f32>,
    normal: vec3<f32>,
    // True where a position of the pixel's grid (`SUPERSAMPLED`) sees past the object (false
    // as the struct starts: no store in the pipelines that never search).
    missed: bool,
};

// Where the ray p + t d (from outside, d unit; model frame about the object's centre) enters
// the convex object of `facet_planes`: x the distance t (NO_HIT where it passes beside), yzw
// the outward unit normal there.
fn convex_entry(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    // x the entry's distance, y the exit's; the entry's plane's normal.
    var span = vec2<f32>(0.0, 3.0e38);
    var n_in = vec3<f32>(0.0);
    // Eight planes a round (`convex_exit`).
    let count = arrayLength(&facet_planes);
    for (var i = 0u; i < count; i += 8u) {
        enter_through(&span, &n_in, facet_planes[i], p, d);
        enter_through(&span, &n_in, facet_planes[i + 1u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 2u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 3u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 4u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 5u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 6u], p, d);
        enter_through(&span, &n_in, facet_planes[i + 7u], p, d);
    }
    if span.x > span.y || dot(n_in, n_in) == 0.0 {
        return vec4<f32>(NO_HIT, d);
    }
    return vec4<f32>(span.x, n_in);
}

// The span of the ray p + t d inside the planes so far (`convex_entry`) cut by `plane`.
fn enter_through(
    span: ptr<function, vec2<f32>>, n_in: ptr<function, vec3<f32>>, plane: vec4<f32>,
    p: vec3<f32>, d: vec3<f32>,
) {
    let along = dot(plane.xyz, d);
    let inside = plane.w - dot(plane.xyz, p);
    if along < -1e-7 {
        let t = inside / along;
        if t > (*span).x {
            (*span).x = t;
            *n_in = plane.xyz;
        }
    } else if along > 1e-7 {
        (*span).y = min((*span).y, inside / along);
    } else if inside < 0.0 {
        (*span).y = -1.0;
    }
}

fn front_surface(in: VertexOut, two_surface_model: bool) -> Front {
    // The object's transform is a similarity (uniform scale), so the sphere about its centre is
    // a sphere in the world too, and the eye's ray meets it without leaving the world frame.
    let from_centre = eye.position.xyz - g.center_world.xyz;
    let d = normalize(in.world_pos - eye.position.xyz);
    let b = dot(from_centre, d);
    let c = dot(from_centre, from_centre) - in.curve.x * in.curve.x;
    let on_sphere = from_centre + d * (-b - sqrt(max(b * b - c, 0.0)));
    let weight = clamp(in.curve.y, 0.0, 1.0);
    var out: Front;
    out.position = mix(in.world_pos, on_sphere + g.center_world.xyz, weight);
    out.normal = normalize(mix(normalize(in.world_normal), on_sphere / in.curve.x, weight));
    // Each condition its own `if`, so that a pipeline constant that rules one out rules out
    // the search too (in the paper's pipelines and a ball's, and in their counted cost).
    if SUPERSAMPLED {
        if !BALL {
            if two_surface_model {
                // A position of the pixel's grid carried off the rasterised triangle by the
                // screen derivatives lies on the triangle's plane, not on the object (outside a
                // convex surface, inside a concave one), where a passage through both surfaces
                // would start on the wrong side: its own view ray finds where it meets the
                // object (its facet planes, or its triangles), or that it passes beside it. (The
                // paper's one surface refracts at the triangle's plane, as it always did.)
                let p0 = (g.model_from_world * vec4<f32>(eye.position.xyz, 1.0)).xyz
                    - g.radial.xyz;
                let dm = normalize((g.model_from_world * vec4<f32>(d, 0.0)).xyz);
                var hit: vec4<f32>;
                if CONVEX {
                    hit = convex_entry(p0, dm);
                } else {
                    hit = mesh_hit(p0, dm);
                }
                if hit.x >= NO_HIT {
                    out.missed = true;
                    return out;
                }
                out.position = (g.world_from_model
                    * vec4<f32>(p0 + dm * hit.x + g.radial.xyz, 1.0)).xyz;
                out.normal = normalize((g.normal_from_model * vec4<f32>(hit.yzw, 0.0)).xyz);
            }
        }
    }
    return out;
}

// One fragment entry point per pipeline (render/src/glass.rs `GlassVariant`): the refraction
// model; whether refraction reaches the registered background plane (disparity or defocus on)
// or the environment; Phong or environment reflection. Each calls `shade` with constants, so
// its pipeline holds only its own path. A branch on a uniform is not free on every device:
// lavapipe runs both sides, masked (paper O5 cost twice as much while the two models shared one
// entry point, and the baseline 1.6x while it shared one with O5).
@fragment
fn fs_paper_environment_fresnel(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, false, false, false);
}

@fragment
fn fs_paper_environment_phong(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, false, false, true);
}

@fragment
fn fs_paper_background_fresnel(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, false, true, false);
}

@fragment
fn fs_paper_background_phong(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, false, true, true);
}

@fragment
fn fs_two_surface_environment_fresnel(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, true, false, false);
}

@fragment
fn fs_two_surface_environment_phong(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, true, false, true);
}

@fragment
fn fs_two_surface_background_fresnel(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, true, true, false);
}

@fragment
fn fs_two_surface_background_phong(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in, true, true, true);
}

fn shade(in: VertexOut, two_surface_model: bool, to_background: bool, phong: bool) -> vec4<f32> {
    // eq. 9: C_o = alpha C_s + (1 - alpha) C_b, alpha the surface's opacity.
    let surface_texel = textureSample(surface, wrap_sampler, in.uv);
    let alpha = g.shading.y * surface_texel.a;
    var light: vec3<f32>;
    if SUPERSAMPLED {
        light = supersampled(in, two_surface_model, to_background, phong, alpha);
    } else {
        light = shade_ray(in, two_surface_model, to_background, phong, alpha);
    }
    var out = alpha * surface_texel.rgb + light;
    if COUNTED {
        if !BALL {
            if !CONVEX {
                // The nodes and triangles the mesh's searches visited and tested (`mesh_hit`),
                // the fragment, and the positions it shaded.
                let slot = 4u * u32(eye.refraction_origin.w);
                atomicAdd(&shaded[slot], mesh_nodes);
                atomicAdd(&shaded[slot + 1u], mesh_triangles);
                atomicAdd(&shaded[slot + 2u], 1u);
                var positions = 1u;
                if SUPERSAMPLED {
                    positions = positions_shaded;
                }
                atomicAdd(&shaded[slot + 3u], positions);
            }
        }
    }
    if COMPENSATED {
        // Each side of each pipeline constant its own line, so that the cost counted of every
        // pipeline is the one fetch of `seen_behind`.
        if SUPERSAMPLED {
            if !BALL {
                if two_surface_model {
                    // Where positions of the grid passed beside a mesh or a gem, the eye sees
                    // the real world there through no glass: it is taken away over the covered
                    // share only.
                    let grid = f32(positions_shaded);
                    let covered = (grid - f32(missed_positions)) / grid;
                    out = max(out - seen_behind(in) * covered, vec3<f32>(0.0));
                } else {
                    out = max(out - seen_behind(in), vec3<f32>(0.0));
                }
            } else {
                // A ball's: over the share of the pixel it covers.
                out = max(out - seen_behind(in) * covered_share, vec3<f32>(0.0));
            }
        } else {
            out = max(out - seen_behind(in), vec3<f32>(0.0));
        }
    }
    // Alpha: the share of the pixel the glass covers, where the pipeline knows it (each
    // pipeline constant its own `if`, so that the others' counted cost is as it was).
    if SUPERSAMPLED {
        if BALL {
            return vec4<f32>(out, covered_share);
        }
    }
    return vec4<f32>(out, 1.0);
}

// B of eq. 6 over the glass: what the eye sees of the real floor or background along the
// pixel's ray, at its centre, or over the pixel as the glass's light is with several positions
// per pixel (`SUPERSAMPLED`).
fn seen_behind(in: VertexOut) -> vec3<f32> {
    let origin = eye.position.xyz;
    var seen: vec3<f32>;
    if SUPERSAMPLED {
        seen = seen_over_footprint(origin, in.world_pos, dpdx(in.world_pos), dpdy(in.world_pos));
    } else {
        seen = seen_along(origin, normalize(in.world_pos - origin));
    }
    return seen;
}

// The glass's light along one view ray, but for the surface's own (eq. 9's
// `(1 - alpha) C_b`, the refraction and reflection).
fn shade_ray(
    in: VertexOut, two_surface_model: bool, to_background: bool, phong: bool, alpha: f32,
) -> vec3<f32> {
    let front = front_surface(in, two_surface_model);
    if SUPERSAMPLED {
        if !BALL {
            if two_surface_model {
                if front.missed {
                    // A position beside the object adds nothing; with eq. 6 the pixel takes away
                    // the real world only over the share of its grid the object covers (`shade`).
                    missed_positions += 1u;
                    return vec3<f32>(0.0);
                }
            }
        }
    }
    let world_pos = front.position;
    let incident = normalize(world_pos - eye.position.xyz);
    var n = front.normal;
    if dot(n, incident) > 0.0 {
        n = -n;
    }
    let ior = g.optics.x;
    let reflected = reflect(incident, n);
    var fresnel = clamp(g.optics.y + g.optics.z * pow(1.0 + dot(incident, n), g.optics.w), 0.0, 1.0);

    // The refracted image C_b.
    var refracted_image: vec3<f32>;
    if two_surface_model {
        // Two-surface: exact Fresnel at the front for the reflection; the refracted image
        // carries both interfaces' transmittance (1 - fresnel undoes the blend below).
        var origin = eye.position.xyz;
        if to_background {
            origin = eye.refraction_origin.xyz;
        }
        let from_origin = normalize(world_pos - origin);
        var passage: Passage;
        if COVERED || (BALL && !ROOM) {
            passage = ball_passage(world_pos, from_origin, n, ior);
        } else {
            passage = two_surface(world_pos, from_origin, n, ior);
        }
        fresnel = fresnel_exact(-dot(incident, n), 1.0 / ior);
        // The background where the ray reaches it, else the environment (fetched only there);
        // the room's photos, nearest first, when the scene registers them as the room.
        var seen: vec3<f32>;
        if COVERED {
            // The frame proved that the ray leaves the ball towards the photo and reaches it
            // (render/src/coverage.rs; only the background looks are compiled with COVERED).
            let uv = background_uv(passage.exit, passage.direction);
            seen = textureSampleLevel(background, clamp_sampler, uv.xy, 0.0).rgb;
        } else if to_background && !ROOM {
            var uv = vec3<f32>(0.0);
            if passage.escaped > 0.0 {
                uv = background_uv(passage.exit, passage.direction);
            }
            if uv.z > 0.0 {
                seen = textureSampleLevel(
                    background, clamp_sampler, uv.xy, 0.0).rgb;
            } else {
                seen = beyond_passage(passage);
            }
        } else {
            seen = beyond_passage(passage);
        }
        var light = seen * passage.transmission;
        if ROOM {
            // The real ball's faint further images: light reflected inside once or more.
            light += passage.echoes;
        }
        refracted_image = light / max(1.0 - fresnel, 1e-6);
    } else if to_background {
        if COVERED {
            // The frame proved that this ray reaches the photo (render/src/coverage.rs; only
            // the background looks are compiled with COVERED): eq. 7-8 give its direction,
            // V' = V / |V . N| the same for any length of V, with a positive radicand (a ray
            // from outside the glass is never reflected totally), and it meets the photo's
            // plane ahead, on the photo.
            let from_origin = world_pos - eye.refraction_origin.xyz;
            let v = from_origin / abs(dot(from_origin, n));
            let w = v + n;
            let away = inverseSqrt(max(ior * ior * dot(v, v) - dot(w, w), 1e-20)) * w - n;
            let o = (g.background_from_world * vec4<f32>(world_pos, 1.0)).xyz;
            let d = (g.background_from_world * vec4<f32>(away, 0.0)).xyz;
            let hit = o.xy - d.xy * (o.z / d.z);
            refracted_image = textureSampleLevel(
                background, clamp_sampler, vec2<f32>(hit.x + 0.5, 0.5 - hit.y), 0.0).rgb;
        } else {
            let from_origin = normalize(world_pos - eye.refraction_origin.xyz);
            let t = refract_heckbert(from_origin, n, ior);
            // Total internal reflection (t.w = 0) sees the environment the mirror way.
            let away = select(reflected, t.xyz, t.w != 0.0);
            let uv = background_uv(world_pos, away);
            if ROOM {
                refracted_image = room(world_pos, away);
            } else if uv.z * t.w > 0.0 {
                refracted_image = textureSampleLevel(
                    background, clamp_sampler, uv.xy, 0.0).rgb;
            } else {
                refracted_image = environment(away);
            }
        }
    } else {
        var t = refract(incident, n, 1.0 / ior);
        if dot(t, t) == 0.0 {
            t = reflected;
        }
        refracted_image = beyond(world_pos, t);
    }

    // The reflected image.
    var reflected_image: vec3<f32>;
    if phong {
        let to_light = normalize(g.light.xyz - world_pos);
        let mirror = reflect(-to_light, n);
        let specular = pow(max(dot(mirror, -incident), 0.0), g.light_colour.w);
        reflected_image = g.light_colour.rgb * g.light.w * g.shading.z * specular;
    } else {
        reflected_image = fresnel * beyond(world_pos, reflected);
        if ROOM {
            if !BALL {
                if two_surface_model {
                    // Off an object other than a ball, the floor beside it in its shadow and
                    // caustic as well (a ball's images keep the bare photo).
                    reflected_image = fresnel * room_through(world_pos, reflected);
                }
            }
        }
    }

    return (1.0 - alpha) * (1.0 - fresnel) * refracted_image + reflected_image;
}
