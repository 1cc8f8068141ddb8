//! Making a session: the session itself, its reference spaces, the colour and depth
//! swapchains, the gaze source and the controller actions, in the order OpenXR needs them.

use std::sync::mpsc;

use ash::vk;
use ash::vk::Handle;
use openxr as xr;
use vitreous_trace::Blend;

use super::super::actions::Controls;
use super::super::choose::{self, GazeChoice, GazeOffer, GazeSource, SpaceChoice};
use super::super::gaze::{ExtGaze, FbTracker, Gaze, TraceGaze};
use super::super::ml_tracker::MlTracker;
use super::super::state::State;
use super::super::{
    DepthOptions, OpenXrError, Result, Runtime, SessionOptions, SwapchainImages, VulkanHandles,
    XrContext,
};
use super::{Session, SessionReport, install_ctrl_c};

/// Creates the session; see [`Runtime::start`].
///
/// # Safety
/// As [`Runtime::start`].
pub(in crate::openxr) unsafe fn start(
    rt: &Runtime,
    vulkan: VulkanHandles,
    options: &SessionOptions,
) -> Result<(Session, SwapchainImages)> {
    let info = xr::vulkan::SessionCreateInfo {
        instance: vulkan.instance.as_raw() as _,
        physical_device: vulkan.physical.as_raw() as _,
        device: vulkan.device.as_raw() as _,
        queue_family_index: vulkan.queue_family,
        queue_index: vulkan.queue_index,
    };
    // SAFETY: `info` holds the Vulkan handles this runtime created (this function's
    // contract), which outlive the session.
    let (session, waiter, stream) =
        unsafe { rt.instance.create_session::<xr::Vulkan>(rt.system, &info) }
            .xr("xrCreateSession")?;

    let spaces = session
        .enumerate_reference_spaces()
        .xr("xrEnumerateReferenceSpaces")?;
    let space_choice = choose::choose_space(spaces.contains(&xr::ReferenceSpaceType::STAGE));
    let space_type = match space_choice {
        SpaceChoice::Stage => xr::ReferenceSpaceType::STAGE,
        SpaceChoice::Local => xr::ReferenceSpaceType::LOCAL,
    };
    let space = session
        .create_reference_space(space_type, xr::Posef::IDENTITY)
        .xr("xrCreateReferenceSpace")?;
    let view_space = session
        .create_reference_space(xr::ReferenceSpaceType::VIEW, xr::Posef::IDENTITY)
        .xr("xrCreateReferenceSpace(VIEW)")?;
    tracing::info!("scene placed in the {space_choice:?} reference space");

    let formats: Vec<i64> = session
        .enumerate_swapchain_formats()
        .xr("xrEnumerateSwapchainFormats")?
        .into_iter()
        .map(i64::from)
        .collect();
    let format = choose::choose_format(&formats).ok_or_else(|| {
        OpenXrError::Unsupported(format!(
            "the runtime offers no 8-bit RGBA/BGRA swapchain format (VkFormat codes offered: {formats:?})"
        ))
    })?;
    tracing::info!(
        "swapchain format VkFormat {} ({})",
        format.vk_format,
        if format.srgb {
            "sRGB: the image encodes"
        } else {
            "UNORM: linear values stored as is"
        }
    );
    let (w, h) = rt.info.size;
    let swapchain = session
        .create_swapchain(&xr::SwapchainCreateInfo {
            create_flags: xr::SwapchainCreateFlags::EMPTY,
            // Another format than the renderer's is blitted into: transfer destination too.
            usage_flags: xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                | xr::SwapchainUsageFlags::TRANSFER_SRC
                | if format.vk_format == choose::vk_format::R8G8B8A8_SRGB {
                    xr::SwapchainUsageFlags::EMPTY
                } else {
                    xr::SwapchainUsageFlags::TRANSFER_DST
                },
            format: format.vk_format as u32,
            sample_count: 1,
            width: w,
            height: h,
            face_count: 1,
            array_size: 2,
            mip_count: 1,
        })
        .xr("xrCreateSwapchain")?;
    let images = swapchain
        .enumerate_images()
        .xr("xrEnumerateSwapchainImages")?
        .into_iter()
        .map(vk::Image::from_raw)
        .collect();
    let depth = match (rt.depth_layer, options.depth) {
        (true, Some(d)) => depth_swapchain(&session, &formats, d, (w, h)),
        (false, Some(_)) => {
            tracing::info!(
                "depth not submitted: the runtime does not offer XR_KHR_composition_layer_depth"
            );
            None
        }
        (_, None) => None,
    };
    let depth_images = match &depth {
        Some((chain, _)) => match chain.enumerate_images() {
            Ok(raw) => raw.into_iter().map(vk::Image::from_raw).collect(),
            Err(e) => {
                return Err(OpenXrError::Call {
                    call: "xrEnumerateSwapchainImages(depth)",
                    result: e,
                });
            }
        },
        None => Vec::new(),
    };

    let offer = GazeOffer {
        ml_eye_tracker: rt.ml_gaze && rt.info.ml_eye_tracker_supported,
        fb_social: rt.fb_gaze && rt.info.fb_eye_tracking_supported,
        ext_gaze_extension: rt.ext_gaze,
        ext_gaze_supported: rt.info.eye_gaze_supported,
        trace: options.gaze_trace.is_some(),
    };
    if rt.ext_gaze && !rt.info.eye_gaze_supported {
        tracing::info!(
            "XR_EXT_eye_gaze_interaction is offered but the system has no eye tracker \
             (supportsEyeGazeInteraction = false)"
        );
    }
    let gaze = make_gaze(&session, options, offer)?;
    // Controller actions: a failure here costs the live actions only, never the session.
    let controls = match Controls::new(&rt.instance) {
        Ok(c) => Some(c),
        Err(e) => {
            tracing::warn!("no live controller actions: {e}");
            None
        }
    };
    // xrAttachSessionActionSets may be called once per session: every set goes in together.
    let mut action_sets: Vec<xr::ActionSet> = Vec::new();
    if let Gaze::Combined(g, _) = &gaze {
        action_sets.push(g.set.clone());
    }
    if let Some(c) = &controls {
        action_sets.push(c.set.clone());
    }
    if !action_sets.is_empty() {
        let refs: Vec<&xr::ActionSet> = action_sets.iter().collect();
        session
            .attach_action_sets(&refs)
            .xr("xrAttachSessionActionSets")?;
    }
    let action_profiles: Vec<String> = controls
        .as_ref()
        .map(|c| c.profiles.iter().map(|p| (*p).to_owned()).collect())
        .unwrap_or_default();
    if controls.is_some() {
        tracing::info!(
            "controller actions attached (select, menu on each hand; profiles: {})",
            action_profiles.join(", ")
        );
    }
    tracing::info!("gaze source: {}", gaze.source());
    match &gaze {
        Gaze::Combined(_, decided) => tracing::warn!(
            "the runtime gives one combined gaze ray (XR_EXT_eye_gaze_interaction), which has no \
             depth: automatic defocus needs per-eye gaze. The combined ray is read and \
             recorded; the gaze image is decided {}",
            if decided.is_some() {
                "from the --gaze-trace's per-eye gaze"
            } else {
                "by hand (no --gaze-trace)"
            }
        ),
        Gaze::Manual => tracing::warn!(
            "no per-eye eye tracker and no --gaze-trace: the gaze image must be chosen by hand"
        ),
        _ => {}
    }

    if options.handle_ctrl_c {
        install_ctrl_c();
    }
    let blend = match rt.info.blend {
        Blend::Additive => xr::EnvironmentBlendMode::ADDITIVE,
        Blend::AlphaBlend => xr::EnvironmentBlendMode::ALPHA_BLEND,
        Blend::Opaque => xr::EnvironmentBlendMode::OPAQUE,
    };
    let report = SessionReport {
        states: vec![State::Idle],
        gaze_source: Some(gaze.source()),
        space: Some(space_choice),
        blend: Some(rt.info.blend),
        actions_attached: controls.is_some(),
        action_profiles,
        depth_format: depth.as_ref().map(|(_, d)| d.format.as_raw()),
        ..SessionReport::default()
    };
    let out = SwapchainImages {
        images,
        format: vk::Format::from_raw(format.vk_format as i32),
        srgb: format.srgb,
        size: (w, h),
        depth_images,
    };
    let (commands_tx, commands_rx) = mpsc::channel();
    let (injected_tx, injected_rx) = mpsc::channel();
    let (planes_tx, planes_rx) = mpsc::channel();
    let planes = if rt.planes {
        super::super::planes::PlaneDetector::new(&rt.instance, &session)
    } else {
        tracing::info!(
            "the runtime detects no planes (no XR_EXT_plane_detection): the table is the scene's"
        );
        None
    };
    let (light_tx, light_rx) = mpsc::channel();
    let light = if rt.light {
        super::super::light_estimator::LightEstimator::load(&rt.instance)
    } else {
        tracing::info!(
            "the runtime estimates no light (no XR_ML_light_estimation): the light is the scene \
             file's"
        );
        None
    };
    Ok((
        Session {
            planes,
            planes_tx,
            planes_rx: Some(planes_rx),
            light,
            light_tx,
            light_rx: Some(light_rx),
            stream,
            waiter,
            swapchain,
            depth,
            controls,
            action_sets,
            commands_tx,
            commands_rx: Some(commands_rx),
            injected_tx,
            injected_rx,
            gaze,
            gaze_order: options.continued.map(|c| c.gaze_order).unwrap_or_default(),
            space,
            space_type,
            view_space,
            session,
            instance: rt.instance.clone(),
            events: xr::EventDataBuffer::new(),
            blend,
            layer_flags: layer_flags(rt.info.blend),
            display_blend: rt.info.blend,
            size: (w, h),
            state: State::Idle,
            running: false,
            exit_requested: false,
            quit: false,
            world_from_space: options
                .continued
                .and_then(|c| c.world_from_space)
                .filter(|_| space_choice == SpaceChoice::Stage),
            first_display: options
                .continued
                .and_then(|c| c.first_display_ns)
                .map(xr::Time::from_nanos),
            next_index: options.continued.map_or(0, |c| c.next_index),
            open: None,
            options: options.clone(),
            report,
            ml_frame_end: rt.ml_frame_end,
            ml_dimmer: rt.ml_dimmer,
            hints: crate::FrameEndHints::default(),
            pending: {
                let mut pending = super::interruptions::Pending::default();
                if let Some(c) = options.continued {
                    pending.push(vitreous_trace::SessionEvent::Reconnected {
                        waited_ms: c.waited_ms,
                    });
                }
                pending
            },
            last_waited_ns: None,
            last_display: options.continued.and_then(|c| c.last_display),
            tracking: Default::default(),
            paused: None,
            failed_in_a_row: 0,
            unfocused: false,
        },
        out,
    ))
}

