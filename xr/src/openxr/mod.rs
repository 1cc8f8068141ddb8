//! The OpenXR backend: a live session on a headset runtime (Magic Leap 2, Monado, ...).
//!
//! Set-up happens in three steps because OpenXR's XR_KHR_vulkan_enable2 must create the Vulkan
//! instance and device itself, while the renderer owns them afterwards:
//! 1. [`Runtime::new`]: OpenXR instance (HMD form factor; XR_KHR_vulkan_enable2 required,
//!    eye-gaze and depth-layer extensions when offered), system, stereo view configuration,
//!    blend-mode choice. Its `create_vulkan_*` methods (`vulkan.rs`) are what the renderer's
//!    device creator calls ([`XrDeviceCreator`], a `vitreous_render::DeviceCreator`).
//! 2. [`Runtime::start`]: session on the renderer's device, reference space (STAGE when offered,
//!    else LOCAL), one 2-layer array swapchain (and a 2-layer depth swapchain when depth is
//!    submitted with XR_KHR_composition_layer_depth), gaze source, the controller action set
//!    ([`actions`]). Gives the [`Session`] backend and the swapchains' `VkImage`s for the
//!    renderer to draw into.
//! 3. The frame loop drives the [`Session`] through [`crate::Backend`]: `wait_frame`
//!    (xrWaitFrame, xrBeginFrame, acquire and wait a swapchain image, locate views at the
//!    predicted display time, xrSyncActions once FOCUSED), rendering into
//!    [`crate::Backend::frame_target`], `end_frame` (release, xrEndFrame with a projection
//!    layer, each view chaining its `XrCompositionLayerDepthInfoKHR` when depth is submitted).
//!
//! Teardown order: [`Session`] (swapchain, spaces, session) before the Vulkan device, the
//! [`Runtime`] (instance) after it; see the app's `run` module.
//!
//! Every way out of a session (frame limit, Ctrl-C, the runtime stopping it, session or
//! instance loss) goes through xrRequestExitSession / xrEndSession where the state allows and
//! ends with a [`state::EndReason`] instead of an error.

pub mod actions;
pub mod choose;
mod convert;
mod device_creator;
mod error;
mod gaze;
mod gaze_order;
mod light_estimator;
pub mod ml_eye_tracker;
pub mod ml_light_estimation;
mod ml_tracker;
mod planes;
mod session;
pub mod state;
mod vulkan;

use ash::vk;
use openxr as xr;
use vitreous_trace::{Blend, Pose};

/// The `ash` crate these APIs use, for callers without their own dependency on it.
pub use ash;
pub use choose::{ColorFormat, GazeChoice, GazeSource};
pub use device_creator::XrDeviceCreator;
pub(crate) use error::XrContext;
pub use error::{OpenXrError, Result};
pub use gaze::GazeTally;
pub use gaze_order::{GazeOrder, Ordered};
pub use session::{Interruptions, Session, SessionReport, interrupted};
pub use state::{EndReason, State};

/// The OpenXR core validation layer's name.
pub const CORE_VALIDATION_LAYER: &str = "XR_APILAYER_LUNARG_core_validation";

/// How to set up the OpenXR side.
#[derive(Clone, Debug, Default)]
pub struct OpenXrOptions {
    /// Blend mode to use instead of the automatic choice (must be offered).
    pub blend: Option<Blend>,
    /// The scene drives a segmented dimmer: ALPHA_BLEND comes first in the automatic choice.
    pub dimmer: bool,
    /// Enable the OpenXR core validation layer (XR_APILAYER_LUNARG_core_validation) when it is
    /// installed; it can also be enabled with `XR_ENABLE_API_LAYERS`.
    pub validation: bool,
    /// Eye image size instead of the runtime's recommended one, pixels.
    pub size: Option<(u32, u32)>,
}

