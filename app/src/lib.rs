//! vitreous: perception-based virtual glass for optical see-through head-mounted displays.
//!
//! The library behind the `vitreous` command: scene files, the frame loop shared by every XR
//! backend, trace replay and trace tools. Rendering lives in `vitreous-render`, XR backends and
//! the trace format in `vitreous-xr`, the gaze pipeline (vergence, the gaze-image decisions,
//! defocus maths) in `vitreous-gaze`, re-exported here as [`gaze`].

pub mod bench;
pub mod blur_stack;
pub mod cli_values;
pub mod defocus_model;
pub mod director;
pub mod error_report;
pub mod frame_log;
pub mod frame_loop;
pub use vitreous_gaze as gaze;
pub use vitreous_scene::{self as scene, caustics, effects, files};
pub mod interrupt;
pub mod look;
pub mod motion_clock;
pub mod output;
pub mod reference_view;
pub mod replay;
pub mod run;
pub mod scene_edit;
pub mod soak;
pub mod spread;
pub mod study;
pub mod trace_analyze;
pub mod trace_cmd;
pub mod view;
pub mod views;
