//! The renderer on the machine's Vulkan device with validation on: the sphere lands where the
//! CPU projection says, in both eyes, and validation stays silent.

use glam::{Quat, Vec2, Vec3};
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_render::renderer::Want;
use vitreous_render::{
    CausticsDesc, FrameParams, Look, PlaneDesc, RenderError, Renderer, SceneDesc, TextureDesc,
};
use vitreous_tests::{
    flat_environment, grey_photo, linear, lit_centroid, mesh_ref, place, scene_desc, srgb,
    uv_sphere,
};

/// A floor 0.5 m below and ahead of the eyes showing `photo`.
fn floor(photo: TextureDesc<'_>) -> PlaneDesc<'_> {
    PlaneDesc {
        world_from_plane: glam::Mat4::from_translation(Vec3::new(0.0, -0.5, -0.5)),
        photo,
    }
}

/// A wall 1 m ahead of the eyes showing `photo`.
fn wall(photo: TextureDesc<'_>) -> PlaneDesc<'_> {
    PlaneDesc {
        world_from_plane: glam::Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0)),
        photo,
    }
}

#[test]
fn sphere_centroid_matches_projection_in_both_eyes_with_validation_silent() {
    let ctx = vitreous_tests::validated_context();
    let sphere = uv_sphere(64, 32);
    let env = flat_environment(64, 32, 0.8);
    let photo = grey_photo(8, 8, 128);
    let center = Vec3::new(0.01, -0.02, -0.45);
    let radius = 0.04;
    let photo_desc = srgb(8, 8, &photo);
    let scene = SceneDesc {
        ior: 1.51,
        ..scene_desc(
            mesh_ref(&sphere),
            place(center, radius),
            linear(64, 32, &env),
            floor(photo_desc),
            wall(photo_desc),
        )
    };
    let (w, h) = (320u32, 240u32);
    let mut renderer = Renderer::new(ctx, &scene, w, h).expect("renderer");
    let fov = Fov {
        left_rad: -0.35,
        right_rad: 0.35,
        up_rad: 0.27,
        down_rad: -0.27,
    };
    let ipd = 0.063;
    let eyes = [-ipd / 2.0, ipd / 2.0]
        .map(|x| EyeParams::new(Vec3::new(x, 0.0, 0.0), Quat::IDENTITY, fov));
    let params = FrameParams {
        eyes,
        look: Look::default(),
    };
    let want = Want {
        eyes: true,
        world: true,
    };
    let mut results = Vec::new();
    for _ in 0..3 {
        results.extend(renderer.submit(&params, want).unwrap());
    }
    results.extend(renderer.flush().unwrap());
    assert_eq!(results.len(), 3);
    let last = results.last().unwrap().readback.as_ref().unwrap();
    let size = Vec2::new(w as f32, h as f32);
    let mut xs = Vec::new();
    for (i, eye) in eyes.iter().enumerate() {
        let (centroid, count) = lit_centroid(&last.eyes[i], w, 10).expect("sphere visible");
        let expected = eye.project_to_pixel(center, size).unwrap();
        assert!(count > 100, "eye {i}: only {count} lit pixels");
        assert!(
            (centroid - expected).length() < 2.0,
            "eye {i}: centroid {centroid} vs projection {expected}"
        );
        xs.push(centroid.x);
    }
    let disparity = xs[0] - xs[1];
    let expected = eyes[0].project_to_pixel(center, size).unwrap().x
        - eyes[1].project_to_pixel(center, size).unwrap().x;
    assert!(
        (disparity - expected).abs() < 1.0,
        "{disparity} vs {expected}"
    );
    let world = last.world.as_ref().unwrap();
    assert!(world[0].chunks_exact(4).all(|p| p[3] == 255));
    let v = renderer.context().validation();
    assert_eq!(
        v.errors() + v.warnings(),
        0,
        "validation messages: {:#?}",
        v.messages()
    );
}