/// What the runtime offers, for logs and summaries.
#[derive(Clone, Debug)]
pub struct RuntimeInfo {
    /// Runtime name and version.
    pub runtime: String,
    /// System (headset) name.
    pub system: String,
    /// Extensions vitreous enabled.
    pub extensions: Vec<String>,
    /// Blend modes offered, in the runtime's order.
    pub blend_modes_offered: Vec<Blend>,
    /// The blend mode used.
    pub blend: Blend,
    /// Recommended eye image size, pixels.
    pub recommended_size: (u32, u32),
    /// Largest eye image size, pixels.
    pub max_size: (u32, u32),
    /// The eye image size used, pixels.
    pub size: (u32, u32),
    /// The system supports XR_EXT_eye_gaze_interaction (`supportsEyeGazeInteraction`).
    pub eye_gaze_supported: bool,
    /// The system supports XR_FB_eye_tracking_social.
    pub fb_eye_tracking_supported: bool,
    /// The system supports XR_ML_eye_tracker (`XrSystemEyeTrackerPropertiesML`).
    pub ml_eye_tracker_supported: bool,
    /// Vulkan versions the runtime accepts (min, max) as "major.minor".
    pub vulkan_versions: (String, String),
}

/// An OpenXR instance and system: everything before there is a Vulkan device.
pub struct Runtime {
    /// The instance (also kept alive by sessions made from it).
    instance: xr::Instance,
    /// The HMD system.
    system: xr::SystemId,
    /// What was found and chosen.
    info: RuntimeInfo,
    /// XR_KHR_composition_layer_depth is enabled.
    depth_layer: bool,
    /// XR_EXT_eye_gaze_interaction is enabled.
    ext_gaze: bool,
    /// XR_FB_eye_tracking_social is enabled.
    fb_gaze: bool,
    /// XR_ML_eye_tracker is enabled.
    ml_gaze: bool,
    /// XR_ML_frame_end_info is enabled: the focus distance is submitted with every frame.
    ml_frame_end: bool,
    /// XR_ML_global_dimmer is enabled: the global dimmer is submitted when asked for.
    ml_dimmer: bool,
    /// XR_EXT_plane_detection is enabled: the session detects the room's upward planes.
    planes: bool,
    /// XR_ML_light_estimation is enabled: the scene's light follows the room's.
    light: bool,
    /// The Vulkan instance made through the runtime, for the device steps.
    vk_instance: Option<vk::Instance>,
}

