//! The frame's proof that the background photo catches the glass's refracted rays, on the
//! machine's Vulkan device with validation on: where it holds, the glass is drawn without the
//! environment's lookup (render/src/coverage.rs, `COVERED` in shaders/glass.wgsl), and every
//! frame is the one drawn with the lookup everywhere: in the study scene, whose refracted rays
//! all reach its photo in the paper's model, through both surfaces of the ball, whose rim bends
//! them past it in the image's corners, and before a photo too small for the ball.

use vitreous_optics::absorption::Attenuation;
use vitreous_optics::refraction::Refraction;
use vitreous_render::renderer::Want;
use vitreous_render::{Composition, Defocus, FrameParams, Readback, Reflection, Renderer};
use vitreous_scene::effects::EffectSet;
use vitreous_tests::{compose_once, neutral_eyes, shipped_scene, validated_context};

/// One frame of `scene` with `effects`, with or without the proof: its eye images and the glass
/// fragments drawn with the environment's lookup and without it.
fn frame(scene: &vitreous_scene::Scene, effects: &str, proof: bool) -> (Readback, [u64; 2]) {
    let desc = vitreous_frames::render_desc::scene_desc(scene, None);
    let mut r = Renderer::new(validated_context(), &desc, 320, 240).expect("renderer");
    assert!(
        r.count_invocations().unwrap(),
        "lavapipe counts invocations"
    );
    r.set_coverage_proof(proof);
    let effects = EffectSet::parse(effects).unwrap();
    let mut look = vitreous_frames::look::base_look(&effects, Reflection::EnvironmentFresnel);
    // The frame's gaze would set the blur; a refracted image 4 px out of focus stands for it.
    look.defocus = effects.defocus.then_some(Defocus {
        refracted_k_g_px: 4.0,
        surface_k_g_px: 0.0,
    });
    let params = FrameParams {
        eyes: neutral_eyes(scene),
        look,
    };
    let want = Want {
        eyes: true,
        world: false,
    };
    let last = compose_once(&mut r, &params, want, Composition::Additive);
    let i = last.work.invocations.expect("invocations counted");
    let readback = last.readback.expect("the frame was read back");
    (
        readback,
        [i.eye_glass.fragment, i.eye_glass_covered.fragment],
    )
}

/// The largest difference of any channel of any pixel between the two frames' eye images.
fn largest_difference(a: &Readback, b: &Readback) -> u8 {
    a.eyes
        .iter()
        .zip(&b.eyes)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| p.abs_diff(*q)))
        .max()
        .unwrap_or(0)
}

/// The frame with the proof against the frame without it: the same image (within one 8-bit
/// step: the covered shader leaves out a normalisation and a branch, not the light), and the
/// glass fragments drawn each way.
fn compare(scene: &vitreous_scene::Scene, effects: &str) -> [u64; 2] {
    let (proved, split) = frame(scene, effects, true);
    let (plain, all_with_lookup) = frame(scene, effects, false);
    assert_eq!(
        all_with_lookup[1], 0,
        "without the proof, nothing is drawn without the lookup"
    );
    assert_eq!(
        split[0] + split[1],
        all_with_lookup[0],
        "every glass fragment is drawn once either way"
    );
    let worst = largest_difference(&proved, &plain);
    eprintln!("{effects}: {split:?} fragments with and without the lookup, worst {worst}");
    assert!(worst <= 1, "{effects}: the images differ by {worst} steps");
    split
}

#[test]
fn the_study_scene_draws_all_its_glass_without_the_environments_lookup() {
    let scene = shipped_scene("visual-effects.toml");
    for effects in ["disparity", "defocus", "disparity,defocus"] {
        let [with, without] = compare(&scene, effects);
        assert_eq!(with, 0, "{effects}");
        assert!(without > 10_000, "{effects}: {without}");
    }
    // The conventional method refracts the environment itself: no proof to draw.
    let (_, [with, without]) = frame(&scene, "none", true);
    assert!(with > 10_000 && without == 0, "{with} {without}");
}

#[test]
fn through_both_surfaces_the_rim_keeps_the_lookup_and_the_middle_leaves_it_out() {
    let mut scene = shipped_scene("visual-effects.toml");
    scene.object.refraction = Refraction::TwoSurface;
    let [with, without] = compare(&scene, "disparity,defocus");
    assert!(with > 0 && without > with, "{with} {without}");
    // Tinted glass: the covered passage absorbs along the same path inside.
    scene.object.attenuation = Attenuation {
        color: glam::Vec3::new(0.25, 1.0, 0.6),
        distance_m: 0.15,
    };
    let [with, without] = compare(&scene, "disparity");
    assert!(with > 0 && without > with, "{with} {without}");
}

#[test]
fn before_a_photo_too_small_for_the_ball_the_rays_beside_it_keep_the_lookup() {
    let mut scene = shipped_scene("visual-effects.toml");
    // A 10 cm photo: the ball's refracted rays reach it from the middle of its image only.
    scene.background.size_m = glam::Vec2::splat(0.1);
    let [with, without] = compare(&scene, "disparity");
    assert!(with > 0 && without > 0, "{with} {without}");
}
