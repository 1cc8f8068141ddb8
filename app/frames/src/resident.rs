//! The process's resident memory (Linux and Android: `/proc/self/status`), and its samples over
//! a session's frames. On a CPU device (lavapipe) GPU memory is process memory, so a buffer,
//! image or shader made per frame and never freed shows here too: `vitreous soak` compares its
//! passes, `vitreous run` reports its frames' ([`ResidentSampler`]).

use anyhow::{Context, Result};
use serde::Serialize;

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

/// Resident memory over a session's frames after a warm-up (the first frames compile shader
/// variants on first use and fill the allocators' pools): the first sample, the last, the
/// largest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidentMemory {
    /// Frames left out before the first sample.
    pub warm_up_frames: u64,
    /// Frame index of the first sample.
    pub first_frame: u64,
    /// Resident memory then, kibibytes.
    pub first_kib: u64,
    /// Frame index of the last sample: the session's last finished frame.
    pub last_frame: u64,
    /// Resident memory then, kibibytes.
    pub last_kib: u64,
    /// The largest sample, kibibytes.
    pub max_kib: u64,
    /// Samples taken.
    pub samples: u64,
    /// Growth of the last sample over the first, percent.
    pub growth_percent: f64,
}

/// Samples resident memory every few frames once the warm-up is over, and once more at the end.
#[derive(Clone, Debug)]
pub struct ResidentSampler {
    warm_up_frames: u64,
    every: u64,
    memory: Option<ResidentMemory>,
    /// The last finished frame's index, once past warm-up.
    last_frame: Option<u64>,
    /// Whether a read failed (logged once).
    failed: bool,
}

impl ResidentSampler {
    /// A sampler whose first sample is at frame `warm_up_frames`, then every `every` frames
    /// (at least 1).
    pub fn new(warm_up_frames: u64, every: u64) -> ResidentSampler {
        ResidentSampler {
            warm_up_frames,
            every: every.max(1),
            memory: None,
            last_frame: None,
            failed: false,
        }
    }

    /// Frame `index` finished: samples when one is due. A failed read is logged once and
    /// leaves the record as it was.
    pub fn frame(&mut self, index: u64) {
        if index < self.warm_up_frames {
            return;
        }
        self.last_frame = Some(index);
        if (index - self.warm_up_frames).is_multiple_of(self.every) {
            self.sample(index);
        }
    }

    /// The record, with a last sample taken now for the last finished frame (call it once the
    /// session's frames are done); `None` when no frame finished after the warm-up or memory
    /// could not be read.
    pub fn finish(&mut self) -> Option<ResidentMemory> {
        if let Some(last) = self.last_frame
            && self.memory.as_ref().is_some_and(|m| m.last_frame != last)
        {
            self.sample(last);
        }
        self.memory.clone()
    }

    fn sample(&mut self, index: u64) {
        match resident_kib() {
            Ok(kib) => self.record(index, kib),
            Err(e) if !self.failed => {
                self.failed = true;
                tracing::warn!("resident memory not sampled: {e:#}");
            }
            Err(_) => {}
        }
    }

    /// Adds a sample of `kib` at frame `index`.
    fn record(&mut self, index: u64, kib: u64) {
        let memory = self.memory.get_or_insert(ResidentMemory {
            warm_up_frames: self.warm_up_frames,
            first_frame: index,
            first_kib: kib,
            last_frame: index,
            last_kib: kib,
            max_kib: kib,
            samples: 0,
            growth_percent: 0.0,
        });
        memory.last_frame = index;
        memory.last_kib = kib;
        memory.max_kib = memory.max_kib.max(kib);
        memory.samples += 1;
        memory.growth_percent = (kib as f64 / memory.first_kib as f64 - 1.0) * 100.0;
    }
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

    #[test]
    fn samples_start_after_the_warm_up_and_growth_is_last_over_first() {
        let mut sampler = ResidentSampler::new(10, 5);
        for index in 0..10 {
            sampler.frame(index);
        }
        assert!(sampler.memory.is_none(), "sampled during the warm-up");
        for (index, kib) in [(10, 1000), (15, 1100), (20, 1050)] {
            sampler.record(index, kib);
        }
        let memory = sampler.memory.expect("three samples");
        assert_eq!((memory.first_frame, memory.first_kib), (10, 1000));
        assert_eq!((memory.last_frame, memory.last_kib), (20, 1050));
        assert_eq!((memory.max_kib, memory.samples), (1100, 3));
        assert!((memory.growth_percent - 5.0).abs() < 1e-9, "{memory:?}");
    }

    #[test]
    fn a_session_that_ends_in_its_warm_up_has_no_record() {
        let mut sampler = ResidentSampler::new(10, 5);
        for index in 0..10 {
            sampler.frame(index);
        }
        assert_eq!(sampler.finish(), None);
    }

    #[test]
    fn the_end_adds_a_sample_at_the_last_frame() {
        let mut sampler = ResidentSampler::new(2, 10);
        for index in 0..7 {
            sampler.frame(index);
        }
        let memory = sampler.finish().expect("frames past the warm-up");
        assert_eq!((memory.first_frame, memory.last_frame), (2, 6));
        assert_eq!(memory.samples, 2);
    }
}
