//! Live actions: what the wearer (or experimenter) can do during a session, bound through an
//! OpenXR action set to whatever the runtime maps (simple controller select/menu, ...), and the
//! pure mapping from input edges to [`Command`]s.
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
//!
//! With a hand's squeeze held, its select and menu edit the glass object instead (right: move
//! it 1 cm away or closer, left: turn it 10 degrees left or right), and a press of the right
//! squeeze alone places the object where the gaze meets the floor.
//!
//! [`commands_for`] turns one hand's presses into commands: the right hand steps the
//! application's two cycles (select: [`Cycle::Primary`], menu: [`Cycle::Secondary`]; what
//! they cycle through is the application's choice), menu pressed while select is held or the
//! other way round nudges the scene away; the left hand drives the registration (select: turn
//! the scene left, menu: turn it right, a chord: nudge it closer).

use glam::Vec3;
use openxr as xr;

use super::{Result, XrContext};

/// The scene nudge per press, metres.
pub const NUDGE_STEP_M: f32 = 0.01;

/// The scene turn per press, radians (2 degrees).
pub const ROTATE_STEP_RAD: f32 = std::f32::consts::PI / 90.0;

/// The object move per press with the squeeze held, metres.
pub const OBJECT_STEP_M: f32 = 0.01;

/// The object turn per press with the squeeze held, radians (10 degrees).
pub const OBJECT_TURN_RAD: f32 = std::f32::consts::PI / 18.0;

/// Something a live action asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Move the scene by this offset in the scene frame, metres.
    Nudge(Vec3),
    /// Rotate the scene about the vertical axis through the viewer, radians (positive: counter-
    /// clockwise seen from above, i.e. to the viewer's left).
    Rotate(f32),
    /// Step one of the application's cycles to its next value.
    Cycle(Cycle),
    /// Move the glass object by this offset, scene frame, metres.
    MoveObject(Vec3),
    /// Turn the glass object about the vertical through its centre, radians (positive:
    /// counter-clockwise seen from above).
    TurnObject(f32),
    /// Place the glass object where the gaze meets the floor.
    PlaceObject,
}

/// The two cycles the right hand steps; the application decides what each goes through.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cycle {
    /// Stepped by the right hand's select (trigger).
    Primary,
    /// Stepped by the right hand's menu button.
    Secondary,
}

impl std::fmt::Display for Command {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Command::Nudge(d) => write!(
                f,
                "nudge the scene by ({:+.3}, {:+.3}, {:+.3}) m",
                d.x, d.y, d.z
            ),
            Command::Rotate(a) => write!(f, "turn the scene by {:+.1} deg", a.to_degrees()),
            Command::Cycle(Cycle::Primary) => f.write_str("step the primary cycle"),
            Command::Cycle(Cycle::Secondary) => f.write_str("step the secondary cycle"),
            Command::MoveObject(d) => write!(
                f,
                "move the object by ({:+.3}, {:+.3}, {:+.3}) m",
                d.x, d.y, d.z
            ),
            Command::TurnObject(a) => write!(f, "turn the object by {:+.1} deg", a.to_degrees()),
            Command::PlaceObject => f.write_str("place the object at the gaze"),
        }
    }
}

/// Which hand an input is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hand {
    /// `/user/hand/left`.
    Left,
    /// `/user/hand/right`.
    Right,
}

impl Hand {
    /// Both hands, left first.
    pub const BOTH: [Hand; 2] = [Hand::Left, Hand::Right];

    /// The user path.
    pub fn path(self) -> &'static str {
        match self {
            Hand::Left => "/user/hand/left",
            Hand::Right => "/user/hand/right",
        }
    }
}

/// Which inputs changed to pressed this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Presses {
    /// The select (trigger) input.
    pub select: bool,
    /// The menu input.
    pub menu: bool,
    /// Select was held while menu was pressed (or the other way round).
    pub chord: bool,
    /// The squeeze went down.
    pub squeeze: bool,
    /// The squeeze is held: select and menu edit the object.
    pub editing: bool,
}

