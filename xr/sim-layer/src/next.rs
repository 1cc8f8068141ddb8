//! The next layer's (or the runtime's) functions that the layer calls, loaded once per
//! instance through the next `xrGetInstanceProcAddr`.

use std::ffi::CStr;

use openxr::sys::{self, pfn};

/// The functions of the next layer down the chain that this layer calls.
#[derive(Clone, Copy)]
pub struct NextTable {
    /// `xrGetInstanceProcAddr`: everything the layer does not handle goes here.
    pub get_instance_proc_addr: pfn::GetInstanceProcAddr,
    /// `xrDestroyInstance`.
    pub destroy_instance: pfn::DestroyInstance,
    /// `xrGetSystemProperties`.
    pub get_system_properties: pfn::GetSystemProperties,
    /// `xrEnumerateEnvironmentBlendModes`.
    pub enumerate_environment_blend_modes: pfn::EnumerateEnvironmentBlendModes,
    /// `xrEnumerateViewConfigurationViews`.
    pub enumerate_view_configuration_views: pfn::EnumerateViewConfigurationViews,
    /// `xrStringToPath`.
    pub string_to_path: pfn::StringToPath,
    /// `xrCreateSession`.
    pub create_session: pfn::CreateSession,
    /// `xrDestroySession`.
    pub destroy_session: pfn::DestroySession,
    /// `xrBeginSession`.
    pub begin_session: pfn::BeginSession,
    /// `xrWaitFrame`.
    pub wait_frame: pfn::WaitFrame,
    /// `xrEndFrame`.
    pub end_frame: pfn::EndFrame,
    /// `xrCreateReferenceSpace`.
    pub create_reference_space: pfn::CreateReferenceSpace,
    /// `xrCreateActionSpace`.
    pub create_action_space: pfn::CreateActionSpace,
    /// `xrLocateSpace`.
    pub locate_space: pfn::LocateSpace,
    /// `xrDestroySpace`.
    pub destroy_space: pfn::DestroySpace,
    /// `xrSuggestInteractionProfileBindings`.
    pub suggest_interaction_profile_bindings: pfn::SuggestInteractionProfileBindings,
    /// `xrGetActionStatePose`.
    pub get_action_state_pose: pfn::GetActionStatePose,
    /// `xrGetActionStateBoolean`.
    pub get_action_state_boolean: pfn::GetActionStateBoolean,
    /// `xrAttachSessionActionSets`.
    pub attach_session_action_sets: pfn::AttachSessionActionSets,
    /// `xrGetCurrentInteractionProfile`.
    pub get_current_interaction_profile: pfn::GetCurrentInteractionProfile,
    /// `xrEnumerateBoundSourcesForAction`.
    pub enumerate_bound_sources_for_action: pfn::EnumerateBoundSourcesForAction,
    /// `xrGetInputSourceLocalizedName`.
    pub get_input_source_localized_name: pfn::GetInputSourceLocalizedName,
    /// `xrSyncActions`.
    pub sync_actions: pfn::SyncActions,
    /// `xrEnumerateSwapchainFormats`.
    pub enumerate_swapchain_formats: pfn::EnumerateSwapchainFormats,
    /// `xrCreateSwapchain`.
    pub create_swapchain: pfn::CreateSwapchain,
    /// `xrDestroySwapchain`.
    pub destroy_swapchain: pfn::DestroySwapchain,
    /// `xrEnumerateSwapchainImages`.
    pub enumerate_swapchain_images: pfn::EnumerateSwapchainImages,
    /// `xrAcquireSwapchainImage`.
    pub acquire_swapchain_image: pfn::AcquireSwapchainImage,
    /// `xrReleaseSwapchainImage`.
    pub release_swapchain_image: pfn::ReleaseSwapchainImage,
    /// `xrWaitSwapchainImage`.
    pub wait_swapchain_image: pfn::WaitSwapchainImage,
    /// `xrBeginFrame`.
    pub begin_frame: pfn::BeginFrame,
    /// `xrEndSession`.
    pub end_session: pfn::EndSession,
    /// `xrRequestExitSession`.
    pub request_exit_session: pfn::RequestExitSession,
    /// `xrPollEvent`.
    pub poll_event: pfn::PollEvent,
    /// `xrGetSystem`.
    pub get_system: pfn::GetSystem,
    /// `xrLocateViews`.
    pub locate_views: pfn::LocateViews,
}

