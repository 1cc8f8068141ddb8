//! Input of the viewer: window events and scripted events in one form, and what each key does.

use std::fmt;

use vitreous_frames::scene_edit::{Axis, MOVE_STEPS_M, SceneEdit, TURN_STEPS_DEG};

/// One input event, from the window or from a script.
#[derive(Clone, Debug, PartialEq)]
pub enum InputEvent {
    /// A key went down (`pressed`) or up; `name` is lower case (`w`, `1`, `f1`, `tab`, `space`,
    /// `escape`).
    Key {
        /// The key's name.
        name: String,
        /// Down (true) or up.
        pressed: bool,
    },
    /// The cursor moved to a point of the window, as fractions of its width and height from
    /// the top left.
    Cursor {
        /// Fraction of the width, 0 (left) to 1 (right).
        x: f32,
        /// Fraction of the height, 0 (top) to 1 (bottom).
        y: f32,
    },
    /// A mouse button went down or up.
    Button {
        /// `left`, `right` or `middle`.
        name: String,
        /// Down (true) or up.
        pressed: bool,
    },
    /// The wheel turned by this many notches (positive: away from the user).
    Wheel(f32),
}

/// What the viewer does in answer to a key (movement keys are held, not actions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Show the effect condition of this index of [`super::conditions::CONDITION_KEYS`].
    Condition(usize),
    /// The next effect condition.
    NextCondition,
    /// Switch the reflected image between Phong and environment + Fresnel.
    Reflection,
    /// The next gaze filter.
    Filter,
    /// The next forced gaze image (auto, surface, refracted).
    GazeOverride,
    /// Fixate the other image under the cursor (surface or refracted).
    FixationTarget,
    /// Switch noise on the synthesised gaze rays on or off.
    Noise,
    /// Show both eyes, the left, or the right.
    Eyes,
    /// Switch between the display's light and the see-through preview.
    Preview,
    /// The next registration error the see-through preview shows the display with.
    Misregister,
    /// Show or hide the overlay.
    Overlay,
    /// List the keys.
    Help,
    /// Back to the scene's viewing position, looking ahead.
    Recentre,
    /// End the session.
    Quit,
    /// Pause or resume trace playback.
    Pause,
    /// One frame on while paused.
    Step,
    /// Seek trace playback by this many seconds.
    Seek(i32),
    /// Move what the arrow keys move (the object, the light or the registered world) along
    /// a world axis, metres.
    Nudge(Axis, f32),
    /// Turn the object about the vertical, degrees.
    Turn(f32),
    /// Place the object where the gaze meets the floor.
    Place,
    /// The next thing the arrow keys move: object, light, registered world.
    EditTarget,
    /// A scene edit, for the sink to apply and record.
    Edit(SceneEdit),
}

/// Keys and what they do, as F1 lists them.
pub const KEYS: &[(&str, &str)] = &[
    ("drag (left button)", "look around"),
    (
        "W A S D / Q E",
        "move forward, left, back, right / down, up",
    ),
    ("R", "recentre"),
    ("cursor", "gaze direction"),
    (
        "wheel / Space",
        "fixate the surface or the refracted image under the cursor",
    ),
    ("1..7", "effects: none, O3, O4, O5, b, c, inducer"),
    ("Tab", "next effect condition"),
    ("F", "reflection: Phong / environment + Fresnel"),
    ("G", "next gaze filter"),
    ("I", "forced gaze image: auto, surface, refracted"),
    ("N", "noise on the gaze rays on / off"),
    ("V", "eyes: both, left, right"),
    ("P", "display light / see-through preview"),
    (
        "X",
        "preview's registration error: none, 0.125, 0.25 deg right",
    ),
    ("H", "overlay on / off"),
    (
        "K / L / J",
        "trace: pause, step, back 1 s (Shift+L: forward 1 s)",
    ),
    (
        "arrows / PgUp PgDn",
        "move the object (or light, world) 1 cm along x, z / y (Shift: 1 mm)",
    ),
    ("B", "arrows move: object, light, registered world"),
    (
        "T / Y",
        "turn the object 10 deg left / right (Shift: 1 deg)",
    ),
    ("M", "place the object where the gaze meets the floor"),
    ("F1", "this list"),
    ("Esc", "quit"),
];

