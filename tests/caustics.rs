//! The corrected caustics overlay (METHOD.md section 2, eq. 6) on the machine's Vulkan device
//! with validation on: with a uniform floor photo and a known caustic gain map G, every floor
//! pixel of the eye image carries (k alpha(d) + G) L_r for the study's condition c (inducer +
//! caustics), G L_r for b (caustics only) and nothing for a; plus the shipped bakes' scene
//! check and the errors for missing and foreign bakes.

use glam::{Quat, Vec2, Vec3};
use vitreous_frames::render_desc;
use vitreous_optics::camera::EyeParams;
use vitreous_render::renderer::Want;
use vitreous_render::{FrameParams, Readback, Reflection, Renderer, ScenePose};
use vitreous_scene::caustics::{Bake, BakeError};
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{CausticsMode, Image, PixelData, Scene};
use vitreous_tests::{
    FloorPixel, eyes_looking_down, floor_pixels, floor_uv, render_once, shipped_scene,
};

/// Where the straight ray from the light through the object's centre meets the floor: the
/// middle of the shadow.
fn shadow_centre(scene: &Scene) -> Vec3 {
    let light = scene.light.position_m;
    let dir = scene.object.center_m - light;
    let floor_y = scene.floor.pose.position.y;
    light + dir * ((floor_y - light.y) / dir.y)
}

/// Two eyes 0.6 m above the shadow's middle looking straight down.
fn top_down_eyes(scene: &Scene) -> [EyeParams; 2] {
    let above = shadow_centre(scene) + Vec3::Y * 0.6;
    eyes_looking_down(above)
}

/// A caustic gain map at `n` x `n`: a Gaussian spot of peak `peak` and sigma 12 texels at
/// floor uv `centre`, 0 where it falls below 1 % of the peak (so the map has a small
/// non-zero extent).
fn spot_bake(n: u32, centre: Vec2, peak: f32, hash: &str) -> Bake {
    let sigma = 12.0f32;
    let gain = (0..n * n)
        .map(|i| {
            let p = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            let r2 = (p - centre * n as f32).length_squared();
            let g = peak * (-r2 / (2.0 * sigma * sigma)).exp();
            if g < 0.01 * peak { 0.0 } else { g }
        })
        .collect();
    Bake {
        width_px: n,
        height_px: n,
        gain,
        light: None,
        inputs_hash: Some(hash.to_owned()),
        params: "method=test".into(),
    }
}

fn render(renderer: &mut Renderer, eyes: [EyeParams; 2], effects: &str) -> Readback {
    let effects = EffectSet::parse(effects).unwrap();
    let params = FrameParams {
        eyes,
        look: vitreous_frames::look::base_look(&effects, Reflection::EnvironmentFresnel),
    };
    let want = Want {
        eyes: true,
        world: false,
    };
    render_once(renderer, &params, want)
}

#[test]
fn eye_image_adds_inducer_and_caustic_gain_times_a_uniform_floor() {
    adds_inducer_and_caustic_gain(false, 1.0, false);
}

/// `[light] share = 0.4`: the light gives 40 % of the floor's light, so only that share is
/// focused and G is added times 0.4; the inducer is unchanged.
#[test]
fn eye_image_adds_only_the_lights_share_of_the_caustic_gain() {
    adds_inducer_and_caustic_gain(false, 0.4, false);
}

/// The same share set on a renderer made with the scene's 1.0 (`Renderer::set_light_share`,
/// as the room's light estimate sets it in `vitreous run`): the same images.
#[test]
fn a_share_set_after_the_start_adds_that_share_of_the_caustic_gain() {
    adds_inducer_and_caustic_gain(false, 0.4, true);
}

/// As above on the overlay's other path, G filtered from four loads (devices that do not
/// filter R32_SFLOAT, which Vulkan leaves optional; lavapipe filters it).
#[test]
fn eye_image_adds_the_gains_with_g_from_four_loads() {
    adds_inducer_and_caustic_gain(true, 1.0, false);
}