/// One input's state after an xrSyncActions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ButtonState {
    /// Bound and active.
    pub active: bool,
    /// Down now.
    pub down: bool,
    /// Changed since the previous sync.
    pub changed: bool,
}

impl ButtonState {
    /// Went down at this sync.
    pub fn pressed(self) -> bool {
        self.active && self.down && self.changed
    }

    /// Held (down and active).
    pub fn held(self) -> bool {
        self.active && self.down
    }
}

/// One hand's presses from its two buttons' states: a chord is a press of one button while
/// the other is held (or both pressed at the same sync).
pub fn presses(select: ButtonState, menu: ButtonState) -> Presses {
    presses_with_squeeze(select, menu, ButtonState::default())
}

/// [`presses`] with the hand's squeeze.
pub fn presses_with_squeeze(
    select: ButtonState,
    menu: ButtonState,
    squeeze: ButtonState,
) -> Presses {
    let (s, m) = (select.pressed(), menu.pressed());
    Presses {
        select: s,
        menu: m,
        chord: (s && menu.held()) || (m && select.held()),
        squeeze: squeeze.pressed(),
        editing: squeeze.held(),
    }
}

/// The commands for this frame's presses on the right hand (the experimenter's): select steps
/// the primary cycle, menu the secondary, both together nudge the scene away from the viewer
/// by [`NUDGE_STEP_M`].
pub fn commands(p: Presses) -> Vec<Command> {
    commands_for(Hand::Right, p)
}

