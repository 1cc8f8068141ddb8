//! vitreous: perception-based virtual glass for optical see-through head-mounted displays.
//!
//! The commands of the `vitreous` binary (`run`, `view`, `replay`, `bench`, `soak`, `trace`,
//! `study`, `compare`, `reference`, `bake`), each wiring the libraries that do the work: the
//! frame loop in `vitreous-frames`, scenes in `vitreous-scene`, the gaze pipeline in
//! `vitreous-gaze`, studies in `vitreous-study`, the physical reference in `vitreous-reference`,
//! image comparison in `vitreous-compare`, the caustic bake in `vitreous-caustics`, rendering in
//! `vitreous-render`, the XR backends in `vitreous-xr`, traces and frame data in
//! `vitreous-trace`. A library here so that the tests reach the commands' own parts.

pub mod bench;
pub mod cli_values;
pub mod compare_cmd;
pub mod error_report;
pub mod font;
pub mod reference_cmd;
pub mod replay;
pub mod run;
pub mod sheet_cmd;
pub mod soak;
pub mod study;
pub mod trace_analyze;
pub mod trace_cmd;
pub mod view;