/// The action of a key pressed; `None` for keys without one (movement keys are held).
pub fn action_for_key(name: &str, shift: bool) -> Option<Action> {
    Some(match name {
        "1" | "2" | "3" | "4" | "5" | "6" | "7" => {
            Action::Condition(name.parse::<usize>().ok()? - 1)
        }
        "tab" => Action::NextCondition,
        "f" => Action::Reflection,
        "g" => Action::Filter,
        "i" => Action::GazeOverride,
        "space" => Action::FixationTarget,
        "n" => Action::Noise,
        "v" => Action::Eyes,
        "p" => Action::Preview,
        "x" => Action::Misregister,
        "h" => Action::Overlay,
        "f1" => Action::Help,
        "r" => Action::Recentre,
        "escape" => Action::Quit,
        "k" => Action::Pause,
        "l" if shift => Action::Seek(1),
        "l" => Action::Step,
        "j" => Action::Seek(-1),
        "left" | "right" | "up" | "down" | "pageup" | "pagedown" => {
            let step = MOVE_STEPS_M[usize::from(!shift)];
            match name {
                "left" => Action::Nudge(Axis::X, -step),
                "right" => Action::Nudge(Axis::X, step),
                // Up: away from the viewer at the start (-z).
                "up" => Action::Nudge(Axis::Z, -step),
                "down" => Action::Nudge(Axis::Z, step),
                "pageup" => Action::Nudge(Axis::Y, step),
                _ => Action::Nudge(Axis::Y, -step),
            }
        }
        "t" => Action::Turn(TURN_STEPS_DEG[usize::from(!shift)]),
        "y" => Action::Turn(-TURN_STEPS_DEG[usize::from(!shift)]),
        "m" => Action::Place,
        "b" => Action::EditTarget,
        _ => return None,
    })
}

/// The keys held for movement: -1, 0 or +1 along the head's x (right), y (up) and -z
/// (forward).
pub fn movement(held: &[String]) -> [f32; 3] {
    let has = |k: &str| held.iter().any(|h| h == k);
    let axis = |neg: &str, pos: &str| f32::from(u8::from(has(pos))) - f32::from(u8::from(has(neg)));
    [axis("a", "d"), axis("q", "e"), axis("s", "w")]
}

/// Which eye images the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EyesShown {
    /// Left and right side by side.
    #[default]
    Both,
    /// The left eye alone.
    Left,
    /// The right eye alone.
    Right,
}

impl EyesShown {
    /// The next choice (both, left, right).
    pub fn next(self) -> EyesShown {
        match self {
            EyesShown::Both => EyesShown::Left,
            EyesShown::Left => EyesShown::Right,
            EyesShown::Right => EyesShown::Both,
        }
    }

    /// The size of each eye image for a window of `width` x `height`.
    pub fn eye_size(self, width: u32, height: u32) -> (u32, u32) {
        match self {
            EyesShown::Both => ((width / 2).max(16), height.max(16)),
            _ => (width.max(16), height.max(16)),
        }
    }

    /// The eye a point of the window (fractions from the top left) falls in, and where in
    /// that eye's image (fractions).
    pub fn locate(self, x: f32, y: f32) -> (usize, f32, f32) {
        match self {
            EyesShown::Both if x < 0.5 => (0, x * 2.0, y),
            EyesShown::Both => (1, (x - 0.5) * 2.0, y),
            EyesShown::Left => (0, x, y),
            EyesShown::Right => (1, x, y),
        }
    }

    /// The name `--eyes` takes.
    pub fn parse(s: &str) -> Option<EyesShown> {
        match s {
            "both" => Some(EyesShown::Both),
            "left" => Some(EyesShown::Left),
            "right" => Some(EyesShown::Right),
            _ => None,
        }
    }
}

impl fmt::Display for EyesShown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            EyesShown::Both => "both",
            EyesShown::Left => "left",
            EyesShown::Right => "right",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digit_keys_choose_conditions_and_shift_l_seeks_forward() {
        assert_eq!(action_for_key("1", false), Some(Action::Condition(0)));
        assert_eq!(action_for_key("7", false), Some(Action::Condition(6)));
        assert_eq!(action_for_key("8", false), None);
        assert_eq!(action_for_key("l", false), Some(Action::Step));
        assert_eq!(action_for_key("l", true), Some(Action::Seek(1)));
        assert_eq!(action_for_key("w", false), None, "movement keys are held");
    }

    #[test]
    fn arrows_move_a_centimetre_and_shift_a_millimetre() {
        assert_eq!(
            action_for_key("left", false),
            Some(Action::Nudge(Axis::X, -0.01))
        );
        assert_eq!(
            action_for_key("up", true),
            Some(Action::Nudge(Axis::Z, -0.001))
        );
        assert_eq!(
            action_for_key("pageup", false),
            Some(Action::Nudge(Axis::Y, 0.01))
        );
        assert_eq!(action_for_key("t", false), Some(Action::Turn(10.0)));
        assert_eq!(action_for_key("y", true), Some(Action::Turn(-1.0)));
        assert_eq!(action_for_key("m", false), Some(Action::Place));
    }

    #[test]
    fn opposite_movement_keys_cancel() {
        let held = |k: &[&str]| k.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(movement(&held(&["w", "d"])), [1.0, 0.0, 1.0]);
        assert_eq!(movement(&held(&["a", "d", "q"])), [0.0, -1.0, 0.0]);
    }

    #[test]
    fn side_by_side_halves_map_to_their_eye() {
        assert_eq!(EyesShown::Both.locate(0.25, 0.5), (0, 0.5, 0.5));
        assert_eq!(EyesShown::Both.locate(0.75, 0.1), (1, 0.5, 0.1));
        assert_eq!(EyesShown::Right.locate(0.25, 0.5), (1, 0.25, 0.5));
        assert_eq!(EyesShown::Both.eye_size(960, 540), (480, 540));
        assert_eq!(EyesShown::Left.eye_size(960, 540), (960, 540));
    }
}
