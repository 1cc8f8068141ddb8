//! XR_EXT_eye_gaze_interaction as the layer answers it for the runtime, held to the spec's
//! orders: a suggestion needs a binding and comes before attaching; a gaze action's state,
//! bound sources and `/user/eyes_ext`'s profile are for attached action sets; a gaze space
//! is located at valid times only, its position and orientation tracked together or neither.

use openxr as xr;
use xr::sys;
use xr::sys::Handle;

use super::{Probe, check};

/// Expects `r` to be `want`, naming the call.
fn expect(call: &str, r: sys::Result, want: sys::Result) -> Probe<()> {
    if r == want {
        println!("spec: {call} -> {r:?}");
        Ok(())
    } else {
        Err(format!("{call}: {r:?}, the spec requires {want:?}"))
    }
}

/// A path from its string.
fn path(instance: &xr::Instance, s: &str) -> Probe<sys::Path> {
    instance
        .string_to_path(s)
        .map_err(|e| format!("xrStringToPath({s}): {e}"))
}

/// The gaze action, its set and its space, after attaching.
pub struct Gaze {
    /// The gaze pose action's action space.
    pub space: sys::Space,
    _action: xr::Action<xr::Posef>,
    _set: xr::ActionSet,
}

/// Runs the checks before and around attaching; returns the gaze action's space.
pub fn before_frames(instance: &xr::Instance, session: sys::Session) -> Probe<Gaze> {
    let fp = instance.fp();
    let profile = path(instance, "/interaction_profiles/ext/eye_gaze_interaction")?;
    let pose_path = path(instance, "/user/eyes_ext/input/gaze_ext/pose")?;
    let user = path(instance, "/user/eyes_ext")?;
    let set = instance
        .create_action_set("probe", "probe", 0)
        .map_err(|e| format!("xrCreateActionSet: {e}"))?;
    let action = set
        .create_action::<xr::Posef>("gaze", "gaze", &[])
        .map_err(|e| format!("xrCreateAction: {e}"))?;
    let mut suggestion = sys::InteractionProfileSuggestedBinding {
        ty: sys::InteractionProfileSuggestedBinding::TYPE,
        next: std::ptr::null(),
        interaction_profile: profile,
        count_suggested_bindings: 0,
        suggested_bindings: std::ptr::null(),
    };
    // SAFETY: live instance, valid structure (no bindings).
    let r = unsafe { (fp.suggest_interaction_profile_bindings)(instance.as_raw(), &suggestion) };
    expect(
        "xrSuggestInteractionProfileBindings(no binding)",
        r,
        sys::Result::ERROR_VALIDATION_FAILURE,
    )?;

    let get = sys::ActionStateGetInfo {
        ty: sys::ActionStateGetInfo::TYPE,
        next: std::ptr::null(),
        action: action.as_raw(),
        subaction_path: sys::Path::NULL,
    };
    let mut state = sys::ActionStatePose {
        ty: sys::ActionStatePose::TYPE,
        next: std::ptr::null_mut(),
        is_active: sys::FALSE,
    };
    // SAFETY: live session and action, valid structures.
    let r = unsafe { (fp.get_action_state_pose)(session, &get, &mut state) };
    expect(
        "xrGetActionStatePose(before attaching)",
        r,
        sys::Result::ERROR_ACTIONSET_NOT_ATTACHED,
    )?;

    let binding = sys::ActionSuggestedBinding {
        action: action.as_raw(),
        binding: pose_path,
    };
    suggestion.count_suggested_bindings = 1;
    suggestion.suggested_bindings = &binding;
    // SAFETY: live instance, valid structure and binding.
    let r = unsafe { (fp.suggest_interaction_profile_bindings)(instance.as_raw(), &suggestion) };
    check("xrSuggestInteractionProfileBindings", r)?;
    let sets = [set.as_raw()];
    let attach = sys::SessionActionSetsAttachInfo {
        ty: sys::SessionActionSetsAttachInfo::TYPE,
        next: std::ptr::null(),
        count_action_sets: 1,
        action_sets: sets.as_ptr(),
    };
    // SAFETY: live session, valid structure and set.
    check("xrAttachSessionActionSets", unsafe {
        (fp.attach_session_action_sets)(session, &attach)
    })?;
    // SAFETY: live instance, valid structure and binding.
    let r = unsafe { (fp.suggest_interaction_profile_bindings)(instance.as_raw(), &suggestion) };
    expect(
        "xrSuggestInteractionProfileBindings(after attaching)",
        r,
        sys::Result::ERROR_ACTIONSETS_ALREADY_ATTACHED,
    )?;

    // SAFETY: live session and action, valid structures.
    let r = unsafe { (fp.get_action_state_pose)(session, &get, &mut state) };
    check("xrGetActionStatePose", r)?;
    if state.is_active != sys::TRUE {
        return Err("the gaze action is not active after attaching".into());
    }
    let mut current = sys::InteractionProfileState {
        ty: sys::InteractionProfileState::TYPE,
        next: std::ptr::null_mut(),
        interaction_profile: sys::Path::NULL,
    };
    // SAFETY: live session, valid output.
    check("xrGetCurrentInteractionProfile(/user/eyes_ext)", unsafe {
        (fp.get_current_interaction_profile)(session, user, &mut current)
    })?;
    if current.interaction_profile != profile {
        return Err(format!(
            "xrGetCurrentInteractionProfile(/user/eyes_ext): {:?}, expected the eye-gaze \
             profile {profile:?}",
            current.interaction_profile
        ));
    }
    println!("spec: /user/eyes_ext's current profile is the eye-gaze profile");

    let info = sys::BoundSourcesForActionEnumerateInfo {
        ty: sys::BoundSourcesForActionEnumerateInfo::TYPE,
        next: std::ptr::null(),
        action: action.as_raw(),
    };
    let mut n = 0u32;
    // SAFETY: live session, valid structure; a null array with capacity 0 asks for the count.
    check("xrEnumerateBoundSourcesForAction", unsafe {
        (fp.enumerate_bound_sources_for_action)(session, &info, 0, &mut n, std::ptr::null_mut())
    })?;
    let mut sources = vec![sys::Path::NULL; n as usize];
    // SAFETY: `sources` holds `n` writable paths.
    check("xrEnumerateBoundSourcesForAction", unsafe {
        (fp.enumerate_bound_sources_for_action)(session, &info, n, &mut n, sources.as_mut_ptr())
    })?;
    if sources != [pose_path] {
        return Err(format!(
            "the gaze action's bound sources are {sources:?}, expected the gaze pose \
             {pose_path:?}"
        ));
    }
    println!("spec: the gaze action's bound source is the gaze pose");

    let space_info = sys::ActionSpaceCreateInfo {
        ty: sys::ActionSpaceCreateInfo::TYPE,
        next: std::ptr::null(),
        action: action.as_raw(),
        subaction_path: sys::Path::NULL,
        pose_in_action_space: sys::Posef::IDENTITY,
    };
    let mut space = sys::Space::NULL;
    // SAFETY: live session and action, valid structure and output.
    check("xrCreateActionSpace", unsafe {
        (fp.create_action_space)(session, &space_info, &mut space)
    })?;
    Ok(Gaze {
        space,
        _action: action,
        _set: set,
    })
}

