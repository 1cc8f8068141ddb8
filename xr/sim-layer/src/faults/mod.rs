//! A headset that misbehaves: what real runtimes do to a session (the wearer taking the headset
//! off, a system menu, a lost session or runtime, a recentre, frames not to render or late,
//! swapchain timeouts, failing calls, lost tracking, poses marked valid that hold none, display
//! times no frame can have, an eye tracker dropping out or its clock running ahead, eyes that
//! change), injected from a
//! schedule (`VITREOUS_SIM_FAULTS`, [`schedule`]) so a test can watch the app survive each.
//!
//! The schedule runs once per process, across every instance and session the app makes (an
//! app that recreates its instance after a loss carries on where it was): its state
//! ([`state::Faults`]) lives in this module's static, and the library pins itself in the
//! process at the first instance (the loader unloads a layer with each instance it destroys,
//! which would start the schedule again). What was injected, and what the app did that the
//! faults made matter, goes to the fault log (`VITREOUS_SIM_FAULT_LOG`, [`log`]).

pub mod log;
pub mod schedule;
pub mod state;

use std::path::Path;
use std::sync::{LazyLock, Mutex};

use crate::config::{FAULT_LOG_VAR, FAULTS_VAR};
use crate::guard::report;
use log::FaultLog;
use state::Faults;

/// The faults of the process and where they are logged.
struct Installed {
    /// The state.
    faults: Faults,
    /// The log, when asked for.
    log: Option<FaultLog>,
}

/// The process's faults: `None` until an instance is made with a schedule.
static FAULTS: LazyLock<Mutex<Option<Installed>>> = LazyLock::new(|| Mutex::new(None));

/// Runs `f` on the process's faults and writes what it logged; `None` when there is no
/// schedule.
pub fn with<R>(f: impl FnOnce(&mut Faults) -> R) -> Option<R> {
    let mut guard = FAULTS.lock().unwrap_or_else(|e| e.into_inner());
    let installed = guard.as_mut()?;
    let out = f(&mut installed.faults);
    let (frame, display) = installed.faults.clock();
    let lines = installed.faults.take_log();
    if let Some(log) = &mut installed.log {
        for (event, detail) in lines {
            if let Err(e) = log.write(frame, display, event, &detail) {
                report(format!("{FAULT_LOG_VAR}: writing: {e}"));
            }
        }
    }
    Some(out)
}

/// Reads the schedule and opens the log at the first instance made with one (later instances
/// carry on with the same state; a different schedule file then is refused).
pub fn install(schedule: Option<&Path>, log: Option<&Path>) -> Result<(), String> {
    let Some(path) = schedule else {
        return Ok(());
    };
    let mut guard = FAULTS.lock().unwrap_or_else(|e| e.into_inner());
    if guard.is_some() {
        return Ok(());
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{FAULTS_VAR}: reading {}: {e}", path.display()))?;
    let parsed =
        schedule::parse(&text).map_err(|e| format!("{FAULTS_VAR}: {}: {e}", path.display()))?;
    let log = log
        .map(|p| {
            FaultLog::open(p).map_err(|e| format!("{FAULT_LOG_VAR}: opening {}: {e}", p.display()))
        })
        .transpose()?;
    pin::pin_library()?;
    *guard = Some(Installed {
        faults: Faults::new(parsed),
        log,
    });
    drop(guard);
    // The schedule's lines.
    with(|_| ());
    Ok(())
}

mod pin {
    //! Keeping the layer's library loaded for the rest of the process.

    /// Opens this library once more with `RTLD_NODELETE` and never closes it: the loader's
    /// `dlclose` with each destroyed instance then leaves it (and the fault schedule's state)
    /// in place.
    pub fn pin_library() -> Result<(), String> {
        // SAFETY: `Dl_info` is plain data; all zero is a valid value to be overwritten.
        let mut info: libc::Dl_info = unsafe { std::mem::zeroed() };
        let here = pin_library as *const () as *const libc::c_void;
        // SAFETY: `here` is an address inside this library; `info` is writable.
        let found = unsafe { libc::dladdr(here, &mut info) };
        if found == 0 || info.dli_fname.is_null() {
            return Err("cannot find the layer's own library to keep it loaded".into());
        }
        // SAFETY: `dli_fname` is the NUL-terminated path of a library already loaded in the
        // process; opening it again only adds a reference.
        let handle = unsafe { libc::dlopen(info.dli_fname, libc::RTLD_NOW | libc::RTLD_NODELETE) };
        if handle.is_null() {
            return Err("cannot keep the layer's library loaded (dlopen failed)".into());
        }
        Ok(())
    }
}