/// Looks up one function through `gipa`.
///
/// # Safety
/// `gipa` must be a valid `xrGetInstanceProcAddr` and `instance` a live instance of its chain.
unsafe fn lookup(
    gipa: pfn::GetInstanceProcAddr,
    instance: sys::Instance,
    name: &CStr,
) -> Result<pfn::VoidFunction, String> {
    let mut f: Option<pfn::VoidFunction> = None;
    // SAFETY: guaranteed by the caller; `name` is NUL-terminated and `f` is writable.
    let r = unsafe { gipa(instance, name.as_ptr(), &mut f) };
    match f {
        Some(f) if r == sys::Result::SUCCESS => Ok(f),
        _ => Err(format!(
            "the next layer has no {} ({r:?})",
            name.to_string_lossy()
        )),
    }
}

/// Loads `$name` as the function pointer type `$ty`.
macro_rules! load {
    ($gipa:expr, $instance:expr, $name:literal, $ty:ty) => {{
        // SAFETY: the caller of `NextTable::load` guarantees `$gipa` and `$instance`.
        let f = unsafe { lookup($gipa, $instance, $name)? };
        // SAFETY: the loader interface returns, under this name, a function with the
        // signature OpenXR defines for it, which is the type of the field being set.
        unsafe { std::mem::transmute::<pfn::VoidFunction, $ty>(f) }
    }};
}

impl NextTable {
    /// Loads the table from the next layer.
    ///
    /// # Safety
    /// `gipa` must be the next layer's `xrGetInstanceProcAddr` and `instance` an instance
    /// it created that is still alive.
    pub unsafe fn load(
        gipa: pfn::GetInstanceProcAddr,
        instance: sys::Instance,
    ) -> Result<NextTable, String> {
        Ok(NextTable {
            get_instance_proc_addr: gipa,
            destroy_instance: load!(gipa, instance, c"xrDestroyInstance", pfn::DestroyInstance),
            get_system_properties: load!(
                gipa,
                instance,
                c"xrGetSystemProperties",
                pfn::GetSystemProperties
            ),
            enumerate_environment_blend_modes: load!(
                gipa,
                instance,
                c"xrEnumerateEnvironmentBlendModes",
                pfn::EnumerateEnvironmentBlendModes
            ),
            enumerate_view_configuration_views: load!(
                gipa,
                instance,
                c"xrEnumerateViewConfigurationViews",
                pfn::EnumerateViewConfigurationViews
            ),
            string_to_path: load!(gipa, instance, c"xrStringToPath", pfn::StringToPath),
            create_session: load!(gipa, instance, c"xrCreateSession", pfn::CreateSession),
            destroy_session: load!(gipa, instance, c"xrDestroySession", pfn::DestroySession),
            begin_session: load!(gipa, instance, c"xrBeginSession", pfn::BeginSession),
            wait_frame: load!(gipa, instance, c"xrWaitFrame", pfn::WaitFrame),
            end_frame: load!(gipa, instance, c"xrEndFrame", pfn::EndFrame),
            create_reference_space: load!(
                gipa,
                instance,
                c"xrCreateReferenceSpace",
                pfn::CreateReferenceSpace
            ),
            create_action_space: load!(
                gipa,
                instance,
                c"xrCreateActionSpace",
                pfn::CreateActionSpace
            ),
            locate_space: load!(gipa, instance, c"xrLocateSpace", pfn::LocateSpace),
            destroy_space: load!(gipa, instance, c"xrDestroySpace", pfn::DestroySpace),
            suggest_interaction_profile_bindings: load!(
                gipa,
                instance,
                c"xrSuggestInteractionProfileBindings",
                pfn::SuggestInteractionProfileBindings
            ),
            get_action_state_pose: load!(
                gipa,
                instance,
                c"xrGetActionStatePose",
                pfn::GetActionStatePose
            ),
            get_action_state_boolean: load!(
                gipa,
                instance,
                c"xrGetActionStateBoolean",
                pfn::GetActionStateBoolean
            ),
            sync_actions: load!(gipa, instance, c"xrSyncActions", pfn::SyncActions),
            enumerate_swapchain_formats: load!(
                gipa,
                instance,
                c"xrEnumerateSwapchainFormats",
                pfn::EnumerateSwapchainFormats
            ),
            create_swapchain: load!(gipa, instance, c"xrCreateSwapchain", pfn::CreateSwapchain),
            destroy_swapchain: load!(gipa, instance, c"xrDestroySwapchain", pfn::DestroySwapchain),
            enumerate_swapchain_images: load!(
                gipa,
                instance,
                c"xrEnumerateSwapchainImages",
                pfn::EnumerateSwapchainImages
            ),
            acquire_swapchain_image: load!(
                gipa,
                instance,
                c"xrAcquireSwapchainImage",
                pfn::AcquireSwapchainImage
            ),
            release_swapchain_image: load!(
                gipa,
                instance,
                c"xrReleaseSwapchainImage",
                pfn::ReleaseSwapchainImage
            ),
            attach_session_action_sets: load!(
                gipa,
                instance,
                c"xrAttachSessionActionSets",
                pfn::AttachSessionActionSets
            ),
            get_current_interaction_profile: load!(
                gipa,
                instance,
                c"xrGetCurrentInteractionProfile",
                pfn::GetCurrentInteractionProfile
            ),
            enumerate_bound_sources_for_action: load!(
                gipa,
                instance,
                c"xrEnumerateBoundSourcesForAction",
                pfn::EnumerateBoundSourcesForAction
            ),
            get_input_source_localized_name: load!(
                gipa,
                instance,
                c"xrGetInputSourceLocalizedName",
                pfn::GetInputSourceLocalizedName
            ),
            wait_swapchain_image: load!(
                gipa,
                instance,
                c"xrWaitSwapchainImage",
                pfn::WaitSwapchainImage
            ),
            begin_frame: load!(gipa, instance, c"xrBeginFrame", pfn::BeginFrame),
            end_session: load!(gipa, instance, c"xrEndSession", pfn::EndSession),
            request_exit_session: load!(
                gipa,
                instance,
                c"xrRequestExitSession",
                pfn::RequestExitSession
            ),
            poll_event: load!(gipa, instance, c"xrPollEvent", pfn::PollEvent),
            get_system: load!(gipa, instance, c"xrGetSystem", pfn::GetSystem),
            locate_views: load!(gipa, instance, c"xrLocateViews", pfn::LocateViews),
        })
    }

