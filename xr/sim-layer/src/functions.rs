//! The layer's own functions by name, as its `xrGetInstanceProcAddr` hands them out: the
//! core and eye-tracking calls it answers (with the extension each needs), and those of
//! XR_EXT_plane_detection and XR_ML_light_estimation.

use openxr::sys::pfn;
use vitreous_xr::openxr::ml_eye_tracker as ml;

use crate::calls;
use crate::config::GazeExtension;

/// Casts one of the layer's entry points to the loader's generic function type.
macro_rules! entry {
    ($f:expr, $ty:ty) => {{
        let f: $ty = $f;
        // SAFETY: function pointers have one size; the caller casts it back to `$ty`, the
        // type OpenXR defines for the name it asked for.
        Some(unsafe { std::mem::transmute::<$ty, pfn::VoidFunction>(f) })
    }};
}

/// The layer's XR_EXT_plane_detection function of that name, if it is one.
pub fn plane_function(name: &[u8]) -> Option<Option<pfn::VoidFunction>> {
    use calls::planes;
    Some(match name {
        b"xrCreatePlaneDetectorEXT" => {
            entry!(planes::create_plane_detector, pfn::CreatePlaneDetectorEXT)
        }
        b"xrDestroyPlaneDetectorEXT" => {
            entry!(planes::destroy_plane_detector, pfn::DestroyPlaneDetectorEXT)
        }
        b"xrBeginPlaneDetectionEXT" => {
            entry!(planes::begin_plane_detection, pfn::BeginPlaneDetectionEXT)
        }
        b"xrGetPlaneDetectionStateEXT" => entry!(
            planes::get_plane_detection_state,
            pfn::GetPlaneDetectionStateEXT
        ),
        b"xrGetPlaneDetectionsEXT" => {
            entry!(planes::get_plane_detections, pfn::GetPlaneDetectionsEXT)
        }
        b"xrGetPlanePolygonBufferEXT" => entry!(
            planes::get_plane_polygon_buffer,
            pfn::GetPlanePolygonBufferEXT
        ),
        _ => return None,
    })
}

/// The layer's XR_ML_light_estimation function of that name, if it is one.
pub fn light_function(name: &[u8]) -> Option<Option<pfn::VoidFunction>> {
    use calls::light;
    use vitreous_xr::openxr::ml_light_estimation as ml;
    Some(match name {
        b"xrCreateLightEstimationML" => {
            entry!(light::create_light_estimation, ml::CreateLightEstimationML)
        }
        b"xrDestroyLightEstimationML" => {
            entry!(
                light::destroy_light_estimation,
                ml::DestroyLightEstimationML
            )
        }
        b"xrGetLightEstimationStateML" => {
            entry!(
                light::get_light_estimation_state,
                ml::GetLightEstimationStateML
            )
        }
        b"xrCreateLightEstimationEstimateML" => entry!(
            light::create_light_estimation_estimate,
            ml::CreateLightEstimationEstimateML
        ),
        b"xrDestroyLightEstimationEstimateML" => entry!(
            light::destroy_light_estimation_estimate,
            ml::DestroyLightEstimationEstimateML
        ),
        b"xrGetLightEstimationTimestampML" => entry!(
            light::get_light_estimation_timestamp,
            ml::GetLightEstimationTimestampML
        ),
        b"xrGetLightEstimationHDRCubemapML" => {
            entry!(light::get_hdr_cubemap, ml::GetLightEstimationHdrCubemapML)
        }
        b"xrGetLightEstimationMainDirectionalLightML" => entry!(
            light::get_main_directional_light,
            ml::GetLightEstimationMainDirectionalLightML
        ),
        b"xrGetLightEstimationSphericalHarmonicsML" => entry!(
            light::get_spherical_harmonics,
            ml::GetLightEstimationSphericalHarmonicsML
        ),
        _ => return None,
    })
}