/// The zero-message assertions above can fail: a deliberate misuse is counted.
#[test]
fn validation_messages_are_counted() {
    let ctx = vitreous_tests::validated_context();
    assert_eq!(ctx.validation().errors(), 0);
    let info = ash::vk::BufferCreateInfo::default()
        .size(0)
        .usage(ash::vk::BufferUsageFlags::VERTEX_BUFFER);
    // A zero-sized buffer violates VUID-VkBufferCreateInfo-size-00912.
    // SAFETY: the device is live; the invalid size is the point (the layer reports it, the
    // driver tolerates it), and the buffer, if made, is destroyed at once, unused.
    if let Ok(buffer) = unsafe { ctx.device.create_buffer(&info, None) } {
        // SAFETY: made just above on this device, never used.
        unsafe { ctx.device.destroy_buffer(buffer, None) };
    }
    assert!(
        ctx.validation().errors() > 0,
        "validation error not counted"
    );
    assert!(!ctx.validation().messages().is_empty());
}

/// A construction that fails part way frees what it made before the device goes: with an
/// allocation failure injected at every step in turn, each attempt reports that failure, and
/// validation (which names every object still alive when the device is destroyed) stays
/// silent; the attempt after the last step builds a working renderer.
#[test]
fn failed_construction_unwinds_without_leaks_at_every_step() {
    let sphere = uv_sphere(8, 4);
    let env = flat_environment(8, 4, 0.5);
    let photo = grey_photo(4, 4, 128);
    let gain = vec![0.5f32; 8 * 8];
    let photo_desc = srgb(4, 4, &photo);
    let scene = SceneDesc {
        inducer: vitreous_render::InducerDesc {
            resolution_px: 32,
            ..vitreous_render::InducerDesc::PAPER
        },
        caustics: Some(CausticsDesc {
            width: 8,
            height: 8,
            gain: &gain,
            light: None,
        }),
        ..scene_desc(
            mesh_ref(&sphere),
            place(Vec3::new(0.0, -0.2, -0.5), 0.05),
            linear(8, 4, &env),
            floor(photo_desc),
            wall(photo_desc),
        )
    };
    let mut failed_steps = 0;
    for step in 0..200 {
        let ctx = vitreous_tests::validated_context();
        let log = ctx.validation_log();
        ctx.fail_allocation_after(step);
        let built = Renderer::new(ctx, &scene, 16, 12);
        let done = match built {
            Err(RenderError::Injected(what)) => {
                failed_steps += 1;
                eprintln!("step {step}: failed allocating {what}");
                false
            }
            Err(e) => panic!("step {step}: not the injected failure: {e}"),
            Ok(mut renderer) => {
                // Past the last allocation of construction: the renderer works. The armed
                // failure, if still pending, hits the fields' readback buffer, which must
                // unwind too and leave the fields computable.
                let fields = match renderer.inducer_fields() {
                    Err(RenderError::Injected(_)) => renderer.inducer_fields(),
                    other => other,
                }
                .expect("fields");
                assert!(fields.mask.contains(&1), "no shadow in the mask");
                drop(renderer);
                true
            }
        };
        // The context (and its device) is gone now, in both cases.
        assert_eq!(
            log.errors() + log.warnings(),
            0,
            "step {step}: validation messages: {:#?}",
            log.messages()
        );
        if done {
            assert!(failed_steps > 20, "only {failed_steps} steps allocate");
            return;
        }
    }
    panic!("construction still failing after 200 injected failures");
}

