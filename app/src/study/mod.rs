//! Paired-comparison studies, end to end: the protocol (`protocol`), each participant's trial
//! order (`plan`), running the trials on the protocol's clock with the answers recorded as they
//! come (`schedule`, `session`, `answers`, `run`), and the analysis the paper used (Thurstone's
//! Case V for forced choices, Nakaya's variant of Scheffe's method for ratings: `responses`,
//! `thurstone`, `scheffe`, `studentized`, `distributions`, `report`).

pub mod answers;
pub mod cli;
pub mod distributions;
pub mod plan;
pub mod plot;
pub mod protocol;
#[cfg(test)]
mod recovery_tests;
pub mod report;
pub mod response_error;
pub mod responses;
pub mod run;
pub mod schedule;
pub mod scheffe;
pub mod session;
pub mod studentized;
pub mod thurstone;
