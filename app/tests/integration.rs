//! The command-line, scene-loading and gaze tests of `vitreous`, in one binary: each module is
//! one subject.

mod cli;
mod compare;
mod gaze_defocus;
mod gaze_filter;
mod gaze_trace;
mod gaze_vergence;
mod interrupted;
mod misregistration;
mod numeric_options;
mod outputs;
mod reference;
mod scene_asset_errors;
mod scene_consistency;
mod scene_edits;
mod scene_errors;
mod scene_load;
mod scene_shipped;
mod sheet;
mod soak;
mod study_analyze;
mod study_run;
mod trace_analyze;
mod trace_import;
mod view;
