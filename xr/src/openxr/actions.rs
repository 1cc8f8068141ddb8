//! Live actions: what the wearer (or experimenter) can do during a session, bound through an
//! OpenXR action set to whatever the runtime maps (simple controller select/menu, ...), and the
//! pure mapping from input edges to [`Command`]s.

use glam::Vec3;

/// The scene nudge per press, metres.
pub const NUDGE_STEP_M: f32 = 0.01;

/// Something a live action asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Move the scene by this offset in the world frame, metres.
    Nudge(Vec3),
    /// Rotate the scene about the vertical axis through the viewer, radians.
    Rotate(f32),
    /// Switch to the next effect condition.
    NextCondition,
    /// Force the gaze image: cycles surface, refracted, automatic.
    NextGazeImage,
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
}

/// The commands for this frame's presses: select cycles the gaze image, menu the effect
/// condition, both together nudge the scene away from the viewer by [`NUDGE_STEP_M`].
pub fn commands(p: Presses) -> Vec<Command> {
    if p.chord {
        return vec![Command::Nudge(Vec3::new(0.0, 0.0, -NUDGE_STEP_M))];
    }
    let mut out = Vec::new();
    if p.select {
        out.push(Command::NextGazeImage);
    }
    if p.menu {
        out.push(Command::NextCondition);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn select_cycles_gaze_and_menu_cycles_condition() {
        let select = Presses {
            select: true,
            ..Default::default()
        };
        assert_eq!(commands(select), [Command::NextGazeImage]);
        let menu = Presses {
            menu: true,
            ..Default::default()
        };
        assert_eq!(commands(menu), [Command::NextCondition]);
        assert!(commands(Presses::default()).is_empty());
    }

    #[test]
    fn a_chord_only_nudges() {
        let chord = Presses {
            select: true,
            menu: true,
            chord: true,
        };
        assert_eq!(
            commands(chord),
            [Command::Nudge(Vec3::new(0.0, 0.0, -NUDGE_STEP_M))]
        );
    }
}
