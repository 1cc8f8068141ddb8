//! XR_EXT_eye_gaze_interaction as the layer answers it for the runtime, held to the spec's
//! orders: a suggestion needs a binding and comes before attaching; a gaze action's state,
//! bound sources, their localized names and `/user/eyes_ext`'s profile are for attached action
//! sets; a bound source's localized name comes in two calls, each part asked for named as
//! `docs/sim-layer.md` gives it; a gaze space is located at valid times only, its position and
//! orientation tracked together or neither.

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
    let all = sys::InputSourceLocalizedNameFlags::USER_PATH
        | sys::InputSourceLocalizedNameFlags::INTERACTION_PROFILE
        | sys::InputSourceLocalizedNameFlags::COMPONENT;
    let mut count = 0u32;
    // SAFETY: live session, valid structure; a null buffer with capacity 0 asks for the size.
    let r = unsafe {
        (fp.get_input_source_localized_name)(
            session,
            &name_info(pose_path, all),
            0,
            &mut count,
            std::ptr::null_mut(),
        )
    };
    expect(
        "xrGetInputSourceLocalizedName(gaze pose, before attaching)",
        r,
        sys::Result::ERROR_ACTIONSET_NOT_ATTACHED,
    )?;
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
    for source in sources {
        localized_names(instance, session, source)?;
    }

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

/// A localized-name query for `source` with `which`.
fn name_info(
    source: sys::Path,
    which: sys::InputSourceLocalizedNameFlags,
) -> sys::InputSourceLocalizedNameGetInfo {
    sys::InputSourceLocalizedNameGetInfo {
        ty: sys::InputSourceLocalizedNameGetInfo::TYPE,
        next: std::ptr::null(),
        source_path: source,
        which_components: which,
    }
}

/// The localized name `info` asks for, in two calls: the size (with the terminating NUL)
/// first, a buffer one char short refused with the size again, then the text.
fn two_call_name(
    instance: &xr::Instance,
    session: sys::Session,
    info: &sys::InputSourceLocalizedNameGetInfo,
) -> Probe<String> {
    let f = instance.fp().get_input_source_localized_name;
    let call = format!(
        "xrGetInputSourceLocalizedName(whichComponents {:#x})",
        info.which_components.into_raw()
    );
    let mut size = 0u32;
    // SAFETY: live session, valid structure; a null buffer with capacity 0 asks for the size.
    check(&call, unsafe {
        f(session, info, 0, &mut size, std::ptr::null_mut())
    })?;
    if size < 2 {
        return Err(format!(
            "{call}: size {size}, expected a name and its terminating NUL"
        ));
    }
    let mut buffer = vec![1 as std::ffi::c_char; size as usize];
    let mut short = 0u32;
    // SAFETY: `buffer` holds more than the `size - 1` chars offered.
    let r = unsafe { f(session, info, size - 1, &mut short, buffer.as_mut_ptr()) };
    if r != sys::Result::ERROR_SIZE_INSUFFICIENT || short != size {
        return Err(format!(
            "{call} with {} chars for {size}: {r:?} and size {short}, the spec requires \
             ERROR_SIZE_INSUFFICIENT and {size}",
            size - 1
        ));
    }
    let mut written = 0u32;
    // SAFETY: `buffer` holds `size` writable chars.
    check(&call, unsafe {
        f(session, info, size, &mut written, buffer.as_mut_ptr())
    })?;
    let bytes: Vec<u8> = buffer.iter().map(|&c| c as u8).collect();
    match bytes.iter().position(|&b| b == 0) {
        Some(end) if written == size && end + 1 == bytes.len() => {
            String::from_utf8(bytes[..end].to_vec()).map_err(|e| format!("{call}: {e}"))
        }
        _ => Err(format!(
            "{call}: {written} chars written for size {size}, {bytes:?}: not one name ending \
             in the buffer's last char"
        )),
    }
}

/// The localized name of a gaze action's bound `source`: each part alone and all together in
/// two calls as `docs/sim-layer.md` names them; no component flag, an undefined flag and a
/// get-info of another type refused; invalid paths refused by the runtime.
fn localized_names(instance: &xr::Instance, session: sys::Session, source: sys::Path) -> Probe<()> {
    use sys::InputSourceLocalizedNameFlags as F;
    let expected = [
        (F::USER_PATH, "Eyes"),
        (F::INTERACTION_PROFILE, "Eye Gaze Interaction"),
        (F::COMPONENT, "Gaze Pose"),
        (
            F::USER_PATH | F::INTERACTION_PROFILE | F::COMPONENT,
            "Eyes Eye Gaze Interaction Gaze Pose",
        ),
    ];
    for (which, want) in expected {
        let name = two_call_name(instance, session, &name_info(source, which))?;
        if name != want {
            return Err(format!(
                "xrGetInputSourceLocalizedName(whichComponents {:#x}): {name:?}, expected \
                 {want:?}",
                which.into_raw()
            ));
        }
    }
    println!(
        "spec: the bound source's localized name: \"Eyes\", \"Eye Gaze Interaction\", \
         \"Gaze Pose\", all \"Eyes Eye Gaze Interaction Gaze Pose\" (two calls, one char short \
         refused)"
    );

    let f = instance.fp().get_input_source_localized_name;
    let mut wrong_type = name_info(source, F::USER_PATH);
    wrong_type.ty = sys::StructureType::ACTION_STATE_GET_INFO;
    let refused = [
        (
            "no component",
            name_info(source, F::EMPTY),
            sys::Result::ERROR_VALIDATION_FAILURE,
        ),
        (
            "an undefined component flag",
            name_info(source, F::USER_PATH | F::from_raw(1 << 3)),
            sys::Result::ERROR_VALIDATION_FAILURE,
        ),
        (
            "another type",
            wrong_type,
            sys::Result::ERROR_VALIDATION_FAILURE,
        ),
        (
            "XR_NULL_PATH",
            name_info(sys::Path::NULL, F::USER_PATH),
            sys::Result::ERROR_PATH_INVALID,
        ),
        (
            "path 0x1234",
            name_info(sys::Path::from_raw(0x1234), F::USER_PATH),
            sys::Result::ERROR_PATH_INVALID,
        ),
    ];
    for (what, info, want) in refused {
        let mut size = 0u32;
        // SAFETY: live session, a structure of the call's layout; capacity 0, null buffer.
        let r = unsafe { f(session, &info, 0, &mut size, std::ptr::null_mut()) };
        expect(&format!("xrGetInputSourceLocalizedName({what})"), r, want)?;
    }
    Ok(())
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
