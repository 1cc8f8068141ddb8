//! `--trace FILE`: a recorded trace played in the window, with pause, single step and seek.

use vitreous_trace::format::TraceSample;
use vitreous_trace::{GazeSample, Pose};

/// Nanoseconds per second.
const NS_PER_S: i64 = 1_000_000_000;

/// Trace time a single step moves on, nanoseconds (one frame at 60 Hz).
const STEP_NS: i64 = NS_PER_S / 60;

/// A trace being played.
pub struct Playback {
    /// The samples, by time.
    samples: Vec<TraceSample>,
    /// Trace time shown, nanoseconds on the trace's clock.
    time_ns: i64,
    /// Whether the trace clock stands still.
    paused: bool,
}

impl Playback {
    /// Plays `samples` (not empty, by increasing time) from the first.
    pub fn new(samples: Vec<TraceSample>) -> Playback {
        let time_ns = samples.first().map_or(0, |s| s.time_ns);
        Playback {
            samples,
            time_ns,
            paused: false,
        }
    }

    /// Pauses or resumes; says which.
    pub fn toggle_pause(&mut self) -> &'static str {
        self.paused = !self.paused;
        if self.paused { "paused" } else { "playing" }
    }

    /// Pauses and moves one frame (1/60 s) on.
    pub fn step(&mut self) {
        self.paused = true;
        self.seek_ns(STEP_NS);
    }

    /// Moves the trace clock by `delta_ns`, within the trace.
    pub fn seek_ns(&mut self, delta_ns: i64) {
        let (first, last) = self.span();
        self.time_ns = self.time_ns.saturating_add(delta_ns).clamp(first, last);
    }

    /// Seconds from the trace's start to the time shown, and the trace's length in seconds.
    pub fn position_s(&self) -> (f64, f64) {
        let (first, last) = self.span();
        (
            (self.time_ns - first) as f64 * 1e-9,
            (last - first) as f64 * 1e-9,
        )
    }

    /// Whether the trace clock stands still.
    pub fn paused(&self) -> bool {
        self.paused
    }

    fn span(&self) -> (i64, i64) {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => (a.time_ns, b.time_ns),
            _ => (0, 0),
        }
    }

    /// Advances the clock by `dt_ns` of wall-clock time (unless paused; it stops at the end)
    /// and returns it with the newest sample at or before it: trace time, head pose, gaze.
    pub fn advance(&mut self, dt_ns: i64) -> (i64, Pose, GazeSample) {
        if !self.paused {
            self.seek_ns(dt_ns);
        }
        let i = self
            .samples
            .partition_point(|s| s.time_ns <= self.time_ns)
            .saturating_sub(1);
        let s = &self.samples[i];
        (self.time_ns, s.head, s.gaze)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn sample(i: i64) -> TraceSample {
        TraceSample {
            time_ns: i * NS_PER_S / 10,
            head: Pose {
                position: Vec3::X * i as f32,
                orientation: glam::Quat::IDENTITY,
            },
            gaze: GazeSample::none(i * NS_PER_S / 10),
        }
    }

    #[test]
    fn playback_follows_the_clock_pauses_steps_and_seeks_within_the_trace() {
        let mut p = Playback::new((0..=20).map(sample).collect());
        assert_eq!(p.advance(0).1.position.x, 0.0);
        assert_eq!(p.advance(NS_PER_S / 4).1.position.x, 2.0);
        p.toggle_pause();
        assert_eq!(p.advance(NS_PER_S).1.position.x, 2.0, "paused");
        p.seek_ns(NS_PER_S);
        assert_eq!(p.advance(0).1.position.x, 12.0);
        p.seek_ns(-10 * NS_PER_S);
        assert_eq!(p.advance(0).1.position.x, 0.0, "clamped at the start");
        for _ in 0..7 {
            p.step();
        }
        assert_eq!(
            p.advance(0).1.position.x,
            1.0,
            "seven 1/60 s steps: past 0.1 s"
        );
        p.toggle_pause();
        assert_eq!(
            p.advance(60 * NS_PER_S).1.position.x,
            20.0,
            "held at the end"
        );
        assert_eq!(p.position_s(), (2.0, 2.0));
    }
}
