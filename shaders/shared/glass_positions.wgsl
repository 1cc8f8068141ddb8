// Shared by the glass's shaders that name it in a `// #include shared/glass_positions.wgsl`
// line: the glass's light over a pixel from several positions inside it (`[output]
// glass_samples`, beyond the paper). The including shader declares the glass's globals,
// `VertexOut`, `shade_ray`, `ball_passage`, `sphere_exit`, `fresnel_exact`, `room` and ECHOES.
//
// A pipeline whose object is a ball in the room (`BALL`, `ROOM`) shades a ball's light in two
// parts, each over as many positions as it needs, in its environment looks (a background look
// reads the background at the frame's blur, and shades every whole position as any other
// pipeline does): the first image (`first_image`: the room refracted through both surfaces, the
// light that is most of the pixel's and changes fastest inside it, where the ball minifies the
// wall and table, where its image turns from the wall to the floor, at a photo's edge) over the
// whole n x n grid, and the rest (`rest_of_light`: the light the exit reflects back inside, the
// internal echoes, faint inside the rim, and the surface's reflection) over a 2 x 2 grid
// (`REST_SIDE`), or over the whole grid towards the ball's outline (`RIM`: the pixel covered in
// part, the exit reflecting more and more of the light back inside, the echoes' images the most
// minified) and on the reflected highlight (`HIGHLIGHT`). Both follow the ball analytically, as
// `shade_ray`'s two-surface passage through a ball does, each for its part alone.
//
// A ball's pipelines over several positions draw it on a proxy about it (render/src/glass/
// proxy.rs): a pixel is the glass's where a position's ray meets the ball, its alpha the share
// that do (`ball_parts`, `supersampled`).
//
// Through a mesh or a gem (two-surface, not a ball), a pixel whose n x n grid leaves its light
// uncertain (`needs_finer`) shades a grid twice as fine too, and its light is the mean over both.

// Share of the ball's radius off its centre beyond which a pixel shades the rest over the whole
// grid.
const RIM: f32 = 0.9;

// The reflected highlight's radiance (linear, the largest channel) at the pixel's centre above
// which it shades the rest over the whole grid: the Phong highlight is sharp (exponent 200).
const HIGHLIGHT: f32 = 0.02;

// Positions along each side of a pixel where it shades the rest, elsewhere.
const REST_SIDE: u32 = 2u;

// Where the eye's ray through `at` meets the ball (`BALL`: the sphere about the object's centre
// through the vertices, as `front_surface` takes it): xyz from the centre, w 1; w 0 where it
// passes beside.
fn on_ball(at: VertexOut) -> vec4<f32> {
    let from_centre = eye.position.xyz - g.center_world.xyz;
    let incident = normalize(at.world_pos - eye.position.xyz);
    let b = dot(from_centre, incident);
    let c = dot(from_centre, from_centre) - at.curve.x * at.curve.x;
    if b * b - c < 0.0 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(from_centre + incident * (-b - sqrt(b * b - c)), 1.0);
}

// The first image at the position `at`: the room seen through both surfaces of the ball, times
// their transmittance (`ball_passage`), as `shade_ray` adds it but for the surface's
// `(1 - alpha)`, w 1; nothing (w 0) where the ray passes beside the ball.
fn first_image(at: VertexOut) -> vec4<f32> {
    let hit = on_ball(at);
    if hit.w == 0.0 {
        return vec4<f32>(0.0);
    }
    let entry = hit.xyz + g.center_world.xyz;
    let incident = normalize(entry - eye.position.xyz);
    let passage = ball_passage(entry, incident, normalize(hit.xyz / at.curve.x), g.optics.x);
    return vec4<f32>(room(passage.exit, passage.direction) * passage.transmission, 1.0);
}