/// Each pixel of the floor in conditions c, b and inducer against k alpha(d) + share G of the
/// CPU reference times a uniform grey photo; with `four_loads` the overlay is built as on a
/// device that does not filter R32_SFLOAT; with `set_later` the scene says 1.0 and the share
/// is set on the renderer once made.
fn adds_inducer_and_caustic_gain(four_loads: bool, share: f32, set_later: bool) {
    const GREY: u8 = 120;
    let mut s = shipped_scene("glass-sphere.toml");
    s.light.share = if set_later { 1.0 } else { share };
    s.floor.photo = Image::new(8, 8, PixelData::Srgb8([GREY, GREY, GREY, 255].repeat(64))).unwrap();
    let l_r = vitreous_optics::srgb::to_linear(GREY);
    // The spot straddles the shadow's edge towards the viewer (shadow, ramp and open floor).
    let centre = floor_uv(&s, shadow_centre(&s) + Vec3::new(0.02, 0.0, 0.06));
    let n = s.inducer.resolution_px;
    let bake = spot_bake(n, centre, 0.8, &s.caustic_inputs_hash());
    s.caustics.gain = Some(bake.clone());
    let (w, h) = (320u32, 240u32);
    let ctx = vitreous_tests::validated_context();
    if four_loads {
        ctx.pretend_r32_float_unfiltered();
    }
    let mut r = Renderer::new(ctx, &render_desc::scene_desc(&s, None), w, h).expect("renderer");
    if set_later {
        r.set_light_share(share);
    }
    let eyes = top_down_eyes(&s);
    let none = render(&mut r, eyes, "a");
    // c, then b, then c again: the combined gain is recomputed on every switch change.
    let frames = [
        ("c", render(&mut r, eyes, "c")),
        ("b", render(&mut r, eyes, "b")),
        ("inducer", render(&mut r, eyes, "inducer")),
        ("c", render(&mut r, eyes, "c")),
    ];
    let fields = r.inducer_fields().unwrap();
    for (name, frame) in &frames {
        let (inducer_on, caustics_on) = match *name {
            "c" => (true, true),
            "b" => (false, true),
            _ => (true, false),
        };
        let (mut worst, mut caustic_px, mut both_px, mut dark_px) = (0.0f32, 0, 0, 0);
        for FloorPixel {
            eye: e,
            x,
            y,
            offset: i,
            uv,
        } in floor_pixels(&s, &eyes, &none)
        {
            let k_alpha = if inducer_on {
                fields.gain_bilinear(uv)
            } else {
                0.0
            };
            let g = if caustics_on {
                share * bake.sample(uv.x, uv.y)
            } else {
                0.0
            };
            let expected = (k_alpha + g) * l_r;
            let got = vitreous_optics::srgb::to_linear(frame.eyes[e][i]);
            let err = (got - expected).abs() / l_r;
            assert!(
                err <= 0.02,
                "{name}: eye {e} pixel ({x}, {y}): {got} vs {expected} (k alpha {k_alpha}, G {g})"
            );
            worst = worst.max(err);
            if g > 0.05 {
                caustic_px += 1;
                if k_alpha > 0.05 {
                    both_px += 1;
                }
            }
            if k_alpha == 0.0 && g == 0.0 && bake.sample(uv.x, uv.y) == 0.0 {
                dark_px += 1;
            }
        }
        eprintln!(
            "{name}{}: {caustic_px} caustic pixels ({both_px} also in the ramp), {dark_px} \
             without overlay, worst error {worst:.4} of L_r",
            if four_loads {
                " (G from four loads)"
            } else {
                ""
            }
        );
        if caustics_on {
            assert!(caustic_px > 1000, "{name}: {caustic_px}");
        }
        if inducer_on && caustics_on {
            assert!(both_px > 100, "{name}: {both_px}");
        }
    }
    // Condition a adds nothing: the eye image is black wherever the glass is not.
    let lit = none.eyes[0]
        .chunks_exact(4)
        .filter(|p| p[..3].iter().any(|&c| c != 0))
        .count();
    assert!(lit < (w * h / 4) as usize, "{lit} lit pixels with a");
    let v = r.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
}