impl Runtime {
    /// Loads the OpenXR loader, creates the instance and finds the headset.
    pub fn new(options: &OpenXrOptions) -> Result<Runtime> {
        // Nothing on a desktop; the Java VM and activity on Android.
        #[allow(clippy::let_unit_value)]
        let platform = platform_info();
        // SAFETY: loading the OpenXR loader only runs its initialisation (on Android with the
        // activity's VM and context, XR_KHR_loader_init_android).
        let entry = unsafe { xr::Entry::load(&platform) }
            .map_err(|e| OpenXrError::NoLoader(e.to_string()))?;
        let available = entry
            .enumerate_extensions()
            .map_err(|e| OpenXrError::NoRuntime(format!("listing extensions: {e}")))?;
        if !available.khr_vulkan_enable2 {
            return Err(OpenXrError::NoVulkan(error::extension_list(&available)));
        }
        let mut wanted = xr::ExtensionSet::default();
        wanted.khr_vulkan_enable2 = true;
        // Android: the instance is created for the NativeActivity (the loader's own
        // requirement there).
        #[cfg(target_os = "android")]
        {
            wanted.khr_android_create_instance = true;
        }
        wanted.ext_eye_gaze_interaction = available.ext_eye_gaze_interaction;
        wanted.fb_eye_tracking_social = available.fb_eye_tracking_social;
        wanted.khr_composition_layer_depth = available.khr_composition_layer_depth;
        // Magic Leap 2's frame controls: the focus plane and the global dimmer.
        wanted.ml_frame_end_info = available.ml_frame_end_info;
        wanted.ml_global_dimmer = available.ml_global_dimmer;
        // The room's level surfaces, for placing the object on the table under the gaze.
        wanted.ext_plane_detection = available.ext_plane_detection;
        // XR_ML_eye_tracker is unknown to the `openxr` crate: enabled by name when listed.
        let ml_name = nul_terminated(ml_eye_tracker::EXTENSION_NAME);
        let ml_gaze = available.other.contains(&ml_name);
        if ml_gaze {
            wanted.other.push(ml_name);
        }
        // XR_ML_light_estimation, Magic Leap 2's estimate of the room's light: likewise.
        let light_name = nul_terminated(ml_light_estimation::EXTENSION_NAME);
        let light = available.other.contains(&light_name);
        if light {
            wanted.other.push(light_name);
        }
        let mut layers = Vec::new();
        if options.validation {
            let installed = entry
                .enumerate_layers()
                .map_err(|e| OpenXrError::NoRuntime(format!("listing API layers: {e}")))?;
            let already = std::env::var("XR_ENABLE_API_LAYERS")
                .is_ok_and(|v| v.split([':', ';', ',']).any(|l| l == CORE_VALIDATION_LAYER));
            if installed
                .iter()
                .any(|l| l.layer_name == CORE_VALIDATION_LAYER)
                && !already
            {
                layers.push(CORE_VALIDATION_LAYER);
            } else if !already {
                tracing::warn!(
                    "OpenXR validation asked for, but {CORE_VALIDATION_LAYER} is not installed"
                );
            }
        }
        let app = xr::ApplicationInfo {
            application_name: "vitreous",
            application_version: 1,
            engine_name: "vitreous",
            engine_version: 1,
            api_version: xr::Version::new(1, 0, 0),
        };
        let instance = entry
            .create_instance(&app, &wanted, &layers, &platform)
            .map_err(|e| {
                if e == xr::sys::Result::ERROR_RUNTIME_UNAVAILABLE {
                    return OpenXrError::Unavailable {
                        call: "xrCreateInstance",
                        result: e,
                    };
                }
                let from_env = std::env::var("XR_ENABLE_API_LAYERS").ok();
                let detail = error::instance_error(&e.to_string(), &layers, from_env.as_deref());
                match e {
                    xr::sys::Result::ERROR_INITIALIZATION_FAILED
                    | xr::sys::Result::ERROR_RUNTIME_FAILURE => OpenXrError::InstanceFailed {
                        result: e,
                        detail: Box::new(detail),
                    },
                    _ => detail,
                }
            })?;
        let props = instance.properties().xr("xrGetInstanceProperties")?;
        let system = instance
            .system(xr::FormFactor::HEAD_MOUNTED_DISPLAY)
            .map_err(|e| match e {
                xr::sys::Result::ERROR_FORM_FACTOR_UNAVAILABLE => OpenXrError::Unavailable {
                    call: "xrGetSystem",
                    result: e,
                },
                _ => OpenXrError::NoHmd(format!("xrGetSystem: {e}")),
            })?;
        let sys_props = instance
            .system_properties(system)
            .xr("xrGetSystemProperties")?;
        let support = gaze_support(
            &instance,
            system,
            wanted.ext_eye_gaze_interaction,
            wanted.fb_eye_tracking_social,
            ml_gaze,
        );

        let stereo = xr::ViewConfigurationType::PRIMARY_STEREO;
        let blend_modes_offered: Vec<Blend> = instance
            .enumerate_environment_blend_modes(system, stereo)
            .xr("xrEnumerateEnvironmentBlendModes")?
            .into_iter()
            .filter_map(|m| match m {
                xr::EnvironmentBlendMode::ADDITIVE => Some(Blend::Additive),
                xr::EnvironmentBlendMode::ALPHA_BLEND => Some(Blend::AlphaBlend),
                xr::EnvironmentBlendMode::OPAQUE => Some(Blend::Opaque),
                _ => None,
            })
            .collect();
        let blend = choose::choose_blend(&blend_modes_offered, options.blend, options.dimmer)
            .map_err(OpenXrError::Unsupported)?;
        let views = instance
            .enumerate_view_configuration_views(system, stereo)
            .xr("xrEnumerateViewConfigurationViews")?;
        if views.len() != 2 {
            return Err(OpenXrError::Unsupported(format!(
                "the stereo view configuration has {} views; expected 2",
                views.len()
            )));
        }
        let recommended_size = (
            views[0].recommended_image_rect_width,
            views[0].recommended_image_rect_height,
        );
        let max_size = (
            views[0].max_image_rect_width,
            views[0].max_image_rect_height,
        );
        let size = choose::choose_size(recommended_size, max_size, options.size);
        let reqs = instance
            .graphics_requirements::<xr::Vulkan>(system)
            .xr("xrGetVulkanGraphicsRequirements2KHR")?;
        let version = |v: xr::Version| format!("{}.{}", v.major(), v.minor());
        let info = RuntimeInfo {
            runtime: format!("{} {}", props.runtime_name, props.runtime_version),
            system: sys_props.system_name.clone(),
            extensions: enabled_names(&wanted),
            blend_modes_offered,
            blend,
            recommended_size,
            max_size,
            size,
            eye_gaze_supported: support.ext,
            fb_eye_tracking_supported: support.fb,
            ml_eye_tracker_supported: support.ml,
            vulkan_versions: (
                version(reqs.min_api_version_supported),
                version(reqs.max_api_version_supported),
            ),
        };
        tracing::info!(
            runtime = %info.runtime,
            system = %info.system,
            extensions = %info.extensions.join(" "),
            "OpenXR runtime ready"
        );
        let offered: Vec<String> = info
            .blend_modes_offered
            .iter()
            .map(ToString::to_string)
            .collect();
        tracing::info!(
            "blend mode {} ({}; offered: {})",
            info.blend,
            if options.blend.is_some() {
                "asked for"
            } else {
                "automatic choice"
            },
            offered.join(", ")
        );
        if info.blend != Blend::Additive {
            tracing::warn!(
                "the runtime offers no ADDITIVE blend mode: this is not an optical see-through \
                 display{}",
                if info.blend.needs_world_behind() {
                    "; the scene's real-world photos are drawn behind the glass"
                } else {
                    ""
                }
            );
        }
        Ok(Runtime {
            instance,
            system,
            info,
            depth_layer: wanted.khr_composition_layer_depth,
            ext_gaze: wanted.ext_eye_gaze_interaction,
            fb_gaze: wanted.fb_eye_tracking_social,
            ml_gaze,
            ml_frame_end: wanted.ml_frame_end_info,
            ml_dimmer: wanted.ml_global_dimmer,
            planes: wanted.ext_plane_detection,
            light,
            vk_instance: None,
        })
    }

