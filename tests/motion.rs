//! A moving scene (`[motion]`) on the machine's Vulkan device with validation on: the glass
//! follows the object's pose from the frame it is set, the shadow inducer's fields follow the
//! light (the shadow's centroid against an exact CPU shadow of the sphere), and a replay of
//! the shipped moving-light scene computes the fields once per frame that moved and never on
//! frames that did not.

use glam::{DVec2, Quat, Vec2, Vec3};
use vitreous::replay::{ReplayOptions, replay};
use vitreous_frames::render_desc;
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_render::floor::InducerFields;
use vitreous_render::renderer::Want;
use vitreous_render::{FrameParams, Look, Renderer};
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{Placement, Scene, load_scene};
use vitreous_tests::{
    assert_silent, floor_uv, lit_centroid, render_once, scene_renderer, shipped_scene, workspace,
};

/// Where a floor texel centre lies in the world.
fn texel_world(scene: &Scene, n: u32, x: u32, y: u32) -> Vec3 {
    let uv = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
    scene
        .floor
        .world_from_plane()
        .transform_point3(Vec3::new(uv.x - 0.5, 0.5 - uv.y, 0.0))
}

/// Centroid (texels) and count of the texels `inside` says are in shadow.
fn centroid(n: u32, inside: impl Fn(u32, u32) -> bool) -> (DVec2, usize) {
    let mut sum = DVec2::ZERO;
    let mut count = 0;
    for y in 0..n {
        for x in 0..n {
            if inside(x, y) {
                sum += DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                count += 1;
            }
        }
    }
    (sum / count.max(1) as f64, count)
}

