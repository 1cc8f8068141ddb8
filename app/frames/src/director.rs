//! A director: what decides each frame's effect condition and gaze image instead of the user,
//! for a session of `run` or `view` (a study's trials, `study::run::StudyStage`). The sessions
//! take one through this trait and know nothing of what is behind it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use vitreous_trace::{Command, FrameInput, SessionEvent};

use vitreous_gaze::GazeOverride;
use vitreous_scene::effects::EffectSet;

/// Decides each frame's condition and gaze image (see the module docs).
pub trait Director {
    /// The effect sets the session builds looks for, in order (the first is shown first).
    fn sets(&self) -> &[EffectSet];

    /// What this frame shows: the effect set (`None`: nothing) and the gaze image cued (`None`
    /// after an error, which [`Director::take_error`] returns).
    fn next_shown(&mut self, input: &FrameInput) -> (Option<EffectSet>, Option<GazeOverride>);

    /// A command from the headset's controls (an answer, for a study); the director handles
    /// it instead of the live controls.
    fn command(&mut self, command: Command);

    /// What happened to the session since the frame before (the headset taken off, a menu,
    /// a loss: [`SessionEvent`]), before the next frame is planned. Directors that do not
    /// care keep the default, which ignores it.
    fn session_events(&mut self, _events: &[SessionEvent]) {}

    /// The flag set once the session should end.
    fn end_flag(&self) -> Arc<AtomicBool>;

    /// Whether the session should end.
    fn ending(&self) -> bool {
        self.end_flag().load(Ordering::SeqCst)
    }

    /// The first error of a frame, once.
    fn take_error(&mut self) -> Option<anyhow::Error>;
}
