//! vitreous-study: paired-comparison studies with no device and no window: the protocol
//! (`protocol`), each participant's trial order (`plan`), the trials on the protocol's clock
//! with the answers recorded as they come (`schedule`, `session`, `answers`), and the analysis
//! the paper used (Thurstone's Case V for forced choices, Nakaya's variant of Scheffe's method
//! for ratings: `responses`, `thurstone`, `scheffe`, `studentized`, `distributions`, `report`).
//!
//! A session is driven frame by frame by the application (`vitreous study run`), which shows
//! each trial's condition through `run` or `view` without either knowing the study.
//!
//! | module | what it is |
//! |---|---|
//! | [`protocol`] | a study's TOML file: conditions, timing, gaze cues, answers |
//! | [`plan`] | each participant's trial order (balanced, seeded), read and written as CSV |
//! | [`schedule`] | one trial's phases on the protocol's clock |
//! | [`session`] | a participant's trials, answers recorded as they come, resumable |
//! | [`answers`] | answers from the keyboard, the controller or a simulated observer |
//! | [`responses`], [`response_error`] | the responses file and its errors |
//! | [`thurstone`], [`scheffe`], [`studentized`], [`distributions`] | the statistics |
//! | [`report`] | a responses file analysed into the JSON report |

pub mod answers;
pub mod distributions;
pub mod plan;
pub mod protocol;
#[cfg(test)]
mod recovery_tests;
pub mod report;
pub mod response_error;
pub mod responses;
pub mod schedule;
pub mod scheffe;
pub mod session;
pub mod studentized;
pub mod thurstone;
