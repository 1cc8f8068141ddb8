//! The keyboard's live controls in `vitreous run`: one command a line on standard input
//! (`object x 10`, `turn -1`, `place`, `light y 10`, `register z -1`; see
//! [`SceneEdit::parse`]), read on a thread of their own and handed to the frame loop; and how
//! the run's sink applies and records them and the controllers' edit commands.

use std::io::BufRead;
use std::sync::mpsc;

use glam::Vec3;
use vitreous_trace::format::EditRecord;
use vitreous_trace::planes::nearest_up_hit;
use vitreous_trace::{Command, FrameInput};

use super::sink::RunSink;
use vitreous_frames::scene_edit::{Axis, SceneEdit, place_ray, ray_meets_plane};

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

impl RunSink<'_> {
    /// Applies the live controls typed since the last frame; a re-registration goes to the
    /// session, which moves the world at the next frame and says so as a nudge.
    pub(super) fn apply_typed_controls(&mut self, input: &FrameInput) {
        let typed: Vec<SceneEdit> = match &self.edits {
            Some(rx) => rx.try_iter().collect(),
            None => Vec::new(),
        };
        for edit in typed {
            match edit {
                SceneEdit::Register(axis, m) => {
                    if let Some(registrar) = &self.registrar {
                        let _ = registrar.send(Command::Nudge(axis.unit() * m));
                    }
                }
                other => self.edit(other, input),
            }
        }
    }

    /// Applies and records the scene edit of a session command. The session has moved the
    /// world already for a nudge or a turn: those are only recorded (a turn by its name: the
    /// head poses hold it).
    pub(super) fn record_command(&mut self, command: Command, input: &FrameInput) {
        match command {
            Command::Nudge(d) => {
                for edit in register_edits(d) {
                    self.edit(edit, input);
                }
            }
            Command::Rotate(a) => {
                let action = format!("register-turn{:+.1}", a.to_degrees());
                // An edit like the others, as the replay of its line counts it.
                self.motion.edit_count += 1;
                tracing::info!(
                    "frame {}: turn the world {:+.1} deg about the head",
                    input.index,
                    a.to_degrees()
                );
                let record = self.motion.edits().record(input.time_ns, action);
                self.record(&record);
            }
            Command::MoveObject(d) => {
                for edit in object_edits(d) {
                    self.edit(edit, input);
                }
            }
            Command::TurnObject(a) => {
                // Whole thousandths of a degree: the step, not its rounding error.
                let deg = (a.to_degrees() * 1000.0).round() / 1000.0;
                self.edit(SceneEdit::TurnObject(deg), input);
            }
            Command::PlaceObject => self.edit(SceneEdit::PlaceObject, input),
            Command::Cycle(_) => {}
        }
    }

    /// Applies a live control to this frame and records it in the trace. A place goes onto
    /// the nearest plane the runtime detected that the gaze meets before the floor, if any.
    fn edit(&mut self, edit: SceneEdit, input: &FrameInput) {
        if edit == SceneEdit::PlaceObject && self.place_on_plane(input) {
            return;
        }
        match self.motion.edit(edit, input) {
            Ok(record) => self.record(&record),
            Err(why) => tracing::warn!("{edit}: {why}"),
        }
    }

    /// Places the object on the nearest detected plane the place ray meets before the floor:
    /// the world is registered so that the floor lies on that plane (a nudge through the
    /// session, recorded when it comes back), and the object goes over the point, resting on
    /// it as it rested on the floor. Returns false, and does nothing, when no plane is met
    /// first.
    fn place_on_plane(&mut self, input: &FrameInput) -> bool {
        let (origin, dir) = place_ray(input);
        let Some((_, hit)) = nearest_up_hit(&self.planes, origin, dir) else {
            return false;
        };
        let (floor, normal) = self.motion.floor();
        if ray_meets_plane(origin, dir, floor, normal)
            .is_some_and(|f| f.distance(origin) < hit.distance(origin))
        {
            return false;
        }
        // To a tenth of a millimetre: the registration's step, as recorded.
        let rise = ((hit - floor).dot(normal) * 1e4).round() / 1e4;
        if rise.abs() > 1e-4 {
            if let Some(registrar) = &self.registrar {
                let _ = registrar.send(Command::Nudge(normal * rise));
            }
            // The planes stay where they are in the room: in the moved scene frame, lower.
            for plane in &mut self.planes {
                plane.pose.position -= normal * rise;
            }
        }
        let record = self.motion.place_over(hit, input);
        self.record(&record);
        tracing::info!(
            "frame {}: placed on a detected plane {:+.4} m above the floor; the floor follows it",
            input.index,
            rise
        );
        true
    }

    /// Takes the planes the runtime detected since the last frame (the latest detection's).
    pub(super) fn take_planes(&mut self) {
        if let Some(rx) = &self.planes_rx
            && let Some(latest) = rx.try_iter().last()
        {
            self.planes = latest;
        }
    }

    /// Writes an edit line into the recording, if any.
    pub(super) fn record(&mut self, record: &EditRecord) {
        if let Some(w) = &mut self.writer
            && let Err(e) = w.write_edit(record)
        {
            self.log_error
                .get_or_insert(anyhow::Error::new(e).context("recording an edit"));
        }
    }
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
