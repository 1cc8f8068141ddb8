//! vitreous: perception-based virtual glass for optical see-through head-mounted displays.
//!
//! The library behind the `vitreous` command: scene files, the frame loop shared by every XR
//! backend, trace replay and trace tools. Rendering lives in `vitreous-render`, XR backends in
//! `vitreous-xr`, the trace format and frame data in `vitreous-trace`, the gaze pipeline
//! (vergence, the gaze-image decisions, defocus maths) in `vitreous-gaze`, re-exported here as
//! [`gaze`].

pub mod bench;
pub mod cli_values;
pub mod compare;
pub mod error_report;
pub mod font;
pub use vitreous_frames::{
    blur_stack, conditions, defocus_model, director, focus, frame_log, frame_loop, input_files,
    interrupt, look, motion_clock, output, reference_view, render_desc, resident, scene_edit,
    setup, spread, test_frame, validation, wearer,
};
pub use vitreous_gaze as gaze;
pub use vitreous_scene::{self as scene, caustics, effects, files};
pub mod reference_cmd;
pub mod replay;
pub mod run;
pub mod soak;
pub mod study;
pub mod trace_analyze;
pub mod trace_cmd;
pub mod view;
