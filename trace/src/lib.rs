//! Traces and frame data for vitreous, with no device behind them.
//!
//! - [`frame`]: the plain data a backend hands the frame loop ([`FrameInput`]: head [`Pose`],
//!   each eye's [`EyeView`], the newest [`GazeSample`]) and the display's [`Blend`] mode;
//!   [`light`] and [`planes`]: the room's light and the planes a headset detected;
//!   [`session_event`]: what happens to a live session between two frames;
//!   [`command`]: what the live controllers ask for.
//! - [`format`](mod@format): the trace format (reader, writer, checks, scene-edit and event
//!   lines), over the delimited-text layer [`records`]; files are written whole or not at all
//!   ([`atomic_file`]).
//! - [`import`] and [`sranipal`]: head-worn eye-tracker recordings (Pupil Labs Neon, Tobii Pro
//!   Glasses 3, HTC Vive Pro Eye) imported into traces.
//! - [`synth`]: synthetic traces with known ground truth, and the seeded generator
//!   [`synth::SplitMix64`].
//! - [`crossing`]: where two gaze rays cross (the fixation point of vergence).
//!
//! The XR backends that hand these out (the null replay, OpenXR) are `vitreous-xr`'s.
//!
//! Axes everywhere are OpenXR's: right-handed, +x right, +y up, -z forward, metres.

pub mod atomic_file;
pub mod command;
pub mod crossing;
pub mod format;
pub mod frame;
pub mod import;
pub mod light;
pub mod planes;
pub mod records;
pub mod session_event;
pub mod sranipal;
pub mod synth;

pub use command::{Command, Cycle};
pub use format::{TraceError, TraceReader, TraceSample, TraceWriter, read_trace};
pub use frame::{
    Blend, EyeView, Fov, FrameInput, GazeBehaviour, GazeRay, GazeSample, Pose, TrackerConfidence,
    TrackerReport,
};
pub use session_event::SessionEvent;
