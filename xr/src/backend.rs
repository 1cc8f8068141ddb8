//! The backend trait: what the frame loop asks of a source of frames, and what it tells the
//! display beyond the images.

use vitreous_trace::{Blend, FrameInput, SessionEvent};

/// A source of frames: an OpenXR session or a replayed trace.
///
/// The frame loop calls [`Backend::wait_frame`] then, after rendering, [`Backend::end_frame`],
/// once each per frame and in that order.
pub trait Backend {
    /// The error type of this backend.
    type Error: std::error::Error + Send + Sync + 'static;

    /// Blocks until the next frame should be rendered. `Ok(None)` ends the session.
    fn wait_frame(&mut self) -> Result<Option<FrameInput>, Self::Error>;

    /// Tells the backend the frame handed out by the last `wait_frame` has been rendered.
    fn end_frame(&mut self, frame: &FrameInput) -> Result<(), Self::Error>;

    /// What the app asks of the display for the frame handed out by the last `wait_frame`,
    /// beyond its images, given before [`Backend::end_frame`]: backends whose display has no
    /// such controls keep the default, which ignores it.
    fn set_frame_end_hints(&mut self, _hints: FrameEndHints) {}

    /// Leaves the frame handed out by the last `wait_frame` without showing it, when the app
    /// failed before [`Backend::end_frame`]: whatever the frame holds (display images, the
    /// begun frame) is given back. Never fails: clean-up errors are the backend's to log, so
    /// the app's error stays the one reported. Backends with nothing to give back keep the
    /// default, which does nothing.
    fn abandon_frame(&mut self) {}

    /// What happened to the session since the frame before the last `wait_frame`'s (a headset
    /// taken off and put back on, frames not rendered, tracking lost, ...), oldest first, taken
    /// out of the backend; also after `wait_frame` ended the session, for what ended it.
    /// Backends to which nothing happens keep the default, which has nothing.
    fn take_events(&mut self) -> Vec<SessionEvent> {
        Vec::new()
    }

    /// Where the frame handed out by the last `wait_frame` is to be drawn. Backends that
    /// own no display images (the null backend) keep the default, [`FrameTarget::Own`].
    fn frame_target(&self) -> FrameTarget {
        FrameTarget::Own
    }
}

/// What the app asks of the display for one frame beyond its images (headset extensions; see
/// [`Backend::set_frame_end_hints`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameEndHints {
    /// The wearer's filtered fixation depth, metres: where a display with a movable focus
    /// (reprojection) plane puts it (Magic Leap 2: `XrFrameEndInfoML::focusDistance`).
    pub focus_distance_m: Option<f32>,
    /// How much to darken the whole view, 0 none to 1 the most (Magic Leap 2:
    /// `XrGlobalDimmerFrameEndInfoML`); `None`: the app does not ask.
    pub global_dimmer: Option<f32>,
}

/// Where a frame is drawn (see [`Backend::frame_target`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameTarget {
    /// The renderer's own images (replay, previews, readback).
    Own,
    /// Image `index` of the backend's swapchain, handed to the renderer before the loop,
    /// composed for the display's blend mode (what is drawn behind the glass, which alpha).
    Swapchain {
        /// Index of the swapchain image acquired for this frame.
        index: u32,
        /// Index of the depth swapchain image acquired for this frame, when depth is
        /// submitted (XR_KHR_composition_layer_depth); the renderer writes its depth there.
        depth_index: Option<u32>,
        /// How the display blends the image with the real world.
        blend: Blend,
    },
}