    /// What the runtime offers and what was chosen.
    pub fn info(&self) -> &RuntimeInfo {
        &self.info
    }

    /// Whether XR_KHR_composition_layer_depth is enabled (depth is then submitted when the
    /// session is asked to, see [`SessionOptions::depth`]).
    pub fn depth_layer_enabled(&self) -> bool {
        self.depth_layer
    }
}

/// The renderer's Vulkan objects a session is created on.
#[derive(Clone, Copy, Debug)]
pub struct VulkanHandles {
    /// The instance made by [`Runtime::create_vulkan_instance`].
    pub instance: vk::Instance,
    /// The physical device from [`Runtime::vulkan_physical_device`].
    pub physical: vk::PhysicalDevice,
    /// The device made by [`Runtime::create_vulkan_device`].
    pub device: vk::Device,
    /// Queue family of the queue frames are submitted on.
    pub queue_family: u32,
    /// Index of that queue in its family.
    pub queue_index: u32,
}

/// How a session runs.
#[derive(Clone, Debug, Default)]
pub struct SessionOptions {
    /// End after this many rendered frames (None: until stopped).
    pub max_frames: Option<u64>,
    /// Replay gaze from this trace (by time since the first frame) when no per-eye eye
    /// tracker is available (or when `gaze` forces it).
    pub gaze_trace: Option<std::path::PathBuf>,
    /// Which gaze source to use (`--gaze`): the best offered, or a forced one.
    pub gaze: GazeChoice,
    /// Where the scene's origin (the viewer's head at start) is put relative to the first
    /// located head pose; `None` puts it exactly there (yaw only).
    pub scene_origin: Option<Pose>,
    /// Position of the viewer's head in the scene frame, metres (the scene's
    /// `viewer.head_position_m`).
    pub viewer_position_m: glam::Vec3,
    /// Install a Ctrl-C handler that ends the session cleanly.
    pub handle_ctrl_c: bool,
    /// Submit depth with XR_KHR_composition_layer_depth in this format and range, when the
    /// runtime offers the extension and the format (None: no depth submission).
    pub depth: Option<DepthOptions>,
    /// Set by the application when it is done (e.g. a study's last answer is in): the session
    /// then ends the way it does at the frame limit, through STOPPING.
    pub end: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// What a session before this one left to go on from, when the app starts a new one after
    /// a loss (`None` for the first).
    pub continued: Option<Continued>,
}

