//! How every entry point of the layer stays safe to call from C: a panic becomes
//! `XR_ERROR_RUNTIME_FAILURE` instead of unwinding into the caller's frames, and messages for
//! the user go to stderr under the layer's name.

use std::panic::{AssertUnwindSafe, catch_unwind};

use openxr::sys;

/// Prints a message for the user on stderr, prefixed with the layer's name.
pub fn report(message: impl std::fmt::Display) {
    eprintln!("vitreous-sim-layer: {message}");
}

/// Runs an entry point's body, turning a panic into `XR_ERROR_RUNTIME_FAILURE` so it never
/// unwinds into the caller's C frames.
pub fn guard(call: &str, body: impl FnOnce() -> sys::Result) -> sys::Result {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(r) => r,
        Err(_) => {
            report(format!(
                "{call} panicked; returning XR_ERROR_RUNTIME_FAILURE"
            ));
            sys::Result::ERROR_RUNTIME_FAILURE
        }
    }
}