/// Locates the gaze space in `base` at time 0 (refused) and at a frame's `time`.
pub fn locate(
    instance: &xr::Instance,
    gaze: &Gaze,
    base: sys::Space,
    time: sys::Time,
) -> Probe<()> {
    let fp = instance.fp();
    let mut location = sys::SpaceLocation {
        ty: sys::SpaceLocation::TYPE,
        next: std::ptr::null_mut(),
        location_flags: sys::SpaceLocationFlags::EMPTY,
        pose: sys::Posef::IDENTITY,
    };
    // SAFETY: live spaces, valid output.
    let r = unsafe { (fp.locate_space)(gaze.space, base, sys::Time::from_nanos(0), &mut location) };
    expect(
        "xrLocateSpace(gaze, time 0)",
        r,
        sys::Result::ERROR_TIME_INVALID,
    )?;
    // SAFETY: live spaces, valid output.
    check("xrLocateSpace(gaze)", unsafe {
        (fp.locate_space)(gaze.space, base, time, &mut location)
    })?;
    let f = location.location_flags;
    let position = f.contains(sys::SpaceLocationFlags::POSITION_TRACKED);
    let orientation = f.contains(sys::SpaceLocationFlags::ORIENTATION_TRACKED);
    if position != orientation {
        return Err(format!(
            "the gaze space's flags {f:?} track the position ({position}) and the orientation \
             ({orientation}) apart: XR_EXT_eye_gaze_interaction requires both or neither"
        ));
    }
    println!(
        "spec: gaze space flags {:#x} (tracked: both or neither)",
        f.into_raw()
    );
    Ok(())
}
