//! After a lost session or runtime: asking the runtime again until it is back (a headset
//! reconnected, a runtime restarted), for a bounded time, so a study does not end when the
//! headset goes to sleep or its cable is pulled for a moment.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use vitreous_xr::openxr::{OpenXrOptions, Runtime, interrupted};

/// How long a run waits for the runtime to come back after a loss by default, seconds.
pub const RECONNECT_S_DEFAULT: f64 = 120.0;

/// The longest `--reconnect-s` accepts, seconds (a day).
pub const RECONNECT_S_MAX: f64 = 86_400.0;

/// How long to wait between two tries.
const RETRY: Duration = Duration::from_millis(250);

/// How often the wait says it is still waiting.
const SAY_EVERY: Duration = Duration::from_secs(5);

/// Asks for the runtime and the headset again until they are back, for at most `limit`: the
/// new runtime and how long it took; `None` when the app stopped waiting (Ctrl-C, or `end`
/// set). Fails when they are not back in time, or when the runtime answers with anything but
/// "not available now" or "could not start" (a runtime starting again after a crash).
pub(super) fn runtime_again(
    options: &OpenXrOptions,
    limit: Duration,
    end: Option<&AtomicBool>,
) -> Result<Option<(Runtime, Duration)>> {
    let started = Instant::now();
    let mut said = started;
    tracing::info!(
        "waiting up to {} s for the OpenXR runtime and the headset to come back",
        limit.as_secs_f64()
    );
    loop {
        if interrupted() || end.is_some_and(|e| e.load(Ordering::SeqCst)) {
            return Ok(None);
        }
        match Runtime::new(options) {
            Ok(runtime) => return Ok(Some((runtime, started.elapsed()))),
            Err(e) if e.may_come_back_after_loss() => {
                if started.elapsed() >= limit {
                    return Err(e).with_context(|| {
                        format!(
                            "the OpenXR runtime did not come back within {} s of the loss \
                             (--reconnect-s)",
                            limit.as_secs_f64()
                        )
                    });
                }
                if said.elapsed() >= SAY_EVERY {
                    tracing::info!(
                        "still waiting for the OpenXR runtime ({:.0} s): {e}",
                        started.elapsed().as_secs_f64()
                    );
                    said = Instant::now();
                }
                std::thread::sleep(RETRY);
            }
            Err(e) => return Err(e).context("starting OpenXR again after the loss"),
        }
    }
}