/// What a new session takes over from the one lost before it, so the app goes on where it was.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Continued {
    /// The next frame's index.
    pub next_index: u64,
    /// The first session's first predicted display time, nanoseconds: a gaze trace's clock
    /// (`--gaze-trace`) keeps running from it.
    pub first_display_ns: Option<i64>,
    /// The scene frame from app space, kept when the new session's space is a STAGE (the
    /// room's own frame, which outlives sessions); a LOCAL space is placed again.
    pub world_from_space: Option<Pose>,
    /// How long the app waited for the runtime to come back, milliseconds (the new session's
    /// first events say so: [`vitreous_trace::SessionEvent::Reconnected`]).
    pub waited_ms: u64,
    /// The frames' gaze order so far: the new session's samples are held against the newest
    /// a frame got ([`GazeOrder`]).
    pub gaze_order: GazeOrder,
    /// The newest usable display time a frame was predicted at, and when: the new session's
    /// frames must come after it, and not further ahead than the world's time moved.
    pub last_display: Option<(i64, std::time::Instant)>,
}

/// How depth is submitted (XR_KHR_composition_layer_depth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthOptions {
    /// The depth format the renderer writes (the depth swapchain's format).
    pub format: vk::Format,
    /// Distance of depth 0 (the projection's near plane), metres.
    pub near_m: f32,
    /// Distance of depth 1 (the projection's far plane), metres.
    pub far_m: f32,
}

/// The swapchain's images and format, for the renderer.
#[derive(Clone, Debug)]
pub struct SwapchainImages {
    /// The `VkImage`s, 2 layers each.
    pub images: Vec<vk::Image>,
    /// Their format.
    pub format: vk::Format,
    /// Whether the format encodes sRGB itself (else OpenXR reads its values as linear light).
    pub srgb: bool,
    /// Size of each layer, pixels.
    pub size: (u32, u32),
    /// The depth swapchain's `VkImage`s (2 layers each, [`DepthOptions::format`]), when depth
    /// is submitted; empty otherwise.
    pub depth_images: Vec<vk::Image>,
}

impl Runtime {
    /// Creates the session on the renderer's device, its spaces, swapchain and gaze source.
    ///
    /// # Safety
    /// `vulkan` must hold the handles made through this runtime; they must outlive the
    /// returned session.
    pub unsafe fn start(
        &self,
        vulkan: VulkanHandles,
        options: &SessionOptions,
    ) -> Result<(Session, SwapchainImages)> {
        // SAFETY: forwarded contract: `vulkan` holds this runtime's handles, which outlive the
        // session.
        unsafe { session::start(self, vulkan, options) }
    }
}

/// Which eye trackers the system supports, of those whose extension is enabled.
#[derive(Clone, Copy, Debug, Default)]
struct GazeSupport {
    /// XR_EXT_eye_gaze_interaction (`supportsEyeGazeInteraction`).
    ext: bool,
    /// XR_FB_eye_tracking_social (`supportsEyeTracking`).
    fb: bool,
    /// XR_ML_eye_tracker (`supportsEyeTracking`).
    ml: bool,
}

/// An extension's name as `xr::ExtensionSet::other` holds it: nul-terminated bytes.
fn nul_terminated(name: &str) -> Vec<u8> {
    let mut bytes = name.as_bytes().to_vec();
    bytes.push(0);
    bytes
}

