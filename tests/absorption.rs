//! Absorption inside a tinted glass ball (Beer-Lambert, two-surface refraction) on the
//! machine's Vulkan device with validation on, against the CPU reference: the darkening of
//! each colour channel at the ball's centre and on a ring around it, where the path inside is
//! shorter. A channel that absorbs nothing, and the paper's model, render exactly as clear
//! glass.

use glam::{Mat4, Quat, Vec2, Vec3};
use vitreous_optics::absorption::Attenuation;
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::sphere_check::{RefractionSample, SphereScene, refraction_sample};
use vitreous_render::renderer::Want;
use vitreous_render::{FrameParams, LightDesc, Look, PlaneDesc, Reflection, Renderer, SceneDesc};
use vitreous_tests::{
    flat_environment, grey_photo, linear, mesh_ref, render_once, scene_desc, srgb, uv_sphere,
};

const W: u32 = 320;
const H: u32 = 240;
const CENTER: Vec3 = Vec3::new(0.0, 0.0, -0.2);
const RADIUS: f32 = 0.075;
const IOR: f32 = 1.51;
const IPD: f32 = 0.063;
/// Side of the (white) background plane, metres, 0.2 m behind the ball's centre.
const PLANE_M: f32 = 0.6;

/// Red turns into a quarter after 2 R (the path through the centre), blue into 0.6; green is
/// not absorbed at all.
const TINT: Attenuation = Attenuation {
    color: Vec3::new(0.25, 1.0, 0.6),
    distance_m: 2.0 * RADIUS,
};

/// Refraction to the background for each eye; the environment (black) reflects nothing.
const DISPARITY: Look = Look {
    disparity: true,
    defocus: None,
    reflection: Reflection::EnvironmentFresnel,
    inducer: false,
    caustics: false,
    blank: false,
};

fn eyes() -> [EyeParams; 2] {
    let fov = Fov {
        left_rad: -0.55,
        right_rad: 0.55,
        up_rad: 0.42,
        down_rad: -0.42,
    };
    [-IPD / 2.0, IPD / 2.0].map(|x| EyeParams::new(Vec3::new(x, 0.0, 0.0), Quat::IDENTITY, fov))
}

fn background_plane() -> Mat4 {
    Mat4::from_scale_rotation_translation(
        Vec3::new(PLANE_M, PLANE_M, 1.0),
        Quat::IDENTITY,
        Vec3::new(0.0, 0.0, -0.4),
    )
}

/// Both eye images (sRGB RGBA8) of a 128 x 64 sphere mesh of the ball under `refraction`
/// with `attenuation`, in front of a white photo.
fn render(refraction: Refraction, attenuation: Attenuation) -> [Vec<u8>; 2] {
    let ctx = vitreous_tests::validated_context();
    let sphere = uv_sphere(128, 64);
    let env = flat_environment(64, 32, 0.0);
    let white = grey_photo(64, 64, 255);
    let black = grey_photo(4, 4, 0);
    let scene = SceneDesc {
        ior: IOR,
        refraction,
        attenuation,
        light: LightDesc {
            position_m: Vec3::new(1.0, 1.0, 1.0),
            radiance: Vec3::ONE,
            share: 1.0,
        },
        ..scene_desc(
            mesh_ref(&sphere),
            vitreous_tests::place(CENTER, RADIUS),
            linear(64, 32, &env),
            PlaneDesc {
                world_from_plane: Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0)),
                photo: srgb(4, 4, &black),
            },
            PlaneDesc {
                world_from_plane: background_plane(),
                photo: srgb(64, 64, &white),
            },
        )
    };
    let mut renderer = Renderer::new(ctx, &scene, W, H).expect("renderer");
    let params = FrameParams {
        eyes: eyes(),
        look: DISPARITY,
    };
    let want = Want {
        eyes: true,
        world: false,
    };
    let readback = render_once(&mut renderer, &params, want);
    let v = renderer.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
    readback.eyes
}

/// Largest relative error of the linear light decoded from an sRGB byte `code` (above the
/// linear segment) that was rounded to the nearest byte: half a code over
/// d ln(linear) / d code = 2.4 / (code + 0.055 * 255).
fn half_code_relative(code: u8) -> f32 {
    1.2 / (f32::from(code) + 14.0)
}

