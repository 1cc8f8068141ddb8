//! `vitreous study`: the commands over the study library ([`vitreous_study`], whose modules
//! are re-exported here): `cli` parses and dispatches them, `run` shows a participant's
//! trials through `run`, `view` or a dry run, `plot` draws an analysis.

pub use vitreous_study::{
    answers, distributions, plan, protocol, report, response_error, responses, schedule, scheffe,
    session, studentized, thurstone,
};

pub mod cli;
pub mod plot;
pub mod run;