/// Each display blend mode composes as it must: ADDITIVE on black (alpha 1), ALPHA_BLEND the
/// same light premultiplied over alpha 0 (the world shows through), OPAQUE over the real-world
/// photos; the object in all three.
#[test]
fn each_composition_draws_the_object_over_what_its_display_needs() {
    use vitreous_render::Composition;
    let ctx = vitreous_tests::validated_context();
    let sphere = uv_sphere(32, 16);
    let env = flat_environment(16, 8, 0.8);
    let photo = grey_photo(4, 4, 128);
    let photo_desc = srgb(4, 4, &photo);
    // The background photo plane fills the view far behind the object.
    let background = glam::Mat4::from_scale_rotation_translation(
        Vec3::new(10.0, 10.0, 1.0),
        Quat::IDENTITY,
        Vec3::new(0.0, 0.0, -2.0),
    );
    let scene = SceneDesc {
        inducer: vitreous_render::InducerDesc {
            resolution_px: 32,
            ..vitreous_render::InducerDesc::PAPER
        },
        ..scene_desc(
            mesh_ref(&sphere),
            place(Vec3::new(0.0, 0.0, -0.5), 0.05),
            linear(16, 8, &env),
            PlaneDesc {
                world_from_plane: glam::Mat4::from_translation(Vec3::new(0.0, -5.0, -0.5)),
                photo: photo_desc,
            },
            PlaneDesc {
                world_from_plane: background,
                photo: photo_desc,
            },
        )
    };
    let (w, h) = (96u32, 72u32);
    let mut renderer = Renderer::new(ctx, &scene, w, h).expect("renderer");
    let fov = Fov {
        left_rad: -0.35,
        right_rad: 0.35,
        up_rad: 0.27,
        down_rad: -0.27,
    };
    let params = FrameParams {
        eyes: [-0.0315f32, 0.0315]
            .map(|x| EyeParams::new(Vec3::new(x, 0.0, 0.0), Quat::IDENTITY, fov)),
        look: Look::default(),
    };
    let want = Want {
        eyes: true,
        world: true,
    };
    let mut render = |c: Composition| {
        let mut results: Vec<_> = renderer
            .submit_composed(&params, want, c)
            .unwrap()
            .into_iter()
            .collect();
        results.extend(renderer.flush().unwrap());
        results.pop().unwrap().readback.unwrap()
    };
    let additive = render(Composition::Additive);
    let alpha = render(Composition::AlphaBlend);
    let opaque = render(Composition::Opaque);
    // A 10x10 px corner of each eye, far from the object.
    let corner = |rgba: &[u8]| -> Vec<[u8; 4]> {
        (0..10)
            .flat_map(|row| (0..10).map(move |col| (row * w + col) as usize * 4))
            .map(|i| [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]])
            .collect()
    };
    for eye in 0..2 {
        let (_, lit) = lit_centroid(&additive.eyes[eye], w, 10).expect("object on additive");
        assert!(lit > 50, "eye {eye}: {lit} lit px");
        assert!(
            corner(&additive.eyes[eye])
                .iter()
                .all(|p| *p == [0, 0, 0, 255])
        );
        // ALPHA_BLEND: the same light, alpha 0 everywhere.
        let (a, b) = (&additive.eyes[eye], &alpha.eyes[eye]);
        assert!(
            b.chunks_exact(4).all(|p| p[3] == 0),
            "eye {eye}: alpha above 0"
        );
        assert!(
            a.chunks_exact(4)
                .zip(b.chunks_exact(4))
                .all(|(p, q)| p[..3] == q[..3]),
            "eye {eye}: alpha-blend colour differs from additive"
        );
        // OPAQUE: the real world where the object is not, and the object where it is.
        let world = &opaque.world.as_ref().unwrap()[eye];
        let seen = corner(&opaque.eyes[eye]);
        assert!(
            seen.iter().all(|p| p[0] > 40 && p[3] == 255),
            "{:?}",
            seen[0]
        );
        assert_eq!(seen, corner(world));
        let differs = opaque.eyes[eye]
            .chunks_exact(4)
            .zip(world.chunks_exact(4))
            .filter(|(p, q)| p[..3].iter().zip(&q[..3]).any(|(x, y)| x.abs_diff(*y) > 8))
            .count();
        assert!(
            differs > 50,
            "eye {eye}: object over the world in {differs} px"
        );
    }
    let v = renderer.context().validation();
    assert_eq!(
        v.errors() + v.warnings(),
        0,
        "validation messages: {:#?}",
        v.messages()
    );
}
