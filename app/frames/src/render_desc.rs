//! From what a backend hands out to what the renderer takes: per-eye cameras and the scene's
//! GPU description.

use vitreous_optics::camera::{EyeParams, Fov as RenderFov};
use vitreous_render::{
    CausticsDesc, FrameParams, InducerDesc, LightDesc, Look, MeshRef, PlaneDesc, SceneDesc,
    ScenePose, TexelData, TextureDesc,
};
use vitreous_trace::{EyeView, Fov, FrameInput};

use crate::blur_stack::DefocusSetup;
use vitreous_scene::{CausticsMode, Image, PixelData, Placement, Scene};

/// Scale applied to environment radiance. The shipped HDR maps are in scene-referred units
/// where 1.0 is a bright diffuse white; they are shown as they are.
pub const ENVIRONMENT_EXPOSURE: f32 = 1.0;

/// The renderer's field of view for an OpenXR one.
pub fn render_fov(fov: Fov) -> RenderFov {
    RenderFov {
        left_rad: fov.angle_left_rad,
        right_rad: fov.angle_right_rad,
        up_rad: fov.angle_up_rad,
        down_rad: fov.angle_down_rad,
    }
}

/// One eye's camera from its view.
pub fn eye_params(view: &EyeView) -> EyeParams {
    EyeParams::new(
        view.pose.position,
        view.pose.orientation,
        render_fov(view.fov),
    )
}

