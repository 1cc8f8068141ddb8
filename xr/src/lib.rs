//! XR backends for vitreous.
//!
//! The frame loop in the `vitreous` crate talks to a [`Backend`]: the OpenXR runtime on a
//! headset, or the [`null`] backend that replays a recorded [`trace`] on any Vulkan device.
//! This crate knows nothing about the rendering method; it hands out plain [`FrameInput`]s.
//!
//! Axes everywhere are OpenXR's: right-handed, +x right, +y up, -z forward, metres.

pub mod atomic_file;
pub mod crossing;
pub mod frame;
pub mod import;
pub mod light;
pub mod null;
pub mod openxr;
pub mod planes;
pub mod records;
pub mod session_event;
pub mod sranipal;
pub mod synth;
pub mod trace;

pub use frame::{
    Backend, Blend, EyeView, Fov, FrameEndHints, FrameInput, FrameTarget, GazeBehaviour, GazeRay,
    GazeSample, Pose, TrackerConfidence, TrackerReport,
};
pub use null::{NullBackend, NullConfig, NullError};
pub use session_event::SessionEvent;
pub use trace::{TraceError, TraceReader, TraceSample, TraceWriter, read_trace};
