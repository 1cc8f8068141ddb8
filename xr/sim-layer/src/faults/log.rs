//! The fault log (`VITREOUS_SIM_FAULT_LOG`): one flushed CSV line for everything the layer
//! injected and everything the app did that a fault made matter, so a test can hold the app's
//! own account of a session against what really happened.
//!
//! ```text
//! frame,display_time_ns,event,detail
//! ,,schedule,frame 40 headset-off 3
//! 40,1764621123456789,fault,headset-off 3
//! 40,1764621123456789,state,VISIBLE
//! 43,1764621123606789,end-session,virtual
//! ```
//!
//! `frame` is the app's newest `xrWaitFrame` of the process (from 0; empty before the first),
//! `display_time_ns` that frame's predicted display time. Events: `schedule` (a fault of the
//! schedule, before the first frame), `fault` (a fault starts), `state` (a session state the
//! layer made the app see), `space-change` (a reference space change it announced, detail the
//! space type), `instance-loss` (the instance loss it announced), `end-session` and
//! `begin-session` (answered by the layer, the runtime's session running on), `no-render` (a
//! frame told not to render), `rendered-unasked` (the app submitted layers in such a frame),
//! `late` (a frame the layer waited for and ended before the app's, detail its display time),
//! `timeout` (a swapchain image wait answered `XR_TIMEOUT_EXPIRED`), `infinite-wait` (a wait
//! with an infinite timeout while a timeout was due: it cannot be given), `failure` (a call
//! failed with `XR_ERROR_RUNTIME_FAILURE`, detail the call), `lost-call` (a call refused as
//! lost, detail the call and result), `unavailable` (`xrGetSystem` or `xrCreateInstance`
//! refused during an outage), `tracking` (a frame's head poses reported without position, or
//! without orientation, or unusable; or its views' fields of view zero: detail `position`,
//! `orientation`, `unusable` or `zerofov`), `dropout` (the eye tracker drops out, detail the kind and seconds),
//! `unfocused-sync` (an `xrSyncActions` while the session was not focused) and `refused` (a
//! call out of order for the state the app was shown, detail the call and the result).

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::Path;

/// The header line.
pub const HEADER: &str = "frame,display_time_ns,event,detail";

/// The open fault log.
#[derive(Debug)]
pub struct FaultLog {
    /// The file, appended to.
    file: File,
}

impl FaultLog {
    /// Opens `path` for appending, writing the header when the file is new or empty (a process
    /// keeps one log across every instance it makes).
    pub fn open(path: &Path) -> io::Result<FaultLog> {
        let mut file = OpenOptions::new().create(true).append(true).open(path)?;
        if file.metadata()?.len() == 0 {
            writeln!(file, "{HEADER}")?;
        }
        Ok(FaultLog { file })
    }

    /// Writes one line: `frame` and `display_ns` empty when `None`; commas in `detail` become
    /// semicolons.
    pub fn write(
        &mut self,
        frame: Option<u64>,
        display_ns: Option<i64>,
        event: &str,
        detail: &str,
    ) -> io::Result<()> {
        let opt = |v: Option<String>| v.unwrap_or_default();
        writeln!(
            self.file,
            "{},{},{event},{}",
            opt(frame.map(|f| f.to_string())),
            opt(display_ns.map(|t| t.to_string())),
            detail.replace([',', '\n'], ";")
        )?;
        self.file.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_append_across_opens_with_one_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("faults.csv");
        FaultLog::open(&path)
            .unwrap()
            .write(None, None, "schedule", "frame 3 menu 2")
            .unwrap();
        FaultLog::open(&path)
            .unwrap()
            .write(Some(3), Some(150), "failure", "xrEndFrame, once")
            .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            format!("{HEADER}\n,,schedule,frame 3 menu 2\n3,150,failure,xrEndFrame; once\n")
        );
    }
}
