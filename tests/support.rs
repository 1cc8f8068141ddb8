//! Shared helpers for the end-to-end tests: small procedural scenes and image measurements.

use glam::{Mat4, Vec2, Vec3};

/// A UV sphere of unit radius: positions, normals, uvs, indices.
pub fn uv_sphere(segments: u32, rings: u32) -> MeshData {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            positions.push(Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            // Counter-clockwise seen from outside.
            indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    let normals = positions.clone();
    (positions, normals, uvs, indices)
}

/// Linear RGBA floats of a smooth, bright environment (for tests that need light everywhere).
pub fn flat_environment(width: u32, height: u32, value: f32) -> Vec<f32> {
    (0..width * height)
        .flat_map(|_| [value, value, value, 1.0])
        .collect()
}

/// A grey sRGB photo.
pub fn grey_photo(width: u32, height: u32, level: u8) -> Vec<u8> {
    (0..width * height)
        .flat_map(|_| [level, level, level, 255])
        .collect()
}

/// Centroid (x, y in pixels, pixel centres at half-integers) and count of the pixels of an
/// RGBA8 image whose brightest channel exceeds `threshold`.
pub fn lit_centroid(rgba: &[u8], width: u32, threshold: u8) -> Option<(Vec2, usize)> {
    let mut sum = glam::DVec2::ZERO;
    let mut count = 0usize;
    for (i, px) in rgba.chunks_exact(4).enumerate() {
        if px[0].max(px[1]).max(px[2]) > threshold {
            let x = (i as u32 % width) as f64 + 0.5;
            let y = (i as u32 / width) as f64 + 0.5;
            sum += glam::DVec2::new(x, y);
            count += 1;
        }
    }
    (count > 0).then(|| ((sum / count as f64).as_vec2(), count))
}

/// The workspace's root folder.
pub fn workspace() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The shipped scene `config/scenes/<name>`, loaded as `vitreous run` loads it (without its
/// bake).
pub fn shipped_scene(name: &str) -> vitreous_scene::Scene {
    let path = workspace().join("config/scenes").join(name);
    vitreous_scene::load_scene(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A renderer of `scene` with eye images of `width` x `height`, validation on.
pub fn scene_renderer(
    scene: &vitreous_scene::Scene,
    width: u32,
    height: u32,
) -> vitreous_render::Renderer {
    let desc = vitreous_frames::render_desc::scene_desc(scene, None);
    vitreous_render::Renderer::new(validated_context(), &desc, width, height).expect("renderer")
}

/// Fails unless validation has been silent for `renderer`'s device.
pub fn assert_silent(renderer: &vitreous_render::Renderer) {
    let v = renderer.context().validation();
    assert_eq!(
        v.errors() + v.warnings(),
        0,
        "validation messages: {:#?}",
        v.messages()
    );
}

/// Two eyes 63 mm apart around `above`, looking straight down (0.8 x 0.6 rad field of view).
pub fn eyes_looking_down(above: Vec3) -> [vitreous_optics::camera::EyeParams; 2] {
    let fov = vitreous_optics::camera::Fov {
        left_rad: -0.4,
        right_rad: 0.4,
        up_rad: 0.3,
        down_rad: -0.3,
    };
    let down = glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    [-0.0315f32, 0.0315]
        .map(|x| vitreous_optics::camera::EyeParams::new(above + Vec3::X * x, down, fov))
}

/// The machine's Vulkan device with validation on (every test checks its messages).
pub fn validated_context() -> vitreous_render::GpuContext {
    vitreous_render::GpuContext::headless(&vitreous_render::ContextOptions {
        validation: true,
        device_name: None,
    })
    .expect("Vulkan device with validation")
}

/// The scene's two eyes at its neutral head (the viewer at `head_position_m`, looking down -z).
pub fn neutral_eyes(scene: &vitreous_scene::Scene) -> [vitreous_optics::camera::EyeParams; 2] {
    let head = vitreous_trace::Pose {
        position: scene.viewer.head_position_m,
        orientation: glam::Quat::IDENTITY,
    };
    let fov = vitreous_frames::render_desc::render_fov(scene.output.fov);
    scene
        .viewer
        .eye_positions_m(&head)
        .map(|p| vitreous_optics::camera::EyeParams::new(p, glam::Quat::IDENTITY, fov))
}

/// Positions, normals, uvs and indices of a mesh, as [`uv_sphere`] makes them.
pub type MeshData = (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<u32>);

/// The renderer's view of `mesh`.
pub fn mesh_ref(mesh: &MeshData) -> vitreous_render::MeshRef<'_> {
    let (positions, normals, uvs, indices) = mesh;
    vitreous_render::MeshRef {
        positions,
        normals,
        uvs,
        indices,
    }
}

/// An sRGB RGBA8 texture of `width` x `height` texels.
pub fn srgb(width: u32, height: u32, rgba: &[u8]) -> vitreous_render::TextureDesc<'_> {
    vitreous_render::TextureDesc {
        width,
        height,
        data: vitreous_render::TexelData::Srgb8(rgba),
    }
}

/// A linear RGBA32F texture of `width` x `height` texels.
pub fn linear(width: u32, height: u32, rgba: &[f32]) -> vitreous_render::TextureDesc<'_> {
    vitreous_render::TextureDesc {
        width,
        height,
        data: vitreous_render::TexelData::LinearF32(rgba),
    }
}

/// A scene of `mesh` placed by `world_from_model` under `environment`, over the `floor` and
/// `background` planes, with what the tests share: glass of index 1.5 refracted as the paper
/// does, without absorption; exposure 1; no surface image or blur stacks; a white light 1 m
/// above the origin; the paper's inducer; no caustics. Tests change the rest with
/// `SceneDesc { field, ..scene_desc(..) }`.
pub fn scene_desc<'a>(
    mesh: vitreous_render::MeshRef<'a>,
    world_from_model: Mat4,
    environment: vitreous_render::TextureDesc<'a>,
    floor: vitreous_render::PlaneDesc<'a>,
    background: vitreous_render::PlaneDesc<'a>,
) -> vitreous_render::SceneDesc<'a> {
    vitreous_render::SceneDesc {
        mesh,
        world_from_model,
        ior: 1.5,
        refraction: vitreous_optics::refraction::Refraction::Paper,
        attenuation: vitreous_optics::absorption::Attenuation::NONE,
        environment,
        floor,
        background,
        exposure: 1.0,
        surface: None,
        surface_transmittance: 1.0,
        light: vitreous_render::LightDesc {
            position_m: Vec3::new(0.0, 1.0, 0.0),
            radiance: Vec3::ONE,
            share: 1.0,
        },
        background_stack: None,
        surface_stack: None,
        inducer: vitreous_render::InducerDesc::PAPER,
        caustics: None,
        compensation: vitreous_optics::display::Compensation::None,
        room: false,
        glass_samples: 1,
        dimmer: None,
    }
}

