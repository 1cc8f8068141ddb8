//! The segmented dimmer (`[display] model = "dimmer"`, glass-sphere-ml2.toml) on the machine's
//! Vulkan device with validation on, seen through the wearer's model of the panel
//! (`WearerView`, the CPU twin of the GPU's panel sums): the real shadow is darkened to the
//! share of the floor's light the lamp gives (which an additive display cannot do), the soft
//! panel's halo around it is given back as light so that the floor there looks as it is, and
//! far from the object nothing is dimmed or drawn.

use glam::{Vec2, Vec3};
use vitreous_frames::wearer::WearerView;
use vitreous_render::renderer::Want;
use vitreous_render::{Composition, FrameParams, Reflection, Renderer};
use vitreous_scene::effects::EffectSet;
use vitreous_tests::{compose_once, neutral_eyes, shipped_scene, validated_context};

const SIZE: (u32, u32) = (320, 240);

/// One frame of the left eye: what the eye sees, the real world alone and the display's light
/// (linear RGB), and the submitted alpha.
struct Left {
    seen: Vec<Vec3>,
    world: Vec<Vec3>,
    light: Vec<Vec3>,
    alpha: Vec<u8>,
}

/// The left eye's frame of `scene` composed as `composition`.
fn left(scene: &vitreous_scene::Scene, composition: Composition) -> Left {
    let desc = vitreous_frames::render_desc::scene_desc(scene, None);
    let mut r = Renderer::new(validated_context(), &desc, SIZE.0, SIZE.1).expect("renderer");
    let left = neutral_eyes(scene)[0];
    let params = FrameParams {
        eyes: [left, left],
        look: vitreous_frames::look::base_look(&EffectSet::NONE, Reflection::EnvironmentFresnel),
    };
    let want = Want {
        eyes: true,
        world: true,
    };
    let readback = compose_once(&mut r, &params, want, composition)
        .readback
        .expect("read back");
    let world = &readback.world.as_ref().unwrap()[0];
    let view = match composition {
        Composition::AlphaBlend => WearerView::of_scene(scene),
        _ => WearerView::additive(),
    };
    let seen = view.see(&readback.eyes[0], world, [SIZE.0, SIZE.1]);
    let linear = |rgba: &[u8]| -> Vec<Vec3> {
        rgba.chunks_exact(4)
            .map(|p| Vec3::from_array([0, 1, 2].map(|c| vitreous_optics::srgb::to_linear(p[c]))))
            .collect()
    };
    Left {
        seen: linear(&seen),
        world: linear(world),
        light: linear(&readback.eyes[0]),
        alpha: readback.eyes[0].chunks_exact(4).map(|p| p[3]).collect(),
    }
}

/// Whether the left eye's pixel `(x, y)` sees the floor in the object's shadow (`Some(true)`),
/// the lit floor (`Some(false)`), or something else: the ball itself or no floor.
fn shadowed(scene: &vitreous_scene::Scene, x: u32, y: u32) -> Option<bool> {
    let eye = neutral_eyes(scene)[0];
    let (c, r) = (scene.object.center_m, scene.object.radius_m);
    let dir = eye.pixel_ray(
        Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
        Vec2::new(SIZE.0 as f32, SIZE.1 as f32),
    );
    let meets_ball = |o: Vec3, d: Vec3| {
        let b = (o - c).dot(d);
        let disc = b * b - ((o - c).length_squared() - r * r);
        disc > 0.0 && -b + disc.sqrt() > 0.0
    };
    if meets_ball(eye.position_m, dir) || dir.y >= 0.0 {
        return None;
    }
    let floor_y = scene.floor.pose.position.y;
    let p = eye.position_m + dir * ((floor_y - eye.position_m.y) / dir.y);
    if (p.z - scene.floor.pose.position.z).abs() > 0.5 || p.x.abs() > 0.5 {
        return None;
    }
    let light = scene.light.position_m;
    Some(meets_ball(p, (light - p).normalize()))
}