/// Asks the system which of the enabled eye-tracking extensions it supports.
fn gaze_support(
    instance: &xr::Instance,
    system: xr::SystemId,
    ext: bool,
    fb: bool,
    ml: bool,
) -> GazeSupport {
    let mut ext_props = xr::sys::SystemEyeGazeInteractionPropertiesEXT {
        ty: xr::sys::SystemEyeGazeInteractionPropertiesEXT::TYPE,
        next: std::ptr::null_mut(),
        supports_eye_gaze_interaction: xr::sys::FALSE,
    };
    let mut fb_props = xr::sys::SystemEyeTrackingPropertiesFB {
        ty: xr::sys::SystemEyeTrackingPropertiesFB::TYPE,
        next: std::ptr::null_mut(),
        supports_eye_tracking: xr::sys::FALSE,
    };
    let mut ml_props = ml_eye_tracker::SystemEyeTrackerPropertiesML {
        ty: xr::sys::StructureType::from_raw(ml_eye_tracker::structure_type::SYSTEM_PROPERTIES),
        next: std::ptr::null_mut(),
        supports_eye_tracking: xr::sys::FALSE,
    };
    let mut next: *mut std::ffi::c_void = std::ptr::null_mut();
    if ext {
        ext_props.next = next;
        next = &mut ext_props as *mut _ as *mut _;
    }
    if fb {
        fb_props.next = next;
        next = &mut fb_props as *mut _ as *mut _;
    }
    if ml {
        ml_props.next = next;
        next = &mut ml_props as *mut _ as *mut _;
    }
    if next.is_null() {
        return GazeSupport::default();
    }
    // SAFETY: a zeroed XrSystemProperties with a valid chain of output structs that live
    // across the call.
    let ok = unsafe {
        let mut props: xr::sys::SystemProperties = std::mem::zeroed();
        props.ty = xr::sys::SystemProperties::TYPE;
        props.next = next;
        (instance.fp().get_system_properties)(instance.as_raw(), system, &mut props)
    };
    if ok != xr::sys::Result::SUCCESS {
        tracing::warn!("xrGetSystemProperties with eye-tracking properties failed: {ok}");
        return GazeSupport::default();
    }
    GazeSupport {
        ext: ext && ext_props.supports_eye_gaze_interaction == xr::sys::TRUE,
        fb: fb && fb_props.supports_eye_tracking == xr::sys::TRUE,
        ml: ml && ml_props.supports_eye_tracking == xr::sys::TRUE,
    }
}

/// The names of the extensions vitreous enables, for logs.
/// What the OpenXR loader and instance are created with on this platform: nothing on a
/// desktop.
#[cfg(not(target_os = "android"))]
fn platform_info() {}

/// What the OpenXR loader and instance are created with on Android: the Java VM and the
/// NativeActivity that the activity glue (android-activity, through winit) recorded in
/// `ndk-context` before the app's main ran.
#[cfg(target_os = "android")]
fn platform_info() -> xr::AndroidPlatformInfo {
    let context = ndk_context::android_context();
    // SAFETY: the glue stores the process's JavaVM and the activity's global reference, both
    // valid for as long as the activity lives, which outlives the app's main.
    unsafe { xr::AndroidPlatformInfo::new(context.vm(), context.context()) }
}

fn enabled_names(set: &xr::ExtensionSet) -> Vec<String> {
    let mut names = Vec::new();
    for (on, name) in [
        (set.khr_vulkan_enable2, "XR_KHR_vulkan_enable2"),
        (set.ext_eye_gaze_interaction, "XR_EXT_eye_gaze_interaction"),
        (set.fb_eye_tracking_social, "XR_FB_eye_tracking_social"),
        (
            set.khr_composition_layer_depth,
            "XR_KHR_composition_layer_depth",
        ),
        (set.ml_frame_end_info, "XR_ML_frame_end_info"),
        #[cfg(target_os = "android")]
        (
            set.khr_android_create_instance,
            "XR_KHR_android_create_instance",
        ),
        (set.ml_global_dimmer, "XR_ML_global_dimmer"),
        (set.ext_plane_detection, "XR_EXT_plane_detection"),
    ] {
        if on {
            names.push(name.to_owned());
        }
    }
    for other in &set.other {
        names.push(String::from_utf8_lossy(other.strip_suffix(&[0]).unwrap_or(other)).into_owned());
    }
    names
}