/// A model matrix placing a unit-radius mesh as a sphere of `radius_m` at `center_m`.
pub fn place(center_m: Vec3, radius_m: f32) -> Mat4 {
    Mat4::from_scale_rotation_translation(Vec3::splat(radius_m), glam::Quat::IDENTITY, center_m)
}

/// The photo coordinate of a world point on the scene's floor (u right, v down).
pub fn floor_uv(scene: &vitreous_scene::Scene, world: Vec3) -> Vec2 {
    let local = scene
        .floor
        .world_from_plane()
        .inverse()
        .transform_point3(world);
    Vec2::new(local.x + 0.5, 0.5 - local.y)
}

/// A pixel of an eye image that shows the floor ([`floor_pixels`]).
#[derive(Clone, Copy, Debug)]
pub struct FloorPixel {
    /// The eye (0 left, 1 right).
    pub eye: usize,
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// Offset of its RGBA bytes in the eye image.
    pub offset: usize,
    /// The floor photo coordinate it shows.
    pub uv: Vec2,
}

/// The pixels of both eyes' images where the floor shows: those that `bare`, a frame drawn
/// without any floor overlay from the same eyes, leaves black (elsewhere the glass covers
/// the floor).
pub fn floor_pixels(
    scene: &vitreous_scene::Scene,
    eyes: &[vitreous_optics::camera::EyeParams; 2],
    bare: &vitreous_render::Readback,
) -> Vec<FloorPixel> {
    let (w, h) = (bare.width, bare.height);
    let floor_y = scene.floor.pose.position.y;
    let mut pixels = Vec::new();
    for (eye, params) in eyes.iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let offset = ((y * w + x) * 4) as usize;
                if bare.eyes[eye][offset..offset + 3].iter().all(|&c| c == 0) {
                    let uv = floor_uv(scene, pixel_on_floor(params, (w, h), x, y, floor_y));
                    pixels.push(FloorPixel {
                        eye,
                        x,
                        y,
                        offset,
                        uv,
                    });
                }
            }
        }
    }
    pixels
}

/// Where the centre of pixel (x, y) of an image of `size` pixels sees the horizontal floor
/// plane at height `floor_y`.
pub fn pixel_on_floor(
    eye: &vitreous_optics::camera::EyeParams,
    size: (u32, u32),
    x: u32,
    y: u32,
    floor_y: f32,
) -> Vec3 {
    let dir = eye.pixel_ray(
        Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
        Vec2::new(size.0 as f32, size.1 as f32),
    );
    eye.position_m + dir * ((floor_y - eye.position_m.y) / dir.y)
}