#[test]
fn the_frame_that_computes_a_live_map_shows_it_as_the_next_frame_does() {
    // On the frame that computes a live caustic map only the GPU knows where its light lies:
    // the overlay takes the map's bounds from the buffer the computation wrote. Its eye image
    // must be the next frame's, drawn over the bounds the host has read back by then; also
    // after the light moved.
    let mut s = shipped_scene("glass-sphere.toml");
    s.caustics.mode = CausticsMode::Live;
    s.load_caustics().unwrap_or_else(|e| panic!("{e}"));
    let (w, h) = (160u32, 120u32);
    let ctx = vitreous_tests::validated_context();
    let desc = render_desc::scene_desc(&s, None);
    let mut r = Renderer::new(ctx, &desc, w, h).expect("renderer");
    render_desc::enable_live_caustics(&mut r, &s, true).expect("live caustics");
    let eyes = top_down_eyes(&s);
    let lit = |frame: &Readback| {
        frame.eyes[0]
            .chunks_exact(4)
            .filter(|p| p[..3].iter().any(|&c| c != 0))
            .count()
    };
    let center = s.object.center_m;
    let turned = center + Quat::from_rotation_y(0.3) * (s.light.position_m - center);
    let mut pictures = Vec::new();
    for light in [s.light.position_m, turned] {
        r.set_pose(ScenePose {
            light_position_m: light,
            ..ScenePose::of(&desc)
        });
        let computing = render(&mut r, eyes, "b");
        let next = render(&mut r, eyes, "b");
        eprintln!(
            "light at {light}: {} lit pixels on the frame computing the map, {} on the next",
            lit(&computing),
            lit(&next)
        );
        assert!(lit(&computing) > 2000, "{} lit pixels", lit(&computing));
        assert!(computing.eyes == next.eyes, "the two frames differ");
        pictures.push(next);
    }
    assert!(
        pictures[0].eyes != pictures[1].eyes,
        "the caustics did not move"
    );
    let v = r.context().validation();
    assert_eq!(v.errors() + v.warnings(), 0, "{:#?}", v.messages());
}

#[test]
fn shipped_bakes_belong_to_their_scenes() {
    for name in ["glass-sphere.toml", "diamond.toml"] {
        let mut s = shipped_scene(name);
        s.load_caustics().unwrap_or_else(|e| panic!("{name}: {e}"));
        let bake = s.caustics.gain.as_ref().unwrap();
        let peak = bake.gain.iter().cloned().fold(0.0f32, f32::max);
        eprintln!(
            "{name}: {}x{} texels, peak G {peak}",
            bake.width_px, bake.height_px
        );
        assert!(peak > 0.5, "{name}: peak G {peak}");
    }
}

#[test]
fn missing_unnamed_and_foreign_bakes_are_named() {
    let mut s = shipped_scene("glass-sphere.toml");
    // The light a centimetre off where the shipped bake was made for.
    s.light.position_m.x += 0.01;
    let err = s.load_caustics().unwrap_err();
    assert!(matches!(err, BakeError::WrongScene { .. }), "{err}");
    assert!(err.to_string().contains("glass-sphere.exr"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    s.caustics.bake = Some(dir.path().join("nowhere.exr"));
    let err = s.load_caustics().unwrap_err();
    assert!(matches!(err, BakeError::Missing { .. }), "{err}");
    assert!(err.to_string().contains("nowhere.exr"), "{err}");

    let mut t = shipped_scene("torus.toml");
    let err = t.load_caustics().unwrap_err();
    assert!(matches!(err, BakeError::NotNamed { .. }), "{err}");
    assert!(err.to_string().contains("torus.toml"), "{err}");
}