/// The commands for this frame's presses on `hand`: the right hand as [`commands`]; on the
/// left, select turns the scene left and menu right by [`ROTATE_STEP_RAD`], both together
/// nudge it closer by [`NUDGE_STEP_M`].
pub fn commands_for(hand: Hand, p: Presses) -> Vec<Command> {
    if p.editing {
        let mut out = Vec::new();
        // The squeeze's own press (the right hand's places the object) comes first.
        if p.squeeze && hand == Hand::Right && !p.select && !p.menu {
            out.push(Command::PlaceObject);
        }
        let (on_select, on_menu) = match hand {
            Hand::Right => (
                Command::MoveObject(Vec3::new(0.0, 0.0, -OBJECT_STEP_M)),
                Command::MoveObject(Vec3::new(0.0, 0.0, OBJECT_STEP_M)),
            ),
            Hand::Left => (
                Command::TurnObject(OBJECT_TURN_RAD),
                Command::TurnObject(-OBJECT_TURN_RAD),
            ),
        };
        if p.select {
            out.push(on_select);
        }
        if p.menu {
            out.push(on_menu);
        }
        return out;
    }
    if p.chord {
        let z = match hand {
            Hand::Right => -NUDGE_STEP_M,
            Hand::Left => NUDGE_STEP_M,
        };
        return vec![Command::Nudge(Vec3::new(0.0, 0.0, z))];
    }
    let mut out = Vec::new();
    match hand {
        Hand::Right => {
            if p.select {
                out.push(Command::Cycle(Cycle::Primary));
            }
            if p.menu {
                out.push(Command::Cycle(Cycle::Secondary));
            }
        }
        Hand::Left => {
            if p.select {
                out.push(Command::Rotate(ROTATE_STEP_RAD));
            }
            if p.menu {
                out.push(Command::Rotate(-ROTATE_STEP_RAD));
            }
        }
    }
    out
}

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

    /// A bound button: up, just pressed, held down, just released.
    const UP: ButtonState = button(false, false);
    const PRESSED: ButtonState = button(true, true);
    const HELD: ButtonState = button(true, false);
    const RELEASED: ButtonState = button(false, true);

    const fn button(down: bool, changed: bool) -> ButtonState {
        ButtonState {
            active: true,
            down,
            changed,
        }
    }

    #[test]
    fn select_steps_the_primary_cycle_and_menu_the_secondary() {
        let select = Presses {
            select: true,
            ..Default::default()
        };
        assert_eq!(commands(select), [Command::Cycle(Cycle::Primary)]);
        let menu = Presses {
            menu: true,
            ..Default::default()
        };
        assert_eq!(commands(menu), [Command::Cycle(Cycle::Secondary)]);
        assert!(commands(Presses::default()).is_empty());
    }

    #[test]
    fn a_chord_only_nudges() {
        let chord = Presses {
            select: true,
            menu: true,
            chord: true,
            ..Default::default()
        };
        assert_eq!(
            commands(chord),
            [Command::Nudge(Vec3::new(0.0, 0.0, -NUDGE_STEP_M))]
        );
        assert_eq!(
            commands_for(Hand::Left, chord),
            [Command::Nudge(Vec3::new(0.0, 0.0, NUDGE_STEP_M))]
        );
    }

    #[test]
    fn the_left_hand_turns_the_scene_both_ways() {
        let select = Presses {
            select: true,
            ..Default::default()
        };
        let menu = Presses {
            menu: true,
            ..Default::default()
        };
        assert_eq!(
            commands_for(Hand::Left, select),
            [Command::Rotate(ROTATE_STEP_RAD)]
        );
        assert_eq!(
            commands_for(Hand::Left, menu),
            [Command::Rotate(-ROTATE_STEP_RAD)]
        );
    }

    #[test]
    fn presses_are_edges_and_chords_need_the_other_button_held() {
        assert_eq!(presses(UP, UP), Presses::default());
        assert_eq!(presses(HELD, HELD), Presses::default());
        assert_eq!(presses(RELEASED, UP), Presses::default());
        assert_eq!(
            presses(PRESSED, UP),
            Presses {
                select: true,
                ..Default::default()
            }
        );
        assert_eq!(
            presses(HELD, PRESSED),
            Presses {
                menu: true,
                chord: true,
                ..Default::default()
            }
        );
        assert_eq!(
            presses(PRESSED, PRESSED),
            Presses {
                select: true,
                menu: true,
                chord: true,
                ..Default::default()
            }
        );
        // An unbound (inactive) input never presses.
        let inactive = ButtonState {
            active: false,
            ..PRESSED
        };
        assert_eq!(presses(inactive, UP), Presses::default());
    }

    #[test]
    fn every_profile_binds_both_hands() {
        for (profile, hands) in BINDINGS {
            assert!(profile.starts_with("/interaction_profiles/"));
            assert_eq!(hands[0].0, Hand::Left, "{profile}");
            assert_eq!(hands[1].0, Hand::Right, "{profile}");
        }
    }

    #[test]
    fn with_the_squeeze_held_select_and_menu_edit_the_object() {
        // The right squeeze alone places the object; the left one alone does nothing.
        let place = presses_with_squeeze(UP, UP, PRESSED);
        assert_eq!(commands_for(Hand::Right, place), [Command::PlaceObject]);
        assert!(commands_for(Hand::Left, place).is_empty());
        // Held: select and menu move (right) or turn (left) the object, never cycle or nudge.
        let select = presses_with_squeeze(PRESSED, UP, HELD);
        assert_eq!(
            commands_for(Hand::Right, select),
            [Command::MoveObject(Vec3::new(0.0, 0.0, -OBJECT_STEP_M))]
        );
        assert_eq!(
            commands_for(Hand::Left, presses_with_squeeze(UP, PRESSED, HELD)),
            [Command::TurnObject(-OBJECT_TURN_RAD)]
        );
        // Without the squeeze, as before.
        assert_eq!(
            commands_for(Hand::Right, presses_with_squeeze(PRESSED, UP, UP)),
            [Command::Cycle(Cycle::Primary)]
        );
    }
}