/// Makes the gaze source: the forced one (an error when it is not offered or cannot be
/// made), else the best offered one that can be made, falling back down the order.
fn make_gaze(
    session: &xr::Session<xr::Vulkan>,
    options: &SessionOptions,
    offer: GazeOffer,
) -> Result<Gaze> {
    let trace = || -> Result<TraceGaze> {
        match options.gaze_trace.as_deref() {
            Some(path) => TraceGaze::open(path),
            None => Err(OpenXrError::Unsupported("no --gaze-trace given".into())),
        }
    };
    let make = |source: GazeSource| -> Result<Gaze> {
        match source {
            GazeSource::MlEyeTracker => MlTracker::new(session).map(Gaze::MlEyeTracker),
            GazeSource::FbSocial => FbTracker::new(session).map(Gaze::FbSocial),
            GazeSource::ExtGaze => {
                // The trace decides the gaze image; the combined ray is read alongside.
                let decided = if offer.trace { Some(trace()?) } else { None };
                ExtGaze::new(session).map(|g| Gaze::Combined(g, decided))
            }
            GazeSource::Trace => trace().map(Gaze::Trace),
            GazeSource::Manual => Ok(Gaze::Manual),
        }
    };
    let forced = options.gaze != GazeChoice::Auto;
    let first = choose::choose_gaze(offer, options.gaze).map_err(OpenXrError::Unsupported)?;
    let ranked = offer.ranked();
    let start = ranked.iter().position(|s| *s == first).unwrap_or(0);
    for &source in &ranked[start..] {
        match make(source) {
            Ok(g) => return Ok(g),
            // A forced source, and a bad trace (the user's error), fail the run.
            Err(e) if forced || source == GazeSource::Trace => return Err(e),
            Err(e) => tracing::warn!("gaze source {source} failed ({e}); trying the next one"),
        }
    }
    Ok(Gaze::Manual)
}

