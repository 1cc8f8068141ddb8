//! Ctrl-C (SIGINT) and SIGTERM for headless commands: the first request ends the run after the
//! frame in progress, so the output folder is finished in a known state.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the signal handler.
static REQUESTED: AtomicBool = AtomicBool::new(false);
/// Whether the handler is installed (a process can install one only once).
static INSTALLED: OnceLock<bool> = OnceLock::new();

/// Installs the handler (once per process) and clears any earlier request. Returns false when
/// another handler owns the signals; the run then cannot be ended early, only killed.
pub fn watch() -> bool {
    REQUESTED.store(false, Ordering::SeqCst);
    *INSTALLED.get_or_init(|| {
        ctrlc::set_handler(|| REQUESTED.store(true, Ordering::SeqCst))
            .map_err(|e| tracing::warn!("cannot handle Ctrl-C/SIGTERM: {e}"))
            .is_ok()
    })
}

/// Whether an interrupt arrived since [`watch`].
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}