// The rest of the ball's light at the position `at`, as `shade_ray` adds it through two surfaces
// with the room: the surface's reflection (`phong`: the highlight of the light, else the room in
// the mirror direction by the exact Fresnel term) and, times `(1 - alpha)`, the light the exit
// reflects back inside followed to its next ECHOES meetings with the surface (as `two_surface`
// does: at each, the share that leaves sees the room, the rest goes on inside); nothing where
// the ray passes beside the ball.
fn rest_of_light(at: VertexOut, phong: bool, alpha: f32) -> vec3<f32> {
    let hit = on_ball(at);
    if hit.w == 0.0 {
        return vec3<f32>(0.0);
    }
    let radius = at.curve.x;
    let ior = g.optics.x;
    let entry = hit.xyz + g.center_world.xyz;
    let incident = normalize(entry - eye.position.xyz);
    let n = normalize(hit.xyz / radius);
    let entered = fresnel_exact(-dot(incident, n), 1.0 / ior);
    var reflected: vec3<f32>;
    if phong {
        let to_light = normalize(g.light.xyz - entry);
        let mirror = reflect(-to_light, n);
        let specular = pow(max(dot(mirror, -incident), 0.0), g.light_colour.w);
        reflected = g.light_colour.rgb * g.light.w * g.shading.z * specular;
    } else {
        reflected = entered * room(entry, reflect(incident, n));
    }
    // Across to the exit, where a ball reflects as the entry did (Stokes), and back inside.
    let inside = refract(incident, n, 1.0 / ior);
    var path = sphere_exit(hit.xyz, inside, radius);
    var q = hit.xyz + inside * path;
    var outward = normalize(q);
    var carried = (1.0 - entered) * fresnel_exact(dot(inside, outward), ior);
    var e = reflect(inside, outward);
    var echoes = vec3<f32>(0.0);
    for (var k = 0; k < ECHOES; k++) {
        let t = sphere_exit(q, e, radius);
        q += e * t;
        path += t;
        outward = normalize(q);
        let leaving = refract(e, -outward, ior);
        if dot(leaving, leaving) > 0.0 {
            let reflects = fresnel_exact(dot(e, outward), ior);
            var share = vec3<f32>(carried * (1.0 - reflects));
            if ABSORBING {
                // `g.absorption` is per model unit: the model's radius over the world's.
                share *= exp2(-g.absorption.rgb * (path * g.radial.w / radius));
            }
            echoes += room(q + g.center_world.xyz, normalize(leaving)) * share;
            carried *= reflects;
        }
        e = reflect(e, outward);
    }
    return (1.0 - alpha) * echoes + reflected;
}

// The cost of one position of each part (render/src/glass.rs charges each position a pixel
// shades beyond its first at it): entry points no pipeline draws with.
@fragment
fn fs_two_surface_first_image(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(first_image(in).rgb, 1.0);
}

@fragment
fn fs_two_surface_rest_fresnel(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(rest_of_light(in, false, 0.0), 1.0);
}

@fragment
fn fs_two_surface_rest_phong(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(rest_of_light(in, true, 0.0), 1.0);
}

// Position `i` of the regular n x n grid inside a pixel, in pixels from its centre.
fn grid_position(i: u32, n: u32) -> vec2<f32> {
    return (vec2<f32>(f32(i % n), f32(i / n)) + 0.5) / f32(n) - 0.5;
}

// `in` moved by `offset` pixels across and down, its vertex outputs carried there by their
// screen derivatives `dx` and `dy`.
fn moved(in: VertexOut, dx: VertexOut, dy: VertexOut, offset: vec2<f32>) -> VertexOut {
    var at = in;
    at.world_pos += dx.world_pos * offset.x + dy.world_pos * offset.y;
    at.world_normal += dx.world_normal * offset.x + dy.world_normal * offset.y;
    at.curve += dx.curve * offset.x + dy.curve * offset.y;
    return at;
}

