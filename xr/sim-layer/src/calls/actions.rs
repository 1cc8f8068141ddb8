//! The eye-gaze profile's action calls, answered as the spec orders them for a profile the
//! runtime below does not know: attaching is passed on and remembered (a suggestion after it
//! is refused, a gaze action's state before it too), `/user/eyes_ext`'s current interaction
//! profile is the gaze profile once a gaze binding is attached, a gaze action's bound source
//! is the gaze pose, and the gaze pose's localized name is the layer's. Everything else goes
//! to the runtime.

use openxr::sys::{self, Handle};

use crate::bindings;
use crate::guard::guard;
use crate::registry::registry;
use crate::two_call;

/// `xrAttachSessionActionSets`: passed on; on success the session and its instance are marked
/// attached.
///
/// # Safety
/// As `xrAttachSessionActionSets`.
pub unsafe extern "system" fn attach_session_action_sets(
    session: sys::Session,
    info: *const sys::SessionActionSetsAttachInfo,
) -> sys::Result {
    guard("xrAttachSessionActionSets", || {
        let Some(next) = registry()
            .session(session.into_raw())
            .map(|(_, i)| i.next.clone())
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.attach_session_action_sets)(session, info) };
        if r.into_raw() >= 0 {
            let mut reg = registry();
            if let Some(s) = reg.sessions.get_mut(&session.into_raw()) {
                s.attached = true;
                let instance = s.instance;
                if let Some(i) = reg.instances.get_mut(&instance) {
                    i.attached = true;
                }
            }
        }
        r
    })
}

