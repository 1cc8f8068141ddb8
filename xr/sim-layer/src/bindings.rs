//! Suggested bindings of the eye-gaze interaction profile: the layer takes them (the runtime
//! has no such device, or does not know the profile once the extension is removed from the
//! instance) and remembers which actions they bind; and the name of the profile's one input
//! as `xrGetInputSourceLocalizedName` gives it.

use openxr::sys;

/// What to do with one `xrSuggestInteractionProfileBindings` call.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Plan {
    /// Not the eye-gaze profile: pass the call on unchanged.
    Forward,
    /// The eye-gaze profile with only the gaze pose bound: answer it here; these actions are
    /// now gaze actions.
    Absorb(Vec<sys::Action>),
    /// The eye-gaze profile with a binding path the profile does not have.
    Reject,
    /// The eye-gaze profile with no binding at all (the spec requires at least one).
    Empty,
}

/// The paths that identify the profile and its one input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GazePaths {
    /// `/interaction_profiles/ext/eye_gaze_interaction`.
    pub profile: sys::Path,
    /// `/user/eyes_ext/input/gaze_ext/pose`.
    pub pose: sys::Path,
    /// `/user/eyes_ext`, the profile's top-level user path.
    pub user: sys::Path,
}

/// The profile's path.
pub const PROFILE: &std::ffi::CStr = c"/interaction_profiles/ext/eye_gaze_interaction";
/// The gaze pose input's path.
pub const POSE: &std::ffi::CStr = c"/user/eyes_ext/input/gaze_ext/pose";
/// The profile's top-level user path.
pub const USER: &std::ffi::CStr = c"/user/eyes_ext";

/// The user path's part of the gaze pose's localized name (`/user/eyes_ext`).
pub const USER_NAME: &str = "Eyes";
/// The interaction profile's part of the gaze pose's localized name.
pub const PROFILE_NAME: &str = "Eye Gaze Interaction";
/// The input component's part of the gaze pose's localized name (`input/gaze_ext/pose`).
pub const POSE_NAME: &str = "Gaze Pose";

/// The gaze pose's localized name with the parts `which` asks for, in the order user path,
/// interaction profile, component, joined by single spaces (as Monado joins its own): with all
/// three, `Eyes Eye Gaze Interaction Gaze Pose`. `XR_ERROR_VALIDATION_FAILURE` when `which` is
/// empty or has a bit OpenXR does not define.
pub fn localized_name(which: sys::InputSourceLocalizedNameFlags) -> Result<String, sys::Result> {
    use sys::InputSourceLocalizedNameFlags as F;
    let parts = [
        (F::USER_PATH, USER_NAME),
        (F::INTERACTION_PROFILE, PROFILE_NAME),
        (F::COMPONENT, POSE_NAME),
    ];
    let known = parts.iter().fold(F::EMPTY, |all, (bit, _)| all | *bit);
    if which.is_empty() || !known.contains(which) {
        return Err(sys::Result::ERROR_VALIDATION_FAILURE);
    }
    let named: Vec<&str> = parts
        .iter()
        .filter(|(bit, _)| which.contains(*bit))
        .map(|(_, name)| *name)
        .collect();
    Ok(named.join(" "))
}

/// Decides what to do with a suggestion of `bindings` for `profile`.
pub fn plan(
    paths: &GazePaths,
    profile: sys::Path,
    bindings: &[sys::ActionSuggestedBinding],
) -> Plan {
    if profile != paths.profile {
        return Plan::Forward;
    }
    if bindings.is_empty() {
        return Plan::Empty;
    }
    if bindings.iter().any(|b| b.binding != paths.pose) {
        return Plan::Reject;
    }
    let mut actions: Vec<sys::Action> = Vec::new();
    for b in bindings {
        if !actions.contains(&b.action) {
            actions.push(b.action);
        }
    }
    Plan::Absorb(actions)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sys::Handle;

    fn paths() -> GazePaths {
        GazePaths {
            profile: sys::Path::from_raw(10),
            pose: sys::Path::from_raw(11),
            user: sys::Path::from_raw(13),
        }
    }

    fn binding(action: u64, path: u64) -> sys::ActionSuggestedBinding {
        sys::ActionSuggestedBinding {
            action: sys::Action::from_raw(action),
            binding: sys::Path::from_raw(path),
        }
    }

    #[test]
    fn other_profiles_go_to_the_runtime() {
        assert_eq!(
            plan(&paths(), sys::Path::from_raw(3), &[binding(1, 11)]),
            Plan::Forward
        );
    }

    #[test]
    fn gaze_bindings_are_taken_and_their_actions_remembered() {
        assert_eq!(
            plan(
                &paths(),
                paths().profile,
                &[binding(1, 11), binding(2, 11), binding(1, 11)]
            ),
            Plan::Absorb(vec![sys::Action::from_raw(1), sys::Action::from_raw(2)])
        );
    }

    #[test]
    fn a_suggestion_with_no_binding_is_invalid() {
        assert_eq!(plan(&paths(), paths().profile, &[]), Plan::Empty);
        assert_eq!(plan(&paths(), sys::Path::from_raw(3), &[]), Plan::Forward);
    }

    #[test]
    fn each_flag_names_its_part() {
        use sys::InputSourceLocalizedNameFlags as F;
        assert_eq!(localized_name(F::USER_PATH), Ok("Eyes".to_string()));
        assert_eq!(
            localized_name(F::INTERACTION_PROFILE),
            Ok("Eye Gaze Interaction".to_string())
        );
        assert_eq!(localized_name(F::COMPONENT), Ok("Gaze Pose".to_string()));
    }

    #[test]
    fn parts_are_joined_in_order_whatever_the_flags_order() {
        use sys::InputSourceLocalizedNameFlags as F;
        assert_eq!(
            localized_name(F::COMPONENT | F::USER_PATH),
            Ok("Eyes Gaze Pose".to_string())
        );
        assert_eq!(
            localized_name(F::INTERACTION_PROFILE | F::COMPONENT),
            Ok("Eye Gaze Interaction Gaze Pose".to_string())
        );
        assert_eq!(
            localized_name(F::USER_PATH | F::INTERACTION_PROFILE | F::COMPONENT),
            Ok("Eyes Eye Gaze Interaction Gaze Pose".to_string())
        );
    }

    #[test]
    fn no_flag_or_an_undefined_one_is_a_validation_failure() {
        use sys::InputSourceLocalizedNameFlags as F;
        let invalid = Err(sys::Result::ERROR_VALIDATION_FAILURE);
        assert_eq!(localized_name(F::EMPTY), invalid);
        assert_eq!(localized_name(F::from_raw(1 << 3)), invalid);
        assert_eq!(localized_name(F::USER_PATH | F::from_raw(1 << 40)), invalid);
    }

    #[test]
    fn a_path_the_profile_lacks_is_rejected() {
        assert_eq!(
            plan(&paths(), paths().profile, &[binding(1, 11), binding(2, 12)]),
            Plan::Reject
        );
    }
}