/// Draws one frame of each look from the scene's neutral head (the viewer at
/// `head_position_m`, looking down -z) into the renderer's own images, composed as
/// `composition` says, and waits for them: a driver that compiles its shaders when they are
/// first used (lavapipe) does it here, before a live session's first frame, instead of while
/// the runtime's clock runs (the first frames then came seconds late). The floor's fields are
/// then due again, so the session's first frame computes them as a fresh renderer's would;
/// the warm-up's computations are in [`vitreous_render::Renderer::inducer_computations`]
/// before the session's.
pub fn warm_up(
    renderer: &mut vitreous_render::Renderer,
    scene: &Scene,
    looks: &[Look],
    composition: vitreous_render::Composition,
) -> anyhow::Result<()> {
    use vitreous_trace::Pose;
    let head = Pose {
        position: scene.viewer.head_position_m,
        orientation: glam::Quat::IDENTITY,
    };
    let views = scene.viewer.eye_positions_m(&head).map(|p| EyeView {
        pose: Pose {
            position: p,
            orientation: glam::Quat::IDENTITY,
        },
        fov: scene.output.fov,
    });
    let input = FrameInput {
        index: 0,
        time_ns: 0,
        head,
        views,
        gaze: None,
    };
    tracing::info!(
        "drawing each of the {} looks once before the session (a driver such as lavapipe \
         finishes its shaders at their first draw)",
        looks.len()
    );
    let started = std::time::Instant::now();
    for look in looks {
        renderer.submit_composed(
            &frame_params(&input, *look),
            vitreous_render::renderer::Want::default(),
            composition,
        )?;
    }
    renderer.flush()?;
    renderer.recompute_floor();
    tracing::info!("looks drawn in {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// The renderer's parameters for a frame drawn with `look`.
pub fn frame_params(input: &FrameInput, look: Look) -> FrameParams {
    FrameParams {
        eyes: [eye_params(&input.views[0]), eye_params(&input.views[1])],
        look,
    }
}

/// The renderer's pose of the object and the light for a placement of `scene`'s object.
pub fn scene_pose(scene: &Scene, placement: &Placement) -> ScenePose {
    ScenePose {
        world_from_model: scene
            .object
            .world_from_model_at(placement.object_position_m, placement.object_rotation),
        light_position_m: placement.light_position_m,
    }
}

/// Turns on the caustics computed per pose when the scene asks for them (`[caustics] mode =
/// "live"`) and `caustics` (the effect) is on; `renderer` must have been made from this
/// scene's description with its caustics loaded.
pub fn enable_live_caustics(
    renderer: &mut vitreous_render::Renderer,
    scene: &Scene,
    caustics: bool,
) -> vitreous_render::Result<()> {
    if !caustics || scene.caustics.mode != CausticsMode::Live {
        return Ok(());
    }
    let live = vitreous_optics::live_caustics::LiveCausticsDesc {
        photons_per_side: scene.caustics.photons_per_side,
        smoothing_px: scene.caustics.smoothing_px,
        min_path_weight: scene.caustics.min_path_weight,
        ..Default::default()
    };
    renderer.enable_live_caustics(&scene_desc(scene, None), live)?;
    let side = scene.caustics.resolution_px;
    tracing::info!(
        "caustics computed on the GPU for each pose: a {side} x {side} map, {n} x {n} photons, \
         smoothed over {r} texels, paths ending below {w} of a photon",
        n = live.photons_per_side,
        r = live.smoothing_px,
        w = live.min_path_weight
    );
    Ok(())
}

/// Seconds from `start_ns` to a frame at `time_ns` (the backend's clock): the time
/// [`Scene::placement_at`] takes.
pub fn seconds_since(start_ns: i64, time_ns: i64) -> f64 {
    time_ns.saturating_sub(start_ns) as f64 * 1e-9
}

/// The renderer's view of an image.
pub fn texture(image: &Image) -> TextureDesc<'_> {
    TextureDesc {
        width: image.width,
        height: image.height,
        data: match &image.data {
            PixelData::Srgb8(bytes) => TexelData::Srgb8(bytes),
            PixelData::LinearF32(floats) => TexelData::LinearF32(floats),
        },
    }
}

/// The renderer for `scene` (with its defocus stacks when given) at `width` x `height` per eye,
/// said before and after: the driver compiles every pipeline here, which for a mesh's glass on
/// a CPU device (lavapipe) takes a minute or more the first time.
pub fn renderer_for(
    ctx: vitreous_render::GpuContext,
    scene: &Scene,
    defocus: Option<&DefocusSetup>,
    width: u32,
    height: u32,
) -> anyhow::Result<vitreous_render::Renderer> {
    use anyhow::Context;
    tracing::info!("preparing the renderer for {width}x{height} (the driver compiles its shaders)");
    let started = std::time::Instant::now();
    let renderer = vitreous_render::Renderer::new(ctx, &scene_desc(scene, defocus), width, height)
        .context("preparing the renderer")?;
    tracing::info!("renderer ready in {:.1} s", started.elapsed().as_secs_f64());
    Ok(renderer)
}

/// The renderer's view of a scene, with the blur stacks of `defocus` when defocus is used.
pub fn scene_desc<'a>(scene: &'a Scene, defocus: Option<&'a DefocusSetup>) -> SceneDesc<'a> {
    let mesh = &scene.object.mesh;
    SceneDesc {
        mesh: MeshRef {
            positions: &mesh.positions,
            normals: &mesh.normals,
            uvs: &mesh.uvs,
            indices: &mesh.indices,
        },
        world_from_model: scene.object.world_from_model,
        ior: scene.object.ior,
        refraction: scene.object.refraction,
        attenuation: scene.object.attenuation,
        environment: texture(&scene.environment.latlong),
        floor: PlaneDesc {
            world_from_plane: scene.floor.world_from_plane(),
            photo: texture(&scene.floor.photo),
        },
        background: PlaneDesc {
            world_from_plane: scene.background.world_from_plane(),
            photo: texture(&scene.background.photo),
        },
        exposure: ENVIRONMENT_EXPOSURE,
        surface: scene.object.surface_texture.as_ref().map(texture),
        surface_transmittance: scene.object.surface_transmittance,
        light: LightDesc {
            position_m: scene.light.position_m,
            radiance: scene.light.color * scene.light.intensity,
            share: scene.light.share,
        },
        background_stack: defocus.map(|d| d.background.desc()),
        surface_stack: defocus.and_then(|d| d.surface.as_ref()).map(|s| s.desc()),
        inducer: InducerDesc {
            k: scene.inducer.k,
            ramp_width_m: scene.inducer.ramp_width_m,
            resolution_px: scene.inducer.resolution_px,
        },
        // Present once `Scene::load_caustics` has read the bake.
        caustics: scene.caustics.gain.as_ref().map(|bake| CausticsDesc {
            width: bake.width_px,
            height: bake.height_px,
            gain: &bake.gain,
            light: bake.light.as_deref(),
        }),
        compensation: scene.compensation,
        room: scene.environment.room,
        glass_samples: scene.output.glass_samples,
        dimmer: scene.dimmer,
    }
}