/// `xrGetCurrentInteractionProfile`: for `/user/eyes_ext` (XR_EXT_eye_gaze_interaction from
/// the layer), the gaze profile once a gaze binding was suggested and the action sets
/// attached, else `XR_NULL_PATH`; `XR_ERROR_ACTIONSET_NOT_ATTACHED` before attaching. Other
/// paths go to the runtime.
///
/// # Safety
/// As `xrGetCurrentInteractionProfile`.
pub unsafe extern "system" fn get_current_interaction_profile(
    session: sys::Session,
    top_level_user_path: sys::Path,
    state: *mut sys::InteractionProfileState,
) -> sys::Result {
    guard("xrGetCurrentInteractionProfile", || {
        let Some((next, paths, bound, attached)) =
            registry().session(session.into_raw()).map(|(s, i)| {
                (
                    i.next.clone(),
                    i.gaze_paths,
                    !i.gaze_actions.is_empty(),
                    s.attached,
                )
            })
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let Some(paths) = paths.filter(|p| p.user == top_level_user_path) else {
            // SAFETY: the next layer's function with the app's arguments.
            return unsafe {
                (next.get_current_interaction_profile)(session, top_level_user_path, state)
            };
        };
        // SAFETY: the app's output structure, null or valid.
        let Some(out) = (unsafe { state.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !attached {
            return sys::Result::ERROR_ACTIONSET_NOT_ATTACHED;
        }
        out.interaction_profile = if bound {
            paths.profile
        } else {
            sys::Path::NULL
        };
        sys::Result::SUCCESS
    })
}

/// `xrEnumerateBoundSourcesForAction`: a gaze action's one source is the gaze pose
/// (`XR_ERROR_ACTIONSET_NOT_ATTACHED` before attaching); other actions go to the runtime.
///
/// # Safety
/// As `xrEnumerateBoundSourcesForAction`.
pub unsafe extern "system" fn enumerate_bound_sources_for_action(
    session: sys::Session,
    info: *const sys::BoundSourcesForActionEnumerateInfo,
    capacity: u32,
    count_out: *mut u32,
    sources: *mut sys::Path,
) -> sys::Result {
    guard("xrEnumerateBoundSourcesForAction", || {
        let Some((next, paths, gaze_actions, attached)) =
            registry().session(session.into_raw()).map(|(s, i)| {
                (
                    i.next.clone(),
                    i.gaze_paths,
                    i.gaze_actions.clone(),
                    s.attached,
                )
            })
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's input structure, null or valid.
        let action = unsafe { info.as_ref() }.map(|i| i.action.into_raw());
        let Some(paths) = paths.filter(|_| action.is_some_and(|a| gaze_actions.contains(&a)))
        else {
            // SAFETY: the next layer's function with the app's arguments.
            return unsafe {
                (next.enumerate_bound_sources_for_action)(
                    session, info, capacity, count_out, sources,
                )
            };
        };
        if !attached {
            return sys::Result::ERROR_ACTIONSET_NOT_ATTACHED;
        }
        // SAFETY: the app's count output and array of `capacity` paths, null or valid.
        let (count_out, out) =
            unsafe { (count_out.as_mut(), two_call::out_slice(capacity, sources)) };
        two_call::answer(&[paths.pose], capacity, count_out, out)
    })
}

/// `xrGetInputSourceLocalizedName`: the gaze pose's name (XR_EXT_eye_gaze_interaction from the
/// layer) is the layer's ([`bindings::localized_name`]), in two calls whose count includes the
/// terminating NUL. A get-info of another type or with no (or an undefined) component flag is
/// `XR_ERROR_VALIDATION_FAILURE`, a call before the session's action sets were attached
/// `XR_ERROR_ACTIONSET_NOT_ATTACHED`. Other sources (an invalid path among them) go to the
/// runtime.
///
/// # Safety
/// As `xrGetInputSourceLocalizedName`.
pub unsafe extern "system" fn get_input_source_localized_name(
    session: sys::Session,
    info: *const sys::InputSourceLocalizedNameGetInfo,
    capacity: u32,
    count_out: *mut u32,
    buffer: *mut std::ffi::c_char,
) -> sys::Result {
    guard("xrGetInputSourceLocalizedName", || {
        let Some((next, paths, attached)) = registry()
            .session(session.into_raw())
            .map(|(s, i)| (i.next.clone(), i.gaze_paths, s.attached))
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's input structure, null or valid.
        let get = unsafe { info.as_ref() };
        let Some(get) = get.filter(|g| paths.is_some_and(|p| p.pose == g.source_path)) else {
            // SAFETY: the next layer's function with the app's arguments.
            return unsafe {
                (next.get_input_source_localized_name)(session, info, capacity, count_out, buffer)
            };
        };
        if get.ty != sys::InputSourceLocalizedNameGetInfo::TYPE {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        if !attached {
            return sys::Result::ERROR_ACTIONSET_NOT_ATTACHED;
        }
        let name = match bindings::localized_name(get.which_components) {
            Ok(name) => name,
            Err(r) => return r,
        };
        let text = nul_terminated(&name);
        // SAFETY: the app's count output, null or writable, and buffer of `capacity` chars,
        // null or writable.
        unsafe { two_call::answer_raw(&text, capacity, count_out, buffer) }
    })
}

/// `s` as C chars with the terminating NUL, as a two-call string answer counts them.
fn nul_terminated(s: &str) -> Vec<std::ffi::c_char> {
    s.bytes()
        .chain(std::iter::once(0))
        .map(|b| b as std::ffi::c_char)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_is_counted_with_its_nul() {
        let text = nul_terminated("Eyes");
        assert_eq!(text.len(), 5);
        assert_eq!(text.last(), Some(&0));
        let mut n = 0;
        let mut out: [std::ffi::c_char; 4] = [7; 4];
        // SAFETY: `n` is writable; `out` holds 4 chars.
        let r = unsafe { two_call::answer_raw(&text, 4, &mut n, out.as_mut_ptr()) };
        assert_eq!(
            (r, n, out),
            (sys::Result::ERROR_SIZE_INSUFFICIENT, 5, [7; 4])
        );
        let mut full: [std::ffi::c_char; 5] = [7; 5];
        // SAFETY: `n` is writable; `full` holds 5 chars.
        let r = unsafe { two_call::answer_raw(&text, 5, &mut n, full.as_mut_ptr()) };
        assert_eq!((r, n), (sys::Result::SUCCESS, 5));
        assert_eq!(full.map(|c| c as u8), *b"Eyes\0");
    }
}