#[test]
fn the_dimmer_darkens_the_real_shadow_and_gives_back_its_halo() {
    let scene = shipped_scene("glass-sphere-ml2.toml");
    assert!(scene.dimmer.is_some());
    let share = scene.light.share;
    let Left {
        seen,
        world,
        light,
        alpha,
    } = left(&scene, Composition::AlphaBlend);
    let mut additive_scene = scene.clone();
    additive_scene.dimmer = None;
    let additive = left(&additive_scene, Composition::Additive);
    assert!(
        additive.alpha.iter().all(|&a| a == 255),
        "additive alpha is 1"
    );

    // Each pixel's class, then the shadow's inner pixels (whose neighbours are all shadow)
    // and the lit floor at least 4 pixels from any shadow or ball pixel.
    let class: Vec<Option<bool>> = (0..SIZE.0 * SIZE.1)
        .map(|i| shadowed(&scene, i % SIZE.0, i / SIZE.0))
        .collect();
    let around = |i: usize, r: i32, want: &dyn Fn(Option<bool>) -> bool| {
        let (x, y) = ((i as u32 % SIZE.0) as i32, (i as u32 / SIZE.0) as i32);
        (-r..=r).all(|dy| {
            (-r..=r).all(|dx| {
                let (u, v) = (x + dx, y + dy);
                u >= 0
                    && v >= 0
                    && u < SIZE.0 as i32
                    && v < SIZE.1 as i32
                    && want(class[(v as u32 * SIZE.0 + u as u32) as usize])
            })
        })
    };
    let ratio = |pixels: &[usize], image: &[Vec3]| {
        let (s, w) = pixels.iter().fold((0.0, 0.0), |(s, w), &i| {
            (s + image[i].element_sum(), w + world[i].element_sum())
        });
        s / w
    };
    let inner: Vec<usize> = (0..class.len())
        .filter(|&i| around(i, 1, &|c| c == Some(true)))
        .collect();
    assert!(inner.len() > 20, "{} shadow pixels", inner.len());
    // In the shadow the eye sees the floor's light without the lamp's share.
    let dimmed = ratio(&inner, &seen);
    assert!(
        (dimmed - (1.0 - share)).abs() < 0.06,
        "shadow keeps {dimmed}"
    );
    // An additive display leaves the real floor as it is there.
    let kept = ratio(&inner, &additive.seen);
    assert!((kept - 1.0).abs() < 0.01, "additive shadow keeps {kept}");

    // The halo: lit floor under dimmed cells, away from the shadow and the ball. The panel
    // takes light away there, and the display gives it back: the floor looks as it is.
    let halo: Vec<usize> = (0..class.len())
        .filter(|&i| alpha[i] > 64 && around(i, 4, &|c| c == Some(false)))
        .collect();
    assert!(halo.len() > 200, "{} halo pixels", halo.len());
    let given_back = ratio(&halo, &seen);
    assert!((given_back - 1.0).abs() < 0.02, "halo at {given_back}");
    // Just outside the dimmed cells the soft panel still takes light away (its blur): the
    // light given back there follows the blur as the wearer's model of the panel has it.
    let near_dimmed = |i: usize| {
        let (x, y) = ((i as u32 % SIZE.0) as i32, (i as u32 / SIZE.0) as i32);
        (-6..=6).any(|dy: i32| {
            (-6..=6).any(|dx: i32| {
                let (u, v) = (x + dx, y + dy);
                u >= 0
                    && v >= 0
                    && u < SIZE.0 as i32
                    && v < SIZE.1 as i32
                    && alpha[(v as u32 * SIZE.0 + u as u32) as usize] > 128
            })
        })
    };
    let edge: Vec<usize> = (0..class.len())
        .filter(|&i| alpha[i] == 0 && class[i] == Some(false) && near_dimmed(i))
        .collect();
    assert!(edge.len() > 100, "{} pixels at the dimmed edge", edge.len());
    let at_edge = ratio(&edge, &seen);
    assert!((at_edge - 1.0).abs() < 0.03, "the dimmed edge at {at_edge}");
    // Without the light given back, the same pixels would be visibly darker.
    let dimmed_only: Vec<Vec3> = seen.iter().zip(&light).map(|(s, l)| *s - *l).collect();
    let unlit = ratio(&edge, &dimmed_only);
    assert!(
        unlit < 0.9,
        "the panel's blur takes only {} away there",
        1.0 - unlit
    );

    // Far from the object (the image's top-left corner) nothing is dimmed or added.
    for y in 0..20 {
        for x in 0..20 {
            let i = (y * SIZE.0 + x) as usize;
            assert_eq!(alpha[i], 0);
            assert!((seen[i] - world[i]).abs().max_element() < 1e-6);
        }
    }
}

