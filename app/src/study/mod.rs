//! `vitreous study`: the commands over the study library ([`vitreous_study`]): `cli` parses
//! and dispatches them, `run` shows a participant's trials through `run`, `view` or a dry
//! run, `plot` draws an analysis.

pub mod cli;
pub mod plot;
pub mod run;
