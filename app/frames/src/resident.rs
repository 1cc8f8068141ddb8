//! The process's resident memory (Linux and Android: `/proc/self/status`). On a CPU device
//! (lavapipe) GPU memory is process memory, so a buffer, image or shader made per frame and
//! never freed shows here too: `vitreous soak` compares its passes.

use anyhow::{Context, Result};

/// Resident memory of this process, kibibytes (`VmRSS` in `/proc/self/status`: no page size
/// to assume).
pub fn resident_kib() -> Result<u64> {
    let status =
        std::fs::read_to_string("/proc/self/status").context("reading /proc/self/status")?;
    vm_rss_kib(&status).context("no VmRSS line in /proc/self/status")
}

/// The `VmRSS:  123456 kB` line of a `/proc/<pid>/status` text, kibibytes.
fn vm_rss_kib(status: &str) -> Option<u64> {
    let line = status.lines().find_map(|l| l.strip_prefix("VmRSS:"))?;
    let kib = line.trim().strip_suffix("kB")?;
    kib.trim().parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resident_line_is_read_in_kibibytes() {
        let status = "Name:\tvitreous\nVmPeak:\t  900 kB\nVmRSS:\t  123456 kB\nThreads:\t4\n";
        assert_eq!(vm_rss_kib(status), Some(123_456));
        assert_eq!(vm_rss_kib("Name:\tvitreous\n"), None);
        assert_eq!(vm_rss_kib("VmRSS:\t12 MB\n"), None);
    }

    #[test]
    fn this_process_is_resident() {
        let kib = resident_kib().expect("reading this process's resident memory");
        assert!(kib > 100, "{kib} KiB");
    }
}