/// The layer's own function for `name`, and the extension the app must have enabled for it
/// (`None`: core); `xrGetInstanceProcAddr` itself is `crate::entry`'s.
pub fn own_function(name: &[u8]) -> Option<(Option<GazeExtension>, Option<pfn::VoidFunction>)> {
    use GazeExtension::{Fb, Ml};
    let f = match name {
        b"xrDestroyInstance" => (
            None,
            entry!(calls::instance::destroy_instance, pfn::DestroyInstance),
        ),
        b"xrGetSystemProperties" => (
            None,
            entry!(
                calls::instance::get_system_properties,
                pfn::GetSystemProperties
            ),
        ),
        b"xrEnumerateEnvironmentBlendModes" => (
            None,
            entry!(
                calls::instance::enumerate_environment_blend_modes,
                pfn::EnumerateEnvironmentBlendModes
            ),
        ),
        b"xrEnumerateViewConfigurationViews" => (
            None,
            entry!(
                calls::instance::enumerate_view_configuration_views,
                pfn::EnumerateViewConfigurationViews
            ),
        ),
        b"xrSuggestInteractionProfileBindings" => (
            None,
            entry!(
                calls::instance::suggest_interaction_profile_bindings,
                pfn::SuggestInteractionProfileBindings
            ),
        ),
        b"xrCreateSession" => (
            None,
            entry!(calls::session::create_session, pfn::CreateSession),
        ),
        b"xrDestroySession" => (
            None,
            entry!(calls::session::destroy_session, pfn::DestroySession),
        ),
        b"xrBeginSession" => (
            None,
            entry!(calls::lifecycle::begin_session, pfn::BeginSession),
        ),
        b"xrEndSession" => (None, entry!(calls::lifecycle::end_session, pfn::EndSession)),
        b"xrRequestExitSession" => (
            None,
            entry!(
                calls::lifecycle::request_exit_session,
                pfn::RequestExitSession
            ),
        ),
        b"xrPollEvent" => (None, entry!(calls::lifecycle::poll_event, pfn::PollEvent)),
        b"xrGetSystem" => (None, entry!(calls::lifecycle::get_system, pfn::GetSystem)),
        b"xrWaitFrame" => (None, entry!(calls::lifecycle::wait_frame, pfn::WaitFrame)),
        b"xrBeginFrame" => (None, entry!(calls::lifecycle::begin_frame, pfn::BeginFrame)),
        b"xrLocateViews" => (
            None,
            entry!(calls::tracking::locate_views, pfn::LocateViews),
        ),
        b"xrWaitSwapchainImage" => (
            None,
            entry!(
                calls::swapchain::wait_swapchain_image,
                pfn::WaitSwapchainImage
            ),
        ),
        b"xrEnumerateSwapchainFormats" => (
            None,
            entry!(
                calls::swapchain::enumerate_swapchain_formats,
                pfn::EnumerateSwapchainFormats
            ),
        ),
        b"xrCreateSwapchain" => (
            None,
            entry!(calls::swapchain::create_swapchain, pfn::CreateSwapchain),
        ),
        b"xrDestroySwapchain" => (
            None,
            entry!(calls::swapchain::destroy_swapchain, pfn::DestroySwapchain),
        ),
        b"xrEnumerateSwapchainImages" => (
            None,
            entry!(
                calls::swapchain::enumerate_swapchain_images,
                pfn::EnumerateSwapchainImages
            ),
        ),
        b"xrAcquireSwapchainImage" => (
            None,
            entry!(
                calls::swapchain::acquire_swapchain_image,
                pfn::AcquireSwapchainImage
            ),
        ),
        b"xrReleaseSwapchainImage" => (
            None,
            entry!(
                calls::swapchain::release_swapchain_image,
                pfn::ReleaseSwapchainImage
            ),
        ),
        b"xrEndFrame" => (None, entry!(calls::session::end_frame, pfn::EndFrame)),
        b"xrCreateReferenceSpace" => (
            None,
            entry!(
                calls::spaces::create_reference_space,
                pfn::CreateReferenceSpace
            ),
        ),
        b"xrCreateActionSpace" => (
            None,
            entry!(calls::spaces::create_action_space, pfn::CreateActionSpace),
        ),
        b"xrLocateSpace" => (None, entry!(calls::spaces::locate_space, pfn::LocateSpace)),
        b"xrDestroySpace" => (
            None,
            entry!(calls::spaces::destroy_space, pfn::DestroySpace),
        ),
        b"xrSyncActions" => (
            None,
            entry!(calls::controller::sync_actions, pfn::SyncActions),
        ),
        b"xrGetActionStateBoolean" => (
            None,
            entry!(
                calls::controller::get_action_state_boolean,
                pfn::GetActionStateBoolean
            ),
        ),
        b"xrAttachSessionActionSets" => (
            None,
            entry!(
                calls::actions::attach_session_action_sets,
                pfn::AttachSessionActionSets
            ),
        ),
        b"xrGetCurrentInteractionProfile" => (
            None,
            entry!(
                calls::actions::get_current_interaction_profile,
                pfn::GetCurrentInteractionProfile
            ),
        ),
        b"xrEnumerateBoundSourcesForAction" => (
            None,
            entry!(
                calls::actions::enumerate_bound_sources_for_action,
                pfn::EnumerateBoundSourcesForAction
            ),
        ),
        // Core, so always the layer's; it answers only for the gaze pose while the app has
        // XR_EXT_eye_gaze_interaction from the layer, and passes every other call on.
        b"xrGetInputSourceLocalizedName" => (
            None,
            entry!(
                calls::actions::get_input_source_localized_name,
                pfn::GetInputSourceLocalizedName
            ),
        ),
        b"xrGetActionStatePose" => (
            None,
            entry!(
                calls::spaces::get_action_state_pose,
                pfn::GetActionStatePose
            ),
        ),
        b"xrCreateEyeTrackerFB" => (
            Some(Fb),
            entry!(calls::fb::create_eye_tracker, pfn::CreateEyeTrackerFB),
        ),
        b"xrDestroyEyeTrackerFB" => (
            Some(Fb),
            entry!(calls::fb::destroy_eye_tracker, pfn::DestroyEyeTrackerFB),
        ),
        b"xrGetEyeGazesFB" => (
            Some(Fb),
            entry!(calls::fb::get_eye_gazes, pfn::GetEyeGazesFB),
        ),
        b"xrCreateEyeTrackerML" => (
            Some(Ml),
            entry!(calls::ml::create_eye_tracker, ml::CreateEyeTrackerML),
        ),
        b"xrDestroyEyeTrackerML" => (
            Some(Ml),
            entry!(calls::ml::destroy_eye_tracker, ml::DestroyEyeTrackerML),
        ),
        b"xrGetEyeTrackerStaticDataML" => (
            Some(Ml),
            entry!(calls::ml::get_static_data, ml::GetEyeTrackerStaticDataML),
        ),
        b"xrGetEyeTrackerPosesML" => (
            Some(Ml),
            entry!(calls::ml::get_poses, ml::GetEyeTrackerPosesML),
        ),
        b"xrGetEyeTrackerPupilDataML" => (
            Some(Ml),
            entry!(calls::ml::get_pupil_data, ml::GetEyeTrackerPupilDataML),
        ),
        b"xrGetEyeTrackerGeometricDataML" => (
            Some(Ml),
            entry!(
                calls::ml::get_geometric_data,
                ml::GetEyeTrackerGeometricDataML
            ),
        ),
        b"xrGetEyeTrackerGazeBehaviorML" => (
            Some(Ml),
            entry!(
                calls::ml::get_gaze_behavior,
                ml::GetEyeTrackerGazeBehaviorML
            ),
        ),
        _ => return None,
    };
    Some(f)
}
