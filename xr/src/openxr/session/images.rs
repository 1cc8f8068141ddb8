//! Waiting for and releasing swapchain images with the raw calls. The `openxr` crate's
//! `wait_image` counts `XR_TIMEOUT_EXPIRED` (a success code) as a finished wait, and its
//! `release_image` then asserts a wait that never happened; a runtime may time a wait out at any
//! time, so the session waits in steps, again after each timeout, and releases through the same
//! raw calls.

use std::time::{Duration, Instant};

use openxr as xr;

use super::super::{OpenXrError, Result};

/// How long one wait may block before the runtime is asked again (a timeout then lets the
/// session notice Ctrl-C or a lost session while an image is late).
pub(super) const WAIT_STEP: Duration = Duration::from_millis(100);

/// How long the session waits for one image in all before giving up: a compositor that holds an
/// image this long is not coming back.
pub(super) const WAIT_LIMIT: Duration = Duration::from_secs(10);

/// Waits for the oldest acquired image of `chain`, asking again after each timeout, for at most
/// [`WAIT_LIMIT`]; returns how many waits timed out.
pub(super) fn wait(
    instance: &xr::Instance,
    chain: &xr::Swapchain<xr::Vulkan>,
    call: &'static str,
) -> Result<u64> {
    let started = Instant::now();
    let info = xr::sys::SwapchainImageWaitInfo {
        ty: xr::sys::SwapchainImageWaitInfo::TYPE,
        next: std::ptr::null(),
        timeout: xr::Duration::from_nanos(WAIT_STEP.as_nanos() as i64),
    };
    let mut timeouts = 0;
    loop {
        // SAFETY: `chain` is a live swapchain of `instance`'s session with an acquired image
        // not yet waited for (the caller's frame scope keeps that order); `info` is valid.
        let result = unsafe { (instance.fp().wait_swapchain_image)(chain.as_raw(), &info) };
        if result == xr::sys::Result::TIMEOUT_EXPIRED {
            timeouts += 1;
            if started.elapsed() >= WAIT_LIMIT {
                return Err(OpenXrError::Unsupported(format!(
                    "{call}: the runtime did not hand the swapchain image back in {} s ({timeouts} \
                     waits timed out)",
                    WAIT_LIMIT.as_secs()
                )));
            }
            continue;
        }
        if result.into_raw() < 0 {
            return Err(OpenXrError::Call { call, result });
        }
        return Ok(timeouts);
    }
}

/// Releases the oldest waited image of `chain`.
pub(super) fn release(
    instance: &xr::Instance,
    chain: &xr::Swapchain<xr::Vulkan>,
    call: &'static str,
) -> Result<()> {
    // SAFETY: `chain` is a live swapchain of `instance`'s session whose oldest acquired image
    // was waited for (the caller's frame scope keeps that order); no release info is needed.
    let result =
        unsafe { (instance.fp().release_swapchain_image)(chain.as_raw(), std::ptr::null()) };
    if result.into_raw() < 0 {
        return Err(OpenXrError::Call { call, result });
    }
    Ok(())
}
