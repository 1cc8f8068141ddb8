//! Version 1.4's event lines: what happened to a live session between its frames (the
//! headset taken off, frames not rendered, tracking lost: [`SessionEvent`]), so a replay of
//! the recording knows about the gaps between its samples and reports them as the session did.
//!
//! An event line starts with the word `event` and holds [`EVENT_FIELDS`] fields:
//!
//! ```text
//! event,time_ns,kind,reason,count
//! event,1500000000,not-rendered,runtime,3
//! event,4250000000,session-ended,,0
//! ```
//!
//! `time_ns` is the display time of the frame the app noticed the event at (the sample line
//! after it, when there is one), `kind` one of [`EVENT_KINDS`], `reason` a word some kinds take
//! (empty otherwise) and `count` the frames, display periods or milliseconds some kinds count
//! (0 otherwise).

use super::TraceError;
use crate::records::{Record, printable};
use crate::session_event::SessionEvent;

pub use crate::session_event::EVENT_KINDS;

/// The first field of an event line.
pub const EVENT_TAG: &str = "event";

/// The names of an event line's fields, in file order (the first is the tag itself).
pub const EVENT_FIELDS: [&str; 5] = ["event", "time_ns", "kind", "reason", "count"];

/// One event of a recorded session and when the app noticed it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EventRecord {
    /// Display time of the frame the event came with, nanoseconds on the trace clock.
    pub time_ns: i64,
    /// What happened.
    pub event: SessionEvent,
}

/// Checks an event at `time_ns` after the line before it (a sample, edit or event at
/// `previous_ns`): not before it.
pub(super) fn check_event(
    file: &str,
    line: usize,
    event: &EventRecord,
    previous_ns: Option<i64>,
) -> Result<EventRecord, TraceError> {
    if let Some(p) = previous_ns
        && event.time_ns < p
    {
        return Err(TraceError::BadEvent {
            file: file.to_owned(),
            line,
            reason: format!(
                "time_ns {} is before the line it follows ({p})",
                event.time_ns
            ),
        });
    }
    Ok(*event)
}

/// Parses an event line (its first field is [`EVENT_TAG`]) without the order check.
pub(super) fn parse_event(record: &Record<'_>) -> Result<EventRecord, TraceError> {
    record.expect_len(EVENT_FIELDS.len())?;
    let time_ns = record.i64(1, EVENT_FIELDS[1], "an integer number of nanoseconds")?;
    let count_text = record.field(4);
    let count = count_text
        .parse::<u64>()
        .map_err(|_| record.bad(EVENT_FIELDS[4], count_text, "a whole number (0 or more)"))?;
    let event =
        SessionEvent::from_fields(record.field(2), record.field(3), count).map_err(|reason| {
            TraceError::BadEvent {
                file: record.file().to_owned(),
                line: record.line(),
                reason: printable(&reason),
            }
        })?;
    Ok(EventRecord { time_ns, event })
}

/// The line of an event (with its line ending).
pub(super) fn format_event(event: &EventRecord) -> String {
    let (kind, reason, count) = event.event.fields();
    format!("{EVENT_TAG},{},{kind},{reason},{count}\n", event.time_ns)
}
