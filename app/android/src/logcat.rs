//! Logs to logcat: the tracing subscriber's lines, each written with `__android_log_write`
//! under the tag `vitreous` at the line's level.

use std::ffi::CString;
use std::io::{self, Write};

use tracing_subscriber::fmt::MakeWriter;

/// Android's log priorities (android/log.h).
const INFO: i32 = 4;
const WARN: i32 = 5;
const ERROR: i32 = 6;

/// Where the subscriber's lines go: one logcat entry per line.
pub struct Logcat;

/// One line being written.
pub struct LogcatLine {
    priority: i32,
    text: Vec<u8>,
}

impl Write for LogcatLine {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.text.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Drop for LogcatLine {
    fn drop(&mut self) {
        let text: Vec<u8> = self.text.iter().copied().filter(|&b| b != 0).collect();
        let Ok(text) = CString::new(text) else {
            return;
        };
        // SAFETY: both strings are NUL-terminated and live across the call; liblog copies them.
        unsafe {
            ndk_sys::__android_log_write(self.priority, c"vitreous".as_ptr(), text.as_ptr());
        }
    }
}

impl<'a> MakeWriter<'a> for Logcat {
    type Writer = LogcatLine;

    fn make_writer(&'a self) -> LogcatLine {
        LogcatLine {
            priority: INFO,
            text: Vec::new(),
        }
    }

    fn make_writer_for(&'a self, meta: &tracing::Metadata<'_>) -> LogcatLine {
        let priority = match *meta.level() {
            tracing::Level::ERROR => ERROR,
            tracing::Level::WARN => WARN,
            _ => INFO,
        };
        LogcatLine {
            priority,
            text: Vec::new(),
        }
    }
}

/// Sends the logs (info and above) to logcat.
pub fn init() {
    let _ = tracing_subscriber::fmt()
        .with_writer(Logcat)
        .with_ansi(false)
        .without_time()
        .with_max_level(tracing::Level::INFO)
        .try_init();
}