// Whether the pixel at `in` shades the rest of the ball's light over the whole grid: it lies
// towards the ball's outline (`RIM`), or on the reflected highlight (`phong`).
fn rest_over_whole_grid(in: VertexOut, phong: bool) -> bool {
    let from_centre = eye.position.xyz - g.center_world.xyz;
    let incident = normalize(in.world_pos - eye.position.xyz);
    let towards = dot(from_centre, incident);
    let off_centre = dot(from_centre, from_centre) - towards * towards;
    var whole = off_centre > RIM * RIM * in.curve.x * in.curve.x;
    if phong {
        let hit = on_ball(in);
        let n = normalize(hit.xyz / in.curve.x);
        let to_light = normalize(g.light.xyz - hit.xyz - g.center_world.xyz);
        let specular = pow(max(dot(reflect(-to_light, n), -incident), 0.0), g.light_colour.w);
        let highlight = g.light_colour.rgb * (g.light.w * g.shading.z * specular);
        whole = whole || max(highlight.r, max(highlight.g, highlight.b)) > HIGHLIGHT;
    }
    return whole;
}

// The glass's light over a pixel (`SUPERSAMPLED`): the mean of `shade_ray` over a regular
// n x n grid of positions inside it (n = `in.samples`), each a view ray of its own through the
// surface found as at the pixel's centre, with the vertex outputs carried there by their screen
// derivatives; for a ball in the room in an environment look, its two parts each over its own
// grid (above); through a mesh or a gem, a grid twice as fine too where the first leaves the
// pixel's light uncertain (`needs_finer`). Where a position's ray passes beside a ball (its front
// surface is the sphere through its vertices), the glass adds nothing there: the pixel's edge is
// covered in part.
fn supersampled(
    in: VertexOut, two_surface_model: bool, to_background: bool, phong: bool, alpha: f32,
) -> vec3<f32> {
    let n = in.samples;
    let grid = n * n;
    let dx = VertexOut(vec4<f32>(0.0), dpdx(in.world_pos), dpdx(in.world_normal), vec2<f32>(0.0),
        dpdx(in.curve), 0u);
    let dy = VertexOut(vec4<f32>(0.0), dpdy(in.world_pos), dpdy(in.world_normal), vec2<f32>(0.0),
        dpdy(in.curve), 0u);
    var light: vec3<f32>;
    if BALL && ROOM && two_surface_model && !to_background {
        light = ball_parts(in, dx, dy, phong, alpha);
    } else {
        // One loop over both grids, the finer one's positions added once the first is done
        // (one `shade_ray` in the pipeline: lavapipe compiles each copy of it for minutes).
        let finer = 2u * n;
        var positions = grid;
        var sum = vec3<f32>(0.0);
        var squares = 0.0;
        for (var i = 0u; i < positions; i++) {
            var offset = grid_position(i, n);
            // Each condition its own `if` (a pipeline constant rules the rest out).
            if !BALL {
                if two_surface_model {
                    // Counted as they run (lavapipe's loop limit, `mesh_hit`).
                    positions_shaded += 1u;
                    if i >= grid {
                        offset = grid_position(i - grid, finer);
                    }
                }
            }
            let at = moved(in, dx, dy, offset);
            if !misses_ball(at) {
                let light = shade_ray(at, two_surface_model, to_background, phong, alpha);
                sum += light;
                if !BALL {
                    if two_surface_model {
                        let y = dot(light, LUMINANCE);
                        squares += y * y;
                    }
                }
            } else if BALL {
                missed_positions += 1u;
            }
            if !BALL {
                if two_surface_model {
                    // Through a mesh or a gem: where the grid's positions disagree, a finer
                    // grid too (`needs_finer`).
                    if i + 1u == grid && finer <= MAX_FINER_SIDE
                        && needs_finer(sum, squares, grid) {
                        positions += finer * finer;
                    }
                }
            }
        }
        light = sum / f32(positions);
        if BALL {
            // As `ball_parts`: beside the ball (drawn on its proxy) nothing; the share of the
            // positions that meet it the share of the pixel it covers.
            if missed_positions == grid {
                discard;
            }
            covered_share = f32(grid - missed_positions) / f32(grid);
        }
    }
    return light;
}