/// The measured darkening (absorbed over clear, linear light, per channel) of the 3 x 3
/// pixels around `pixel`, the CPU reference's absorption there (their mean) and the
/// tolerance: both images' rounding to bytes at their darkest pixel, and 0.5 % of the
/// reference for the mesh's facets (its sag and normals change the path inside by about
/// 1e-3 of it, under 0.2 % of the transmittance at the ball's optical depths).
fn darkening(
    eye: &EyeParams,
    clear: &[u8],
    tinted: &[u8],
    pixel: (u32, u32),
    reference: &SphereScene,
) -> (Vec3, Vec3, Vec3) {
    let size = Vec2::new(W as f32, H as f32);
    let (mut sum_clear, mut sum_tinted, mut expected) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    let mut darkest = [u8::MAX; 2];
    for y in pixel.1 - 1..=pixel.1 + 1 {
        for x in pixel.0 - 1..=pixel.0 + 1 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let RefractionSample::Hit {
                uv: Some(_),
                absorption,
                ..
            } = refraction_sample(eye, p, size, reference)
            else {
                panic!("the reference's ray through pixel {p} misses the photo");
            };
            expected += absorption / 9.0;
            let i = ((y * W + x) * 4) as usize;
            let [c, t] = [&clear[i..i + 3], &tinted[i..i + 3]];
            assert!(c[0] > 150, "pixel {p} of the clear ball is dark: {c:?}");
            sum_clear += Vec3::new(
                vitreous_optics::srgb::to_linear(c[0]),
                vitreous_optics::srgb::to_linear(c[1]),
                vitreous_optics::srgb::to_linear(c[2]),
            );
            sum_tinted += Vec3::new(
                vitreous_optics::srgb::to_linear(t[0]),
                vitreous_optics::srgb::to_linear(t[1]),
                vitreous_optics::srgb::to_linear(t[2]),
            );
            darkest[0] = darkest[0].min(*c.iter().min().unwrap());
            darkest[1] = darkest[1].min(*t.iter().min().unwrap());
        }
    }
    let tolerance =
        expected * (half_code_relative(darkest[0]) + half_code_relative(darkest[1]) + 0.005);
    (sum_tinted / sum_clear, expected, tolerance)
}

#[test]
fn tinted_ball_darkens_each_channel_as_the_reference_path_inside_says() {
    let clear = render(Refraction::TwoSurface, Attenuation::NONE);
    let tinted = render(Refraction::TwoSurface, TINT);
    let reference = SphereScene {
        center_m: CENTER,
        radius_m: RADIUS,
        ior: IOR,
        refraction: Refraction::TwoSurface,
        attenuation: TINT,
        background_from_world: background_plane().inverse(),
    };
    let size = Vec2::new(W as f32, H as f32);
    for (e, eye) in eyes().iter().enumerate() {
        let centre = eye
            .project_to_pixel(CENTER, size)
            .expect("the ball is in view");
        // The ball's edge seen from the eye, to place the ring at 75 % of its radius.
        let edge_dir = Quat::from_rotation_y((RADIUS / CENTER.distance(eye.position_m)).asin())
            * (CENTER - eye.position_m).normalize();
        let edge = eye
            .project_to_pixel(eye.position_m + edge_dir, size)
            .expect("the edge is in view");
        let ring_px = 0.75 * (edge - centre).length();
        let mut centre_red = 0.0;
        for k in 0..9 {
            let at = if k == 0 {
                centre
            } else {
                let a = (k - 1) as f32 * std::f32::consts::FRAC_PI_4;
                centre + ring_px * Vec2::new(a.cos(), a.sin())
            };
            let pixel = (at.x as u32, at.y as u32);
            let (measured, expected, tolerance) =
                darkening(eye, &clear[e], &tinted[e], pixel, &reference);
            eprintln!(
                "eye {e} pixel {pixel:?}: measured {measured}, reference {expected} (± {tolerance})"
            );
            assert!(
                (measured - expected).abs().cmple(tolerance).all(),
                "eye {e} pixel {pixel:?}: darkening {measured}, reference {expected} \
                 (tolerance {tolerance})"
            );
            if k == 0 {
                // Straight through the centre: 2 R inside, the colour itself.
                assert!(expected.abs_diff_eq(TINT.color, 0.01), "{expected}");
                centre_red = measured.x;
            } else {
                // The shorter chord off the centre darkens visibly less than the centre.
                assert!(
                    measured.x > centre_red + 3.0 * tolerance.x,
                    "eye {e} ring pixel {pixel:?}: red {} vs centre {centre_red}",
                    measured.x
                );
            }
        }
        // Green absorbs nothing: exactly the clear ball's bytes.
        let green = |img: &[u8]| img.chunks_exact(4).map(|p| p[1]).collect::<Vec<u8>>();
        assert!(
            green(&clear[e]) == green(&tinted[e]),
            "eye {e}: an unabsorbed channel changed"
        );
    }
}

#[test]
fn the_papers_model_has_no_path_inside_and_ignores_the_tint() {
    let clear = render(Refraction::Paper, Attenuation::NONE);
    let tinted = render(Refraction::Paper, TINT);
    assert!(clear == tinted, "the tint changed the paper's image");
    assert!(
        clear[0].chunks_exact(4).any(|p| p[0] > 150),
        "the paper's ball shows the white photo"
    );
}