    /// The runtime's blend modes for a system and view configuration (two calls).
    pub fn runtime_blend_modes(
        &self,
        instance: sys::Instance,
        system: sys::SystemId,
        view: sys::ViewConfigurationType,
    ) -> Result<Vec<sys::EnvironmentBlendMode>, sys::Result> {
        let mut n = 0u32;
        // SAFETY: the table was loaded for `instance`'s chain; a null array with capacity 0
        // asks for the count.
        let r = unsafe {
            (self.enumerate_environment_blend_modes)(
                instance,
                system,
                view,
                0,
                &mut n,
                std::ptr::null_mut(),
            )
        };
        if r.into_raw() < 0 {
            return Err(r);
        }
        let mut modes = vec![sys::EnvironmentBlendMode::OPAQUE; n as usize];
        // SAFETY: `modes` holds `n` writable elements.
        let r = unsafe {
            (self.enumerate_environment_blend_modes)(
                instance,
                system,
                view,
                n,
                &mut n,
                modes.as_mut_ptr(),
            )
        };
        if r.into_raw() < 0 {
            return Err(r);
        }
        modes.truncate(n as usize);
        Ok(modes)
    }

    /// The runtime's swapchain formats for a session, in its order of preference (two calls).
    pub fn runtime_swapchain_formats(
        &self,
        session: sys::Session,
    ) -> Result<Vec<i64>, sys::Result> {
        let mut n = 0u32;
        // SAFETY: the table was loaded for the chain of `session`'s instance; a null array
        // with capacity 0 asks for the count.
        let r =
            unsafe { (self.enumerate_swapchain_formats)(session, 0, &mut n, std::ptr::null_mut()) };
        if r.into_raw() < 0 {
            return Err(r);
        }
        let mut formats = vec![0i64; n as usize];
        // SAFETY: `formats` holds `n` writable elements.
        let r =
            unsafe { (self.enumerate_swapchain_formats)(session, n, &mut n, formats.as_mut_ptr()) };
        if r.into_raw() < 0 {
            return Err(r);
        }
        formats.truncate(n as usize);
        Ok(formats)
    }
}
