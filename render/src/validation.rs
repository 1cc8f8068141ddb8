//! The validation layer's messages: counted and kept by the context's messenger.

use std::ffi::{CStr, c_void};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, Ordering};

use ash::vk;

/// Counts and keeps the validation layer's messages.
#[derive(Debug, Default)]
pub struct ValidationLog {
    /// Messages of warning severity seen so far.
    warnings: AtomicU32,
    /// Messages of error severity seen so far.
    errors: AtomicU32,
    /// The first few messages' texts, for test failures and logs.
    first: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Number of warning messages so far.
    pub fn warnings(&self) -> u32 {
        self.warnings.load(Ordering::Relaxed)
    }

    /// Number of error messages so far.
    pub fn errors(&self) -> u32 {
        self.errors.load(Ordering::Relaxed)
    }

    /// The first (up to 20) warning and error messages.
    pub fn messages(&self) -> Vec<String> {
        self.first.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            self.errors.fetch_add(1, Ordering::Relaxed);
            tracing::error!(target: "vulkan", "{text}");
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            self.warnings.fetch_add(1, Ordering::Relaxed);
            tracing::warn!(target: "vulkan", "{text}");
        } else {
            tracing::debug!(target: "vulkan", "{text}");
            return;
        }
        if let Ok(mut first) = self.first.lock()
            && first.len() < 20
        {
            first.push(text);
        }
    }
}

/// The validation messenger's callback: records the message in the context's log.
///
/// # Safety
/// Called by the Vulkan loader only, with `user` the `ValidationLog` registered with the
/// messenger (alive while the messenger is) and `data` valid for the call.
pub(crate) unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the ValidationLog kept alive by the GpuContext for the messenger's
    // lifetime; `data` is valid for the duration of the callback per the Vulkan spec.
    let log = unsafe { &*(user as *const ValidationLog) };
    // SAFETY: `data`, when not null, is valid for the callback, and its `p_message`, when not
    // null, is a NUL-terminated string (Vulkan spec, VkDebugUtilsMessengerCallbackDataEXT).
    let text = unsafe {
        data.as_ref()
            .filter(|d| !d.p_message.is_null())
            .map(|d| CStr::from_ptr(d.p_message).to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    log.record(severity, text);
    vk::FALSE
}
