//! Eq. 6 over the glass (`[display] compensation = "background"`) on the machine's Vulkan
//! device with validation on: each glass pixel of an eye image is what it would be without
//! compensation less what the eye already sees there (the real floor or background, as the
//! preview's world view draws it), clamped at 0, in linear light; every other pixel is
//! untouched; with the world drawn behind (an opaque display) nothing is taken away.

use vitreous_optics::display::Compensation;
use vitreous_render::renderer::Want;
use vitreous_render::{Composition, FrameParams, Reflection, Renderer};
use vitreous_scene::effects::EffectSet;
use vitreous_tests::{compose_once, neutral_eyes, shipped_scene, validated_context};

fn linear(v: u8) -> f32 {
    vitreous_optics::srgb::to_linear(v)
}

/// One 8-bit sRGB step at `v`, in linear light.
fn step(v: u8) -> f32 {
    let below = v.min(254);
    linear(below + 1) - linear(below)
}

/// A frame's glass fragments (where the device counts them) and the fetches of one fragment of
/// each of the glass's pipelines drawn: with the environment's lookup, and without it.
type GlassWork = Option<(u64, [Option<u32>; 2])>;

fn frame(
    scene: &vitreous_scene::Scene,
    compensation: Compensation,
    composition: Composition,
) -> (vitreous_render::Readback, GlassWork) {
    let mut scene = scene.clone();
    scene.compensation = compensation;
    let desc = vitreous_frames::render_desc::scene_desc(&scene, None);
    let mut r = Renderer::new(validated_context(), &desc, 320, 240).expect("renderer");
    let counted = r.count_invocations().unwrap();
    let params = FrameParams {
        eyes: neutral_eyes(&scene),
        look: vitreous_frames::look::base_look(
            &EffectSet::parse("disparity").unwrap(),
            Reflection::EnvironmentFresnel,
        ),
    };
    let want = Want {
        eyes: true,
        world: true,
    };
    let last = compose_once(&mut r, &params, want, composition);
    // The glass's fragments (both of its pipelines: with the environment's lookup, and
    // without it where the frame proved it needless) and the fetches of one of each.
    let fetches = [last.work.glass_shader, last.work.glass_covered_shader]
        .map(|cost| cost.map(|c| c.fetches));
    assert!(fetches[0].is_some(), "the glass was drawn");
    let fragments = last
        .work
        .invocations
        .filter(|_| counted)
        .map(|i| (i.eye_glass.fragment + i.eye_glass_covered.fragment, fetches));
    (last.readback.expect("the frame was read back"), fragments)
}

#[test]
fn glass_pixels_lose_what_the_eye_already_sees_and_nothing_else_changes() {
    let scene = shipped_scene("glass-sphere.toml");
    let (plain, plain_fragments) = frame(&scene, Compensation::None, Composition::Additive);
    let (compensated, compensated_fragments) =
        frame(&scene, Compensation::Background, Composition::Additive);
    let world = plain.world.as_ref().expect("the world views");
    let (mut glass_px, mut darker_px, mut worst) = (0, 0, 0.0f32);
    for (eye, ((t, c), b)) in plain
        .eyes
        .iter()
        .zip(&compensated.eyes)
        .zip(world)
        .enumerate()
    {
        for (i, ((tp, cp), bp)) in t
            .chunks_exact(4)
            .zip(c.chunks_exact(4))
            .zip(b.chunks_exact(4))
            .enumerate()
        {
            let lit = tp[..3].iter().any(|&v| v != 0);
            if !lit {
                assert_eq!(cp, tp, "eye {eye} pixel {i}: drawn where nothing was");
                continue;
            }
            glass_px += 1;
            for ch in 0..3 {
                let expected = (linear(tp[ch]) - linear(bp[ch])).max(0.0);
                let got = linear(cp[ch]);
                // Each of T, B and the result is stored in 8 bits: within one step of each,
                // in linear light, at its own value.
                let tolerance = step(tp[ch]) + step(bp[ch]) + step(cp[ch]);
                // Where T is saturated, the glass's light was 1 or more: the difference is
                // taken before it is stored, so the result is at least 1 - B.
                let err = if tp[ch] == 255 {
                    (expected - got).max(0.0)
                } else {
                    (got - expected).abs()
                };
                worst = worst.max(err / tolerance);
                assert!(
                    err <= tolerance,
                    "eye {eye} pixel {i} channel {ch}: {got} vs max({} - {}, 0) = {expected}",
                    linear(tp[ch]),
                    linear(bp[ch])
                );
            }
            if cp[..3] != tp[..3] {
                darker_px += 1;
            }
        }
    }
    eprintln!("{glass_px} glass pixels, {darker_px} darker, worst {worst:.2} of the tolerance");
    assert!(glass_px > 500, "{glass_px}");
    assert!(darker_px > glass_px / 2, "{darker_px} of {glass_px}");
    // Counted work (where the device counts invocations): the glass's own fragment shader
    // takes B away, so the frame runs it as often as without, each time one fetch more.
    if let (Some((plain, plain_fetches)), Some((compensated, compensated_fetches))) =
        (plain_fragments, compensated_fragments)
    {
        eprintln!(
            "glass fragments: {plain} without, {compensated} with; fetches per fragment \
             {plain_fetches:?} without, {compensated_fetches:?} with"
        );
        assert_eq!(plain, compensated, "fragments");
        assert_eq!(
            compensated_fetches,
            plain_fetches.map(|f| f.map(|f| f + 1)),
            "fetches per fragment"
        );
    }
}

#[test]
fn an_opaque_display_shows_the_world_itself_and_loses_nothing() {
    let scene = shipped_scene("glass-sphere.toml");
    let (plain, _) = frame(&scene, Compensation::None, Composition::Opaque);
    let (compensated, _) = frame(&scene, Compensation::Background, Composition::Opaque);
    assert_eq!(plain.eyes, compensated.eyes);
    // The scene itself: nothing but the glass pass draws where the disc is, so the
    // compensation's absence is not an empty frame.
    assert!(plain.eyes[0].chunks_exact(4).any(|p| p[..3] != [0, 0, 0]));
}
