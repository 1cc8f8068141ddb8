//! XR backends for vitreous.
//!
//! The frame loop (`vitreous-frames`, `app/frames`) talks to a [`Backend`]: the OpenXR runtime
//! on a headset ([`openxr`]), or the [`null`] backend that replays a recorded trace on any
//! Vulkan device. This crate knows nothing about the rendering method; it hands out plain
//! `FrameInput`s. The traces and the frame data themselves (poses, views, gaze samples,
//! session events) are `vitreous-trace`'s.
//!
//! Axes everywhere are OpenXR's: right-handed, +x right, +y up, -z forward, metres.

pub mod backend;
pub mod null;
pub mod openxr;

pub use backend::{Backend, FrameEndHints, FrameTarget};
pub use null::{NullBackend, NullConfig, NullError};