/// The projection layer's flags for a blend mode: ALPHA_BLEND composes the premultiplied
/// image by its alpha (XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT); the others show
/// the colour alone.
fn layer_flags(blend: Blend) -> xr::CompositionLayerFlags {
    if blend.uses_source_alpha() {
        xr::CompositionLayerFlags::BLEND_TEXTURE_SOURCE_ALPHA
    } else {
        xr::CompositionLayerFlags::EMPTY
    }
}

/// Makes the 2-layer depth swapchain, or says why not and returns `None` (no depth is then
/// submitted; nothing else changes).
fn depth_swapchain(
    session: &xr::Session<xr::Vulkan>,
    formats: &[i64],
    depth: DepthOptions,
    (w, h): (u32, u32),
) -> Option<(xr::Swapchain<xr::Vulkan>, DepthOptions)> {
    let code = i64::from(depth.format.as_raw());
    if !formats.contains(&code) {
        tracing::warn!(
            "depth not submitted: the runtime offers no {:?} swapchain (VkFormat codes \
             offered: {formats:?})",
            depth.format
        );
        return None;
    }
    let made = session.create_swapchain(&xr::SwapchainCreateInfo {
        create_flags: xr::SwapchainCreateFlags::EMPTY,
        usage_flags: xr::SwapchainUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        format: code as u32,
        sample_count: 1,
        width: w,
        height: h,
        face_count: 1,
        array_size: 2,
        mip_count: 1,
    });
    match made {
        Ok(chain) => {
            tracing::info!(
                "depth submitted with XR_KHR_composition_layer_depth: {:?} swapchain, depth 0..1 \
                 = {} m..{} m",
                depth.format,
                depth.near_m,
                depth.far_m
            );
            Some((chain, depth))
        }
        Err(e) => {
            tracing::warn!("depth not submitted: xrCreateSwapchain(depth) failed: {e}");
            None
        }
    }
}