// Rec. 709 luminance of linear RGB.
const LUMINANCE: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Through a mesh or a gem, the light inside a pixel can change over less than a position's
// spacing (an edge of a wall or a facet seen through several surfaces, light guided round a
// ring, a thin stem's image): a pixel whose grid of positions leaves its mean this uncertain (the standard error of its luminance, linear)
// shades a grid twice as fine too, and takes the mean over both. The torus's disc gap at
// 640 x 480 (4 x 4 positions): 0.368 with none, 0.330 at this error (its pixels 2.5 times the
// positions), 0.306 at 0.01 (4.2 times), 0.340 at 0.06, 0.310 with every pixel at 8 x 8.
const FINER_ERROR: f32 = 0.03;

// Positions along each side of the finer grid at most (lavapipe's loop limit, `mesh_hit`).
const MAX_FINER_SIDE: u32 = 8u;

// Whether a pixel's grid of `grid` positions, their light's sum `sum` and the sum of its
// luminance squared `squares`, leaves its mean's luminance more uncertain than FINER_ERROR.
fn needs_finer(sum: vec3<f32>, squares: f32, grid: u32) -> bool {
    let count = f32(grid);
    let mean = dot(sum, LUMINANCE) / count;
    let variance = max(squares / count - mean * mean, 0.0);
    return variance > FINER_ERROR * FINER_ERROR * count;
}

// A ball's light over the pixel at `in` in the room (`supersampled`), its screen derivatives
// `dx` and `dy`: the first image over the whole grid, the rest over its own.
fn ball_parts(in: VertexOut, dx: VertexOut, dy: VertexOut, phong: bool, alpha: f32) -> vec3<f32> {
    let n = in.samples;
    let grid = n * n;
    // w: the positions whose rays meet the ball.
    var first = vec4<f32>(0.0);
    for (var i = 0u; i < grid; i++) {
        first += first_image(moved(in, dx, dy, grid_position(i, n)));
    }
    let side = select(REST_SIDE, n, rest_over_whole_grid(in, phong));
    let rests = side * side;
    var rest = vec3<f32>(0.0);
    for (var i = 0u; i < rests; i++) {
        rest += rest_of_light(moved(in, dx, dy, grid_position(i, side)), phong, alpha);
    }
    if COUNTED {
        // Positions of the rest, of the first image, and the pixels.
        let slot = 4u * u32(eye.refraction_origin.w);
        atomicAdd(&shaded[slot], rests);
        atomicAdd(&shaded[slot + 1u], grid);
        atomicAdd(&shaded[slot + 2u], 1u);
    }
    // Drawn on its proxy (render/src/glass/proxy.rs), a pixel none of whose positions meets the
    // ball is beside it: the glass draws nothing there. Elsewhere the share of its positions
    // that meet the ball is the share of the pixel it covers (`covered_share`, the alpha a
    // segmented dimmer's want and light read: dimmer_panel.wgsl).
    if first.w == 0.0 {
        discard;
    }
    covered_share = first.w / f32(grid);
    return (1.0 - alpha) * first.rgb / f32(grid) + rest / f32(rests);
}

// The eye's ray through `in.world_pos` passes beside the sphere `front_surface` would put it
// on (a ball's vertices, `in.curve.y` 1).
fn misses_ball(in: VertexOut) -> bool {
    let from_centre = eye.position.xyz - g.center_world.xyz;
    let d = normalize(in.world_pos - eye.position.xyz);
    let b = dot(from_centre, d);
    let c = dot(from_centre, from_centre) - in.curve.x * in.curve.x;
    return in.curve.y > 0.5 && b * b - c < 0.0;
}
