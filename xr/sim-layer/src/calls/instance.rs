//! Instance-level calls: destroying the instance, system properties, blend modes and the
//! eye-gaze profile's bindings.

use std::ffi::c_void;

use openxr::sys::{self, Handle};
use vitreous_xr::openxr::ml_eye_tracker as ml;

use super::chain;
use crate::bindings::{self, Plan};
use crate::blend;
use crate::config::GazeExtension;
use crate::faults;
use crate::guard::guard;
use crate::registry::registry;
use crate::two_call;

/// `xrDestroyInstance`: passed on, then the layer forgets the instance (and the fault
/// schedule its sessions and whether it was lost).
///
/// # Safety
/// As `xrDestroyInstance`.
pub unsafe extern "system" fn destroy_instance(instance: sys::Instance) -> sys::Result {
    guard("xrDestroyInstance", || {
        let raw = instance.into_raw();
        let Some(next) = registry().instances.get(&raw).map(|i| i.next.clone()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function for its own live instance.
        let r = unsafe { (next.destroy_instance)(instance) };
        registry().remove_instance(raw);
        faults::with(|f| f.instance_destroyed(raw));
        r
    })
}

/// Which of the layer's system-property structures `ty` is.
fn own_property(ty: sys::StructureType) -> Option<GazeExtension> {
    if ty == sys::SystemEyeGazeInteractionPropertiesEXT::TYPE {
        Some(GazeExtension::Ext)
    } else if ty == sys::SystemEyeTrackingPropertiesFB::TYPE {
        Some(GazeExtension::Fb)
    } else if ml::structure_type::is(ty, ml::structure_type::SYSTEM_PROPERTIES) {
        Some(GazeExtension::Ml)
    } else {
        None
    }
}

/// `xrGetSystemProperties`: the layer's property structures are taken out of the chain (the
/// runtime below was not told about the extensions), the rest is filled by the runtime, then
/// the chain is restored and the layer's structures say the system has eye tracking.
///
/// # Safety
/// As `xrGetSystemProperties`.
pub unsafe extern "system" fn get_system_properties(
    instance: sys::Instance,
    system: sys::SystemId,
    properties: *mut sys::SystemProperties,
) -> sys::Result {
    guard("xrGetSystemProperties", || {
        let Some((next, owned)) = registry()
            .instances
            .get(&instance.into_raw())
            .map(|i| (i.next.clone(), i.owned.clone()))
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if properties.is_null() {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: `properties` is the app's valid output structure with a valid chain.
        let nodes = unsafe { chain((*properties).next) };
        // SAFETY: every node is a valid structure of the chain.
        let ours: Vec<bool> = nodes
            .iter()
            .map(|&n| own_property(unsafe { (*n).ty }).is_some_and(|e| owned.contains(&e)))
            .collect();
        // SAFETY: as above: reading each node's `next` to restore it afterwards.
        let saved: Vec<*mut sys::BaseOutStructure> =
            nodes.iter().map(|&n| unsafe { (*n).next }).collect();
        // Relink the chain without the layer's structures.
        let foreign: Vec<*mut sys::BaseOutStructure> = nodes
            .iter()
            .zip(&ours)
            .filter(|(_, o)| !**o)
            .map(|(n, _)| *n)
            .collect();
        // SAFETY: rewriting `next` pointers of the app's chain; restored below before return.
        unsafe {
            (*properties).next = foreign
                .first()
                .map_or(std::ptr::null_mut(), |n| *n as *mut c_void);
            for w in foreign.windows(2) {
                (*w[0]).next = w[1];
            }
            if let Some(last) = foreign.last() {
                (**last).next = std::ptr::null_mut();
            }
        }
        // SAFETY: the next layer's function with the app's structure (trimmed chain).
        let r = unsafe { (next.get_system_properties)(instance, system, properties) };
        // SAFETY: restoring the chain exactly as the app built it.
        unsafe {
            (*properties).next = nodes
                .first()
                .map_or(std::ptr::null_mut(), |n| *n as *mut c_void);
            for (n, s) in nodes.iter().zip(&saved) {
                (**n).next = *s;
            }
        }
        if r.into_raw() < 0 {
            return r;
        }
        for (&n, _) in nodes.iter().zip(&ours).filter(|(_, o)| **o) {
            // SAFETY: each node was identified by its type as one of these structures; only
            // the boolean field after `type` and `next` is written.
            unsafe {
                match own_property((*n).ty) {
                    Some(GazeExtension::Ext) => {
                        (*(n as *mut sys::SystemEyeGazeInteractionPropertiesEXT))
                            .supports_eye_gaze_interaction = sys::TRUE;
                    }
                    Some(GazeExtension::Fb) => {
                        (*(n as *mut sys::SystemEyeTrackingPropertiesFB)).supports_eye_tracking =
                            sys::TRUE;
                    }
                    Some(GazeExtension::Ml) => {
                        (*(n as *mut ml::SystemEyeTrackerPropertiesML)).supports_eye_tracking =
                            sys::TRUE;
                    }
                    None => {}
                }
            }
        }
        r
    })
}

/// `xrEnumerateEnvironmentBlendModes`: the configured modes (ADDITIVE, ALPHA_BLEND), then the
/// runtime's own.
///
/// # Safety
/// As `xrEnumerateEnvironmentBlendModes`.
pub unsafe extern "system" fn enumerate_environment_blend_modes(
    instance: sys::Instance,
    system: sys::SystemId,
    view: sys::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    modes: *mut sys::EnvironmentBlendMode,
) -> sys::Result {
    guard("xrEnumerateEnvironmentBlendModes", || {
        let Some((next, added)) = registry()
            .instances
            .get(&instance.into_raw())
            .map(|i| (i.next.clone(), i.config.blend.clone()))
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let runtime = match next.runtime_blend_modes(instance, system, view) {
            Ok(m) => m,
            Err(r) => return r,
        };
        let list = blend::offered(&added, &runtime);
        // SAFETY: the app's pointers, valid as the call defines them.
        unsafe { two_call::answer_raw(&list, capacity, count, modes) }
    })
}

/// `xrEnumerateViewConfigurationViews`: the runtime's views, each one's recommended and
/// largest image rectangle clamped to `VITREOUS_SIM_EYE_MAX` when it is set.
///
/// # Safety
/// As `xrEnumerateViewConfigurationViews`.
pub unsafe extern "system" fn enumerate_view_configuration_views(
    instance: sys::Instance,
    system: sys::SystemId,
    view: sys::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    views: *mut sys::ViewConfigurationView,
) -> sys::Result {
    guard("xrEnumerateViewConfigurationViews", || {
        let Some((next, eye_max)) = registry()
            .instances
            .get(&instance.into_raw())
            .map(|i| (i.next.clone(), i.config.eye_max))
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe {
            (next.enumerate_view_configuration_views)(
                instance, system, view, capacity, count, views,
            )
        };
        let Some(max) = eye_max else {
            return r;
        };
        if r != sys::Result::SUCCESS || count.is_null() {
            return r;
        }
        // SAFETY: `count` is the app's non-null output, which the runtime wrote.
        let filled = unsafe { *count }.min(capacity);
        // SAFETY: the app's array holds `capacity` elements (null when it asked for the
        // count), of which the runtime filled the first `count` when it had room for them.
        if let Some(slice) = unsafe { two_call::out_slice(filled, views) } {
            for v in slice {
                clamp_view(v, max);
            }
        }
        r
    })
}

/// Clamps a view's recommended and largest image rectangle to `max` (width, height).
pub fn clamp_view(view: &mut sys::ViewConfigurationView, max: (u32, u32)) {
    view.max_image_rect_width = view.max_image_rect_width.min(max.0);
    view.max_image_rect_height = view.max_image_rect_height.min(max.1);
    view.recommended_image_rect_width = view
        .recommended_image_rect_width
        .min(view.max_image_rect_width);
    view.recommended_image_rect_height = view
        .recommended_image_rect_height
        .min(view.max_image_rect_height);
}

/// `xrSuggestInteractionProfileBindings`: suggestions for the eye-gaze profile are taken
/// here (their actions become gaze actions); the rest go on.
///
/// # Safety
/// As `xrSuggestInteractionProfileBindings`.
pub unsafe extern "system" fn suggest_interaction_profile_bindings(
    instance: sys::Instance,
    suggested: *const sys::InteractionProfileSuggestedBinding,
) -> sys::Result {
    guard("xrSuggestInteractionProfileBindings", || {
        let Some((next, paths, buttons)) = registry()
            .instances
            .get(&instance.into_raw())
            .map(|i| (i.next.clone(), i.gaze_paths, i.buttons.clone()))
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let forward = || {
            // SAFETY: the next layer's function with the app's arguments.
            unsafe { (next.suggest_interaction_profile_bindings)(instance, suggested) }
        };
        if paths.is_none() && buttons.is_none() {
            return forward();
        }
        // SAFETY: the app's structure, null or valid.
        let Some(s) = (unsafe { suggested.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let list = if s.count_suggested_bindings == 0 || s.suggested_bindings.is_null() {
            &[][..]
        } else {
            // SAFETY: the app's array of `count_suggested_bindings` bindings.
            unsafe {
                std::slice::from_raw_parts(
                    s.suggested_bindings,
                    s.count_suggested_bindings as usize,
                )
            }
        };
        // Scripted inputs: their actions are answered by the layer; the suggestion still goes
        // on, so the runtime knows the actions.
        if let Some(b) = &buttons {
            let bound = b.bound(s.interaction_profile, list);
            if let Some(i) = registry().instances.get_mut(&instance.into_raw()) {
                for (action, input) in bound {
                    i.button_actions
                        .entry(action.into_raw())
                        .or_default()
                        .push(input);
                }
            }
        }
        let Some(paths) = paths else {
            return forward();
        };
        let attached = registry()
            .instances
            .get(&instance.into_raw())
            .is_some_and(|i| i.attached);
        if attached && s.interaction_profile == paths.profile {
            return sys::Result::ERROR_ACTIONSETS_ALREADY_ATTACHED;
        }
        match bindings::plan(&paths, s.interaction_profile, list) {
            Plan::Forward => forward(),
            Plan::Reject => sys::Result::ERROR_PATH_UNSUPPORTED,
            Plan::Empty => sys::Result::ERROR_VALIDATION_FAILURE,
            Plan::Absorb(actions) => {
                if let Some(i) = registry().instances.get_mut(&instance.into_raw()) {
                    i.gaze_actions.extend(actions.iter().map(|a| a.into_raw()));
                }
                sys::Result::SUCCESS
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(recommended: (u32, u32), max: (u32, u32)) -> sys::ViewConfigurationView {
        sys::ViewConfigurationView {
            ty: sys::ViewConfigurationView::TYPE,
            next: std::ptr::null_mut(),
            recommended_image_rect_width: recommended.0,
            max_image_rect_width: max.0,
            recommended_image_rect_height: recommended.1,
            max_image_rect_height: max.1,
            recommended_swapchain_sample_count: 1,
            max_swapchain_sample_count: 4,
        }
    }

    fn sizes(v: &sys::ViewConfigurationView) -> [u32; 4] {
        [
            v.recommended_image_rect_width,
            v.recommended_image_rect_height,
            v.max_image_rect_width,
            v.max_image_rect_height,
        ]
    }

    #[test]
    fn views_are_clamped_to_the_largest_eye_image_and_never_grown() {
        let mut v = view((1440, 1760), (2880, 3520));
        clamp_view(&mut v, (320, 240));
        assert_eq!(sizes(&v), [320, 240, 320, 240]);
        // Within the limit: untouched, a limit above the runtime's does not raise it.
        let mut v = view((640, 480), (1024, 768));
        clamp_view(&mut v, (2048, 600));
        assert_eq!(sizes(&v), [640, 480, 1024, 600]);
        assert_eq!(v.max_swapchain_sample_count, 4);
    }
}