/// Renders one frame, waits for it, and returns its pixels.
pub fn render_once(
    renderer: &mut vitreous_render::Renderer,
    params: &vitreous_render::FrameParams,
    want: vitreous_render::Want,
) -> vitreous_render::Readback {
    let mut done: Vec<_> = renderer.submit(params, want).unwrap().into_iter().collect();
    done.extend(renderer.flush().unwrap());
    done.pop()
        .and_then(|frame| frame.readback)
        .expect("the frame was read back")
}

/// Draws one frame composed for `composition`, waits for it and returns what it finished with,
/// failing on any validation message.
pub fn compose_once(
    renderer: &mut vitreous_render::Renderer,
    params: &vitreous_render::FrameParams,
    want: vitreous_render::Want,
    composition: vitreous_render::Composition,
) -> vitreous_render::FrameResult {
    let mut done: Vec<_> = renderer
        .submit_composed(params, want, composition)
        .unwrap()
        .into_iter()
        .collect();
    done.extend(renderer.flush().unwrap());
    let v = renderer.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
    done.pop().expect("the frame finished")
}

/// The left eye's display light (linear RGB, row by row) for `scene` at `size` pixels: both eyes
/// at the neutral head's left eye, no effects, environment reflection with Fresnel, composed for
/// an additive display (the scene's `[display] compensation` applies), validation on.
pub fn left_eye_light(scene: &vitreous_scene::Scene, size: (u32, u32)) -> Vec<Vec3> {
    linear_rgb(&left_eye_frame(scene, size, false).eyes[0])
}

/// The left eye's world view (the real floor and background as the see-through preview shows
/// them; linear RGB, row by row) for `scene` at `size` pixels, as [`left_eye_light`] renders.
pub fn left_world_view(scene: &vitreous_scene::Scene, size: (u32, u32)) -> Vec<Vec3> {
    let frame = left_eye_frame(scene, size, true);
    linear_rgb(&frame.world.expect("the world views")[0])
}

/// A frame's parameters with both eyes at `eye`, no effects, environment reflection with
/// Fresnel.
pub fn plain_params(eye: vitreous_optics::camera::EyeParams) -> vitreous_render::FrameParams {
    vitreous_render::FrameParams {
        eyes: [eye, eye],
        look: vitreous_frames::look::base_look(
            &vitreous_scene::effects::EffectSet::parse("none").unwrap(),
            vitreous_render::Reflection::EnvironmentFresnel,
        ),
    }
}

fn left_eye_frame(
    scene: &vitreous_scene::Scene,
    size: (u32, u32),
    world: bool,
) -> vitreous_render::Readback {
    use vitreous_render::{Composition, Renderer, Want};
    let desc = vitreous_frames::render_desc::scene_desc(scene, None);
    let mut r = Renderer::new(validated_context(), &desc, size.0, size.1).expect("renderer");
    let params = plain_params(neutral_eyes(scene)[0]);
    let want = Want { eyes: true, world };
    compose_once(&mut r, &params, want, Composition::Additive)
        .readback
        .expect("read back")
}

/// sRGB RGBA8 pixels in linear RGB.
fn linear_rgb(pixels: &[u8]) -> Vec<Vec3> {
    pixels
        .chunks_exact(4)
        .map(|p| {
            Vec3::new(
                vitreous_optics::srgb::to_linear(p[0]),
                vitreous_optics::srgb::to_linear(p[1]),
                vitreous_optics::srgb::to_linear(p[2]),
            )
        })
        .collect()
}

/// `glass-sphere-real.toml` with the torus (100 mm, lying flat on the table) for its object and
/// no bake, written into `dir` (its assets named by absolute paths).
pub fn torus_in_the_room(dir: &std::path::Path) -> vitreous_scene::Scene {
    let config = workspace().join("config");
    let text = std::fs::read_to_string(config.join("scenes/glass-sphere-real.toml"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", config.display()))
        .replace("sphere.glb", "torus.glb")
        .replace("diameter_m = 0.08", "diameter_m = 0.10")
        .replace(
            "position_m = [0.0, -0.26, -1.5]",
            "position_m = [0.0, -0.285, -1.5]",
        )
        .lines()
        .filter(|line| !line.starts_with("bake = "))
        .collect::<Vec<_>>()
        .join("\n");
    let path = dir.join("torus-real.toml");
    std::fs::write(&path, text).unwrap();
    vitreous_scene::load_scene(&path).unwrap()
}