/// The share of the left eye's pixel `(x, y)` the ball covers: of the glass's grid of positions
/// in it (`[output] glass_samples` along each side, as shaders/shared/glass_positions.wgsl
/// places them), those whose rays meet the ball's sphere.
fn covered(scene: &vitreous_scene::Scene, x: u32, y: u32) -> f32 {
    let eye = neutral_eyes(scene)[0];
    let (c, r) = (scene.object.center_m, scene.object.radius_m);
    let n = scene.output.glass_samples;
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let meeting = (0..n * n)
        .filter(|i| {
            let offset = (Vec2::new((i % n) as f32, (i / n) as f32) + 0.5) / n as f32;
            let dir = eye.pixel_ray(Vec2::new(x as f32, y as f32) + offset, size);
            let to = c - eye.position_m;
            (to - dir * to.dot(dir)).length() < r
        })
        .count();
    meeting as f32 / (n * n) as f32
}

#[test]
fn at_the_balls_outline_the_eye_sees_the_real_world_through_the_share_the_glass_leaves() {
    // A pixel the ball covers in part: the glass's light there is the covered share's (its
    // positions beside the ball add nothing), and the rest of the pixel is the real world's.
    let scene = shipped_scene("glass-sphere-ml2.toml");
    assert!(scene.output.glass_samples > 1);
    let dimmed = left(&scene, Composition::AlphaBlend);
    // The glass's own light: the same scene on an additive display, nothing taken away.
    let mut additive_scene = scene.clone();
    additive_scene.dimmer = None;
    additive_scene.compensation = vitreous_optics::display::Compensation::None;
    let glass = left(&additive_scene, Composition::Additive);
    // The outline's upper half (the wall and table behind it, no shadow), a quarter to three
    // quarters covered.
    let eye = neutral_eyes(&scene)[0];
    let size = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let centre = eye.project_to_pixel(scene.object.center_m, size).unwrap();
    let outline: Vec<(usize, f32)> = (0..SIZE.0 * SIZE.1)
        .filter(|&i| ((i / SIZE.0) as f32) < centre.y - 2.0)
        .map(|i| (i as usize, covered(&scene, i % SIZE.0, i / SIZE.0)))
        .filter(|&(_, k)| (0.25..=0.75).contains(&k))
        .collect();
    assert!(outline.len() > 15, "{} outline pixels", outline.len());
    // What the eye sees there: the glass's light and the world through the share it leaves,
    // G + (1 - k) B. Taking the whole of such a pixel for the glass would leave G alone: off by
    // the whole of (1 - k) B.
    let (mut off, mut through) = (0.0, 0.0);
    for &(i, k) in &outline {
        let world = dimmed.world[i] * (1.0 - k);
        off += (dimmed.seen[i] - (glass.light[i] + world))
            .abs()
            .element_sum();
        through += world.element_sum();
    }
    eprintln!(
        "{} outline pixels: the world through them {through:.3}, the eye's view off by {off:.3}",
        outline.len()
    );
    assert!(
        off < 0.25 * through,
        "the eye's view at the outline is off by {off}, the world through it {through}"
    );
}
