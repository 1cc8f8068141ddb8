//! Live actions: the OpenXR action set that binds the controller inputs the commands come from
//! (`vitreous_trace::command`) to whatever the runtime maps (simple controller select/menu, ...).
//!
//! Three boolean actions, `select`, `menu` and `squeeze`, each with the subaction paths
//! `/user/hand/left` and `/user/hand/right`, are suggested for these interaction profiles
//! ([`BINDINGS`]):
//!
//! | profile | select | menu | squeeze |
//! | --- | --- | --- | --- |
//! | `/interaction_profiles/khr/simple_controller` | `select/click` | `menu/click` | - |
//! | `/interaction_profiles/htc/vive_controller` | `trigger/click` | `menu/click` | `squeeze/click` |
//! | `/interaction_profiles/oculus/touch_controller` | left `x/click`, right `a/click` | left `y/click`, right `b/click` | `squeeze/value` |
//! | `/interaction_profiles/valve/index_controller` | `a/click` | `b/click` | `squeeze/value` |

use openxr as xr;
use vitreous_trace::command::{ButtonState, Command, Hand, commands_for, presses_with_squeeze};

use super::{Result, XrContext};

/// One hand's suggested bindings: the hand, then its select, menu and (where the profile has
/// one) squeeze input paths relative to the hand's user path.
pub type HandBinding = (Hand, &'static str, &'static str, Option<&'static str>);

/// Suggested bindings: interaction profile, then each hand's (left first).
pub const BINDINGS: &[(&str, [HandBinding; 2])] = &[
    (
        "/interaction_profiles/khr/simple_controller",
        [
            (Hand::Left, "input/select/click", "input/menu/click", None),
            (Hand::Right, "input/select/click", "input/menu/click", None),
        ],
    ),
    (
        "/interaction_profiles/htc/vive_controller",
        [
            (
                Hand::Left,
                "input/trigger/click",
                "input/menu/click",
                Some("input/squeeze/click"),
            ),
            (
                Hand::Right,
                "input/trigger/click",
                "input/menu/click",
                Some("input/squeeze/click"),
            ),
        ],
    ),
    (
        "/interaction_profiles/oculus/touch_controller",
        [
            (
                Hand::Left,
                "input/x/click",
                "input/y/click",
                Some("input/squeeze/value"),
            ),
            (
                Hand::Right,
                "input/a/click",
                "input/b/click",
                Some("input/squeeze/value"),
            ),
        ],
    ),
    (
        "/interaction_profiles/valve/index_controller",
        [
            (
                Hand::Left,
                "input/a/click",
                "input/b/click",
                Some("input/squeeze/value"),
            ),
            (
                Hand::Right,
                "input/a/click",
                "input/b/click",
                Some("input/squeeze/value"),
            ),
        ],
    ),
];

/// The controller action set: `select` and `menu` on each hand.
pub(super) struct Controls {
    /// The action set (attached by the session with its other sets).
    pub(super) set: xr::ActionSet,
    /// The select action.
    select: xr::Action<bool>,
    /// The menu action.
    menu: xr::Action<bool>,
    /// The squeeze action.
    squeeze: xr::Action<bool>,
    /// `/user/hand/left`, `/user/hand/right`.
    hands: [xr::Path; 2],
    /// Profiles whose suggested bindings the runtime accepted.
    pub(super) profiles: Vec<&'static str>,
}

impl Controls {
    /// Creates the set and its actions and suggests [`BINDINGS`]. A profile the runtime
    /// refuses is skipped with a warning; the caller attaches [`Controls::set`].
    pub(super) fn new(instance: &xr::Instance) -> Result<Controls> {
        let hands = [
            instance
                .string_to_path(Hand::Left.path())
                .xr("xrStringToPath")?,
            instance
                .string_to_path(Hand::Right.path())
                .xr("xrStringToPath")?,
        ];
        let set = instance
            .create_action_set("vitreous_controls", "vitreous controls", 0)
            .xr("xrCreateActionSet")?;
        let select = set
            .create_action::<bool>("select", "Select", &hands)
            .xr("xrCreateAction(select)")?;
        let menu = set
            .create_action::<bool>("menu", "Menu", &hands)
            .xr("xrCreateAction(menu)")?;
        let squeeze = set
            .create_action::<bool>("squeeze", "Squeeze", &hands)
            .xr("xrCreateAction(squeeze)")?;
        let mut profiles = Vec::new();
        for (profile, hand_bindings) in BINDINGS {
            let made = (|| -> Result<()> {
                let profile_path = instance.string_to_path(profile).xr("xrStringToPath")?;
                let mut bindings = Vec::new();
                for (hand, s, m, q) in hand_bindings {
                    let path = |input: &str| {
                        instance
                            .string_to_path(&format!("{}/{input}", hand.path()))
                            .xr("xrStringToPath")
                    };
                    bindings.push(xr::Binding::new(&select, path(s)?));
                    bindings.push(xr::Binding::new(&menu, path(m)?));
                    if let Some(q) = q {
                        bindings.push(xr::Binding::new(&squeeze, path(q)?));
                    }
                }
                instance
                    .suggest_interaction_profile_bindings(profile_path, &bindings)
                    .xr("xrSuggestInteractionProfileBindings")
            })();
            match made {
                Ok(()) => profiles.push(*profile),
                Err(e) => tracing::warn!("controller bindings for {profile} refused: {e}"),
            }
        }
        Ok(Controls {
            set,
            select,
            menu,
            squeeze,
            hands,
            profiles,
        })
    }

    /// The commands of both hands' presses since the previous sync; call right after
    /// xrSyncActions with [`Controls::set`] active.
    pub(super) fn commands(&self, session: &xr::Session<xr::Vulkan>) -> Result<Vec<Command>> {
        let state = |action: &xr::Action<bool>, hand: xr::Path| -> Result<ButtonState> {
            let s = action.state(session, hand).xr("xrGetActionStateBoolean")?;
            Ok(ButtonState {
                active: s.is_active,
                down: s.current_state,
                changed: s.changed_since_last_sync,
            })
        };
        let mut out = Vec::new();
        for (hand, path) in Hand::BOTH.into_iter().zip(self.hands) {
            let p = presses_with_squeeze(
                state(&self.select, path)?,
                state(&self.menu, path)?,
                state(&self.squeeze, path)?,
            );
            out.extend(commands_for(hand, p));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_profile_binds_both_hands() {
        for (profile, hands) in BINDINGS {
            assert!(profile.starts_with("/interaction_profiles/"));
            assert_eq!(hands[0].0, Hand::Left, "{profile}");
            assert_eq!(hands[1].0, Hand::Right, "{profile}");
        }
    }
}
