//! Live controller commands: what the wearer (or experimenter) can do during a session, and
//! the pure mapping from one hand's input edges to [`Command`]s. The OpenXR action set that
//! reads the inputs is `vitreous-xr`'s.
//!
//! Each hand has three boolean inputs, `select`, `menu` and `squeeze`. With a hand's squeeze
//! held, its select and menu edit the glass object instead (right: move it 1 cm away or
//! closer, left: turn it 10 degrees left or right), and a press of the right squeeze alone
//! places the object where the gaze meets the floor.
//!
//! [`commands_for`] turns one hand's presses into commands: the right hand steps the
//! application's two cycles (select: [`Cycle::Primary`], menu: [`Cycle::Secondary`]; what
//! they cycle through is the application's choice), menu pressed while select is held or the
//! other way round nudges the scene away; the left hand drives the registration (select: turn
//! the scene left, menu: turn it right, a chord: nudge it closer).

use glam::Vec3;

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