/// Whether the segment from a floor point to the light passes through the sphere.
fn shadowed(point: Vec3, light: Vec3, center: Vec3, radius: f32) -> bool {
    let d = light - point;
    let t = ((center - point).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (point + d * t).distance(center) < radius
}

#[test]
fn inducer_fields_follow_the_circling_light() {
    let mut scene = shipped_scene("moving-light.toml");
    scene.inducer.resolution_px = 256;
    let n = scene.inducer.resolution_px;
    let mut renderer = scene_renderer(&scene, 32, 32);
    let mut previous: Option<DVec2> = None;
    // Light beyond, to the left of, in front of and to the right of the sphere; then the
    // sphere itself moved 10 cm to the right under the last light.
    let mut placements: Vec<(f64, Placement)> = [0.0, 1.5, 3.0, 4.5]
        .into_iter()
        .map(|t| (t, scene.placement_at(t)))
        .collect();
    let mut moved = placements[3].1;
    moved.object_position_m.x += 0.1;
    placements.push((4.5, moved));
    for (time_s, placement) in placements {
        let center = placement.object_position_m;
        renderer.set_pose(render_desc::scene_pose(&scene, &placement));
        let fields: InducerFields = renderer.inducer_fields().expect("fields");
        let light = placement.light_position_m;
        let (gpu, gpu_count) = centroid(n, |x, y| fields.mask[fields.index(x, y)] == 1);
        let (cpu, cpu_count) = centroid(n, |x, y| {
            shadowed(
                texel_world(&scene, n, x, y),
                light,
                center,
                scene.object.radius_m,
            )
        });
        assert!(
            cpu_count > 100,
            "the exact shadow covers {cpu_count} texels"
        );
        let area = gpu_count as f64 / cpu_count as f64;
        eprintln!(
            "t = {time_s} s: shadow centroid off by {:.2} texels, area {gpu_count} / {cpu_count}",
            gpu.distance(cpu)
        );
        assert!(
            (0.93..=1.02).contains(&area),
            "at {time_s} s: {gpu_count} vs {cpu_count} texels"
        );
        assert!(
            gpu.distance(cpu) < 1.0,
            "at {time_s} s the shadow's centroid is at {gpu}, the exact one at {cpu}"
        );
        // The shadow lies on the far side of the sphere from the light: floor-space offset
        // of the centroid from the sphere's foot against the light's.
        let foot = floor_uv(&scene, center) * n as f32;
        let away = (gpu.as_vec2() - foot).normalize();
        let towards_light = (floor_uv(&scene, light) * n as f32 - foot).normalize();
        assert!(
            away.dot(towards_light) < -0.99,
            "at {time_s} s the shadow points {away}, the light {towards_light}"
        );
        if let Some(p) = previous {
            assert!(
                p.distance(gpu) > 5.0,
                "the shadow did not move at {time_s} s"
            );
        }
        previous = Some(gpu);
    }
    // One computation per pose.
    assert_eq!(renderer.inducer_computations(), 5);
    assert_silent(&renderer);
}

/// The fields and the eye images of `renderer` after moving the object to `position`: the
/// fields read back before or after drawing a frame of condition c (the inducer and the
/// baked caustics) seen from 1 m above the floor's centre.
fn fields_and_eyes(
    scene: &Scene,
    renderer: &mut Renderer,
    position: Vec3,
    read_first: bool,
) -> (InducerFields, Vec<u8>) {
    let placement = Placement {
        object_position_m: position,
        ..scene.rest_placement()
    };
    renderer.set_pose(render_desc::scene_pose(scene, &placement));
    let above = scene.floor.pose.position + Vec3::Y;
    let fov = Fov {
        left_rad: -0.55,
        right_rad: 0.55,
        up_rad: 0.55,
        down_rad: -0.55,
    };
    let down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let eye = EyeParams::new(above, down, fov);
    let params = FrameParams {
        eyes: [eye, eye],
        look: Look {
            inducer: true,
            caustics: true,
            ..Look::default()
        },
    };
    let want = Want {
        eyes: true,
        world: false,
    };
    let first = read_first.then(|| renderer.inducer_fields().expect("fields"));
    let frame = render_once(renderer, &params, want);
    let fields = first.unwrap_or_else(|| renderer.inducer_fields().expect("fields"));
    let [left, _] = frame.eyes;
    (fields, left)
}

#[test]
fn region_limited_fields_match_a_fresh_computation_as_the_object_crosses_the_floor() {
    let mut scene = shipped_scene("glass-sphere.toml");
    scene.inducer.resolution_px = 256;
    scene.load_caustics().expect("the sphere's bake");
    let (k, d_m) = (scene.inducer.k, scene.inducer.ramp_width_m);
    let (w, h) = (96, 96);
    let mut moving = scene_renderer(&scene, w, h);
    let y = scene.object.center_m.y;
    let z = scene.floor.pose.position.z;
    // From the rest pose across the floor, to its right edge with the shadow leaving it at
    // the front, to the back left corner and back (the floor is 1 m square).
    let positions = [
        scene.object.center_m,
        Vec3::new(0.25, y, z),
        Vec3::new(0.46, y, z + 0.42),
        Vec3::new(-0.46, y, z - 0.46),
        scene.object.center_m,
    ];
    for (i, position) in positions.into_iter().enumerate() {
        let read_first = i % 2 == 1;
        let (fields, eyes) = fields_and_eyes(&scene, &mut moving, position, read_first);
        let mut fresh = scene_renderer(&scene, w, h);
        let (full, full_eyes) = fields_and_eyes(&scene, &mut fresh, position, read_first);
        assert_silent(&fresh);
        let shadow = fields.mask.iter().filter(|&&m| m == 1).count();
        eprintln!("object at {position}: {shadow} shadow texels");
        assert!(shadow > 50, "at {position}: {shadow} shadow texels");
        assert!(fields.mask == full.mask, "at {position}: masks differ");
        assert!(
            fields.distance_m == full.distance_m,
            "at {position}: distances differ"
        );
        assert!(fields.gain == full.gain, "at {position}: gains differ");
        assert!(eyes == full_eyes, "at {position}: eye images differ");
        crate::inducer::check_distance_field(&fields, d_m);
        crate::inducer::check_gain_follows_distance(&fields, k, d_m);
    }
    assert_eq!(moving.inducer_computations(), positions.len() as u64);
    assert_silent(&moving);
}

/// Two frames in a row with the shadow off the floor: the second finds nothing drawn before
/// nor now, and still writes each of the frame's timestamps once (a second write to a query
/// not reset is a validation error).
#[test]
fn frames_with_the_shadow_off_the_floor_twice_write_each_stamp_once() {
    let scene = shipped_scene("glass-sphere.toml");
    let mut renderer = scene_renderer(&scene, 32, 32);
    let y = scene.object.center_m.y;
    for x in [5.0, 6.0, 7.0] {
        let (fields, _) = fields_and_eyes(&scene, &mut renderer, Vec3::new(x, y, 0.0), false);
        assert!(
            fields.rect.is_none(),
            "a shadow at x = {x}: {:?}",
            fields.rect
        );
        assert_silent(&renderer);
    }
}

#[test]
fn fields_are_clear_while_the_light_is_below_the_floor_and_come_back_after() {
    let mut scene = shipped_scene("moving-light.toml");
    scene.inducer.resolution_px = 128;
    let mut renderer = scene_renderer(&scene, 32, 32);
    let rest = scene.rest_placement();
    let lit = renderer.inducer_fields().expect("fields");
    assert!(
        lit.gain.iter().any(|&g| g > 0.0),
        "no inducer light at rest"
    );
    let below = Placement {
        light_position_m: rest.light_position_m - Vec3::Y * 2.0,
        ..rest
    };
    assert!(below.light_position_m.y < scene.floor.pose.position.y);
    renderer.set_pose(render_desc::scene_pose(&scene, &below));
    let dark = renderer.inducer_fields().expect("fields");
    assert!(dark.rect.is_none(), "{:?}", dark.rect);
    assert!(
        dark.mask.iter().all(|&m| m == 0),
        "a shadow from below the floor"
    );
    assert!(
        dark.gain.iter().all(|&g| g == 0.0),
        "light from below the floor"
    );
    assert!(
        dark.distance_m
            .iter()
            .all(|&d| d == vitreous_optics::floor::FAR_M),
        "distances without a shadow"
    );
    renderer.set_pose(render_desc::scene_pose(&scene, &rest));
    let back = renderer.inducer_fields().expect("fields");
    assert!(back.mask == lit.mask && back.distance_m == lit.distance_m && back.gain == lit.gain);
    assert_eq!(renderer.inducer_computations(), 3);
    assert_silent(&renderer);
}

#[test]
fn glass_follows_the_object_from_the_frame_its_pose_is_set() {
    let scene = shipped_scene("rolling-diamond.toml");
    let (w, h) = (128, 96);
    let mut renderer = scene_renderer(&scene, w, h);
    let fov = Fov {
        left_rad: -0.2,
        right_rad: 0.2,
        up_rad: 0.0,
        down_rad: -0.3,
    };
    let eye = EyeParams::new(Vec3::ZERO, Quat::IDENTITY, fov);
    let params = FrameParams {
        eyes: [eye, eye],
        look: Look::default(),
    };
    for time_s in [0.0, 2.0, 4.0] {
        let placement = scene.placement_at(time_s);
        renderer.set_pose(render_desc::scene_pose(&scene, &placement));
        let frame = render_once(
            &mut renderer,
            &params,
            Want {
                eyes: true,
                world: false,
            },
        );
        let (lit, count) = lit_centroid(&frame.eyes[0], w, 8).expect("the diamond is drawn");
        let expected = eye
            .project_to_pixel(placement.object_position_m, Vec2::new(w as f32, h as f32))
            .unwrap();
        assert!(count > 80, "{count} pixels");
        assert!(
            (lit.x - expected.x).abs() < 2.0,
            "at {time_s} s the diamond is drawn at x = {}, its centre projects to {}",
            lit.x,
            expected.x
        );
    }
    assert_silent(&renderer);
}

#[test]
fn moving_light_replay_recomputes_the_inducer_only_when_something_moved() {
    let out = tempfile::tempdir().unwrap();
    let scene_path = workspace().join("config/scenes/moving-light.toml");
    let rate_hz = 4.0;
    let frames = 36u64;
    let summary = replay(&ReplayOptions {
        scene: scene_path.clone(),
        trace: None,
        out: out.path().to_path_buf(),
        frames: Some(frames),
        save_every: 0,
        size: Some((64, 48)),
        validate: true,
        effects: Some(EffectSet::parse("inducer").unwrap()),
        device: None,
        frame_rate_hz: rate_hz,
        at_samples: false,
        progress: false,
        reflection: vitreous_render::Reflection::Phong,
        sphere_check: false,
        compare_reference: false,
        compare_shifts_deg: Vec::new(),
        gaze: Default::default(),
        fields: Default::default(),
    })
    .expect("replay");
    assert_eq!(summary.frames, frames);
    assert_eq!(summary.validation.errors + summary.validation.warnings, 0);
    // Frames k / rate seconds apart: the light circles until 6 s, holds until 8 s (where the
    // circle starts again at the same place), then circles again.
    let scene = load_scene(&scene_path).unwrap();
    let moved = (1..frames)
        .filter(|&k| {
            let at = |k: u64| scene.placement_at(k as f64 / rate_hz);
            at(k) != at(k - 1)
        })
        .count() as u64;
    assert_eq!(moved, 24 + 3, "frames 1-24 and 33-35 move");
    assert_eq!(summary.moved_frames, moved);
    assert_eq!(summary.inducer_computations, 1 + moved);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["inducer_computations"], 1 + moved);
}
