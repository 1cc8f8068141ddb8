//! The keyboard's live controls in `vitreous run`: one command a line on standard input
//! (`object x 10`, `turn -1`, `place`, `light y 10`, `register z -1`; see
//! [`SceneEdit::parse`]), read on a thread of their own and handed to the frame loop.

use std::io::BufRead;
use std::sync::mpsc;

use glam::Vec3;

use crate::scene_edit::{Axis, SceneEdit};

/// Starts reading commands from standard input; each valid line arrives on the receiver (a
/// bad one is logged and skipped). The thread ends with the input.
pub fn stdin_edits() -> mpsc::Receiver<SceneEdit> {
    let (tx, rx) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("stdin-controls".into())
        .spawn(move || {
            for line in std::io::stdin().lock().lines() {
                let Ok(line) = line else { break };
                let line = line.trim();
                if line.is_empty() || line.starts_with('#') {
                    continue;
                }
                match SceneEdit::parse(line) {
                    Ok(edit) => {
                        if tx.send(edit).is_err() {
                            break;
                        }
                    }
                    Err(e) => tracing::warn!("standard input: {e}"),
                }
            }
        });
    if let Err(e) = spawned {
        tracing::warn!("keyboard controls off: cannot start their thread: {e}");
    }
    rx
}

/// The re-registration edits of a session's nudge (the world moved by `d`, metres), one per
/// axis that moved.
pub fn register_edits(d: Vec3) -> Vec<SceneEdit> {
    per_axis(d, SceneEdit::Register)
}

/// The object moves of a controller's move (by `d`, metres), one per axis that moved.
pub fn object_edits(d: Vec3) -> Vec<SceneEdit> {
    per_axis(d, SceneEdit::MoveObject)
}

/// One edit per non-zero component of `d`.
fn per_axis(d: Vec3, edit: fn(Axis, f32) -> SceneEdit) -> Vec<SceneEdit> {
    [Axis::X, Axis::Y, Axis::Z]
        .into_iter()
        .zip(d.to_array())
        .filter(|(_, m)| *m != 0.0)
        .map(|(axis, m)| edit(axis, m))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_nudge_is_recorded_axis_by_axis() {
        assert_eq!(
            register_edits(Vec3::new(0.0, 0.0, -0.01)),
            [SceneEdit::Register(Axis::Z, -0.01)]
        );
        assert_eq!(register_edits(Vec3::new(0.001, 0.0, 0.01)).len(), 2);
        assert!(register_edits(Vec3::ZERO).is_empty());
        assert_eq!(
            object_edits(Vec3::new(0.0, 0.0, 0.01)),
            [SceneEdit::MoveObject(Axis::Z, 0.01)]
        );
    }
}
