//! The debug output of `vitreous replay --sphere-check`: each saved eye image under the
//! paper's refraction and under two-surface refraction, beside the sphere check's two-surface
//! refraction layer (`vitreous_optics::sphere_check`, computed on the CPU), for scenes whose
//! object is a sphere (the check traces the analytic sphere of the object's bounding sphere),
//! tinted by the glass's absorption along each ray's path inside.

use glam::{Vec2, Vec3};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::sphere_check::{RefractionSample, SphereScene, refraction_sample};
use vitreous_trace::FrameInput;

use crate::render_desc::eye_params;
use vitreous_scene::{PixelData, Scene};

/// Grey level shown where the refracted ray misses the background photo (the renderer shows
/// the environment map there).
const MISS_GREY: u8 = 40;

/// The analytic sphere of a scene: its object's bounding sphere.
pub fn sphere_of(scene: &Scene) -> SphereScene {
    SphereScene {
        center_m: scene.object.center_m,
        radius_m: scene.object.radius_m,
        ior: scene.object.ior,
        refraction: scene.object.refraction,
        attenuation: scene.object.attenuation,
        background_from_world: scene.background.world_from_plane().inverse(),
    }
}

/// An RGBA8 image as wide as `gpu.len() + 1` eye images: the GPU's eye images left to right
/// (paper, then two-surface refraction), then the sphere check of the refraction layer under
/// `refraction` (the background photo's texel at `(u_c, v_c)` times the absorption along the
/// path inside, black off the sphere, grey where the ray misses the photo).
pub fn side_by_side(
    scene: &Scene,
    input: &FrameInput,
    eye: usize,
    gpu: &[&[u8]],
    refraction: Refraction,
    size: (u32, u32),
) -> Vec<u8> {
    let (w, h) = size;
    let panels = gpu.len() as u32 + 1;
    let camera = eye_params(&input.views[eye]);
    let sphere = SphereScene {
        refraction,
        ..sphere_of(scene)
    };
    let dims = Vec2::new(w as f32, h as f32);
    let photo = &scene.background.photo;
    let mut out = vec![0u8; (w * panels * h * 4) as usize];
    let row_bytes = (w * 4) as usize;
    for y in 0..h {
        let row = (y * w * panels * 4) as usize;
        let src = (y * w * 4) as usize;
        for (k, image) in gpu.iter().enumerate() {
            let at = row + k * row_bytes;
            out[at..at + row_bytes].copy_from_slice(&image[src..src + row_bytes]);
        }
        let cpu_panel = gpu.len() as u32 * w;
        for x in 0..w {
            let pixel = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let rgba = match refraction_sample(&camera, pixel, dims, &sphere) {
                RefractionSample::Miss => [0, 0, 0, 255],
                RefractionSample::Hit { uv: None, .. } => [MISS_GREY, MISS_GREY, MISS_GREY, 255],
                RefractionSample::Hit {
                    uv: Some(uv),
                    absorption,
                    ..
                } => absorbed(
                    texel(&photo.data, photo.width, photo.height, uv),
                    absorption,
                ),
            };
            let i = row + ((cpu_panel + x) * 4) as usize;
            out[i..i + 4].copy_from_slice(&rgba);
        }
    }
    out
}

/// An sRGB texel seen through glass that leaves `absorption` of each linear channel (sRGB
/// bytes round-trip exactly, so clear glass leaves the texel as it is).
fn absorbed(rgba: [u8; 4], absorption: Vec3) -> [u8; 4] {
    let through = |byte: u8, t: f32| {
        vitreous_optics::srgb::from_linear(vitreous_optics::srgb::to_linear(byte) * t)
    };
    [
        through(rgba[0], absorption.x),
        through(rgba[1], absorption.y),
        through(rgba[2], absorption.z),
        rgba[3],
    ]
}

/// The nearest texel of an sRGB photo at texture coordinates `uv`.
fn texel(data: &PixelData, width: u32, height: u32, uv: Vec2) -> [u8; 4] {
    let x = ((uv.x * width as f32) as u32).min(width - 1);
    let y = ((uv.y * height as f32) as u32).min(height - 1);
    let i = ((y * width + x) * 4) as usize;
    match data {
        PixelData::Srgb8(bytes) => [bytes[i], bytes[i + 1], bytes[i + 2], 255],
        PixelData::LinearF32(_) => [255, 0, 255, 255],
    }
}
