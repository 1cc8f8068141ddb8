//! The viewer's scene edits: the keys' moves of the object, the light and the world, and the
//! edits of a trace played, applied to the scene's motion frame by frame and recorded with the
//! session's trace.

use anyhow::Context;
use glam::Vec3;
use vitreous_render::ScenePose;
use vitreous_trace::FrameInput;
use vitreous_trace::format::{AtomicFile, EditRecord, TraceWriter};

use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::scene_edit::{EditState, SceneEdit};
use vitreous_scene::Scene;

/// The scene's motion with the edits made in the window and those of a trace played.
pub struct ViewEdits {
    /// The scene's motion and the keys' edits.
    motion: MotionClock,
    /// The first error recording an edit, reported when the next frame finishes.
    error: Option<anyhow::Error>,
    /// The scene edits of the trace played (`--trace`), by time.
    played: Vec<EditRecord>,
}

impl ViewEdits {
    /// No edits yet, on `scene`'s own motion.
    pub fn new(scene: &Scene) -> ViewEdits {
        ViewEdits {
            motion: MotionClock::new(scene),
            error: None,
            played: Vec::new(),
        }
    }

    /// Starts again from a reloaded `scene`'s own placement (the edits made are dropped, and
    /// the log says so).
    pub fn reset(&mut self, scene: &Scene) {
        if self.motion.edit_count > 0 {
            tracing::info!("the reloaded scene starts from its own placement: edits dropped");
        }
        self.motion = MotionClock::new(scene);
    }

    /// The scene's motion and the edits made.
    pub fn motion(&self) -> &MotionClock {
        &self.motion
    }

    /// Shows the scene edits of the trace played: each frame takes the edit state of the last
    /// edit at or before its trace time (so pausing, stepping and seeking back show it too).
    pub fn play(&mut self, edits: Vec<EditRecord>) {
        self.played = edits;
    }

    /// Applies the keys' `edits` to this frame, each recorded in `recording` (the trace
    /// written and the time of its newest sample) when there is one; returns the message for
    /// the overlay (the last edit, or why it was refused). An error recording is kept for
    /// [`ViewEdits::take_error`].
    pub fn apply(
        &mut self,
        edits: Vec<SceneEdit>,
        input: &FrameInput,
        mut recording: Option<(&mut TraceWriter<AtomicFile>, Option<i64>)>,
    ) -> Option<String> {
        let mut status = None;
        for edit in edits {
            let record = match self.motion.edit(edit, input) {
                Ok(record) => record,
                Err(why) => {
                    tracing::warn!("{edit}: {why}");
                    status = Some(why);
                    continue;
                }
            };
            if let Some((writer, recorded_until_ns)) = &mut recording {
                // A paused or rewound trace goes back in time; the edit follows the last sample.
                let time_ns = recorded_until_ns.map_or(record.time_ns, |t| t.max(record.time_ns));
                if let Err(e) = writer
                    .write_edit(&EditRecord { time_ns, ..record })
                    .context("recording a scene edit")
                {
                    self.error.get_or_insert(e);
                }
            }
            status = Some(format!("{edit}"));
        }
        status
    }

    /// The object's centre and the scene's pose for this frame, with the played trace's edits
    /// as of its time; `None` for a scene that stands still and was never moved.
    pub fn pose(&mut self, input: &FrameInput) -> Option<(Vec3, ScenePose)> {
        if !self.played.is_empty() {
            let last = self
                .played
                .iter()
                .rev()
                .find(|e| e.time_ns <= input.time_ns);
            let state = last.map_or_else(EditState::default, EditState::of_record);
            if state != self.motion.edits() {
                match last {
                    Some(record) => self.motion.replay_edit(record, input.index),
                    None => self.motion.set_edits(state),
                }
            }
        }
        let placement = self.motion.placement(input.time_ns)?;
        let center_m = placement.object_position_m;
        Some((center_m, self.motion.pose_of(&placement)))
    }

    /// Whether the scene's caustic bake still fits the placement shown.
    pub fn caustics_valid(&mut self) -> bool {
        self.motion.caustics_valid()
    }

    /// The first error recording an edit since the last call.
    pub fn take_error(&mut self) -> Option<anyhow::Error> {
        self.error.take()
    }
}
