//! Paired-comparison studies: reading a responses file and analysing it as the paper did
//! (Thurstone's Case V for forced choices, Nakaya's variant of Scheffe's method for ratings).

pub mod distributions;
pub mod report;
pub mod response_error;
pub mod responses;
pub mod scheffe;
pub mod studentized;
pub mod thurstone;
