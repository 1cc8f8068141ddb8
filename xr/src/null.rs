//! The null backend: replays a trace as frames, with no headset and no real-time pacing.
//!
//! Frame `k` is displayed at `t0 + k / frame_rate_hz` (rounded to the nanosecond), where `t0`
//! is the first sample's time, for as long as that time is not after the last sample's time
//! (or until `max_frames`). For each frame:
//! - the head pose is interpolated between the samples around the frame time (position
//!   linearly, orientation by slerp);
//! - the gaze is the newest sample whose `sample_time_ns` is at or before the frame time, so a
//!   30 Hz tracker seen by a 90 Hz loop gives the same sample (same `sample_time_ns`) to about
//!   three frames: samples are never invented or interpolated;
//! - each eye's position in the head frame is the running mean of that eye's valid gaze-ray
//!   origins over every gaze sample up to the frame time (±`ipd_m / 2` along head x until one
//!   is valid); the eye views are the head pose moved to those positions, with the head's
//!   orientation (displays are fixed to the head) and the configured field of view.
//!
//! Samples are pulled from the source only as far as needed, so a streaming [`TraceReader`]
//! replays arbitrarily long traces in constant memory (apart from gaze samples repeated
//! across many head samples).

use std::collections::VecDeque;
use std::io::BufRead;

use glam::Vec3;
use thiserror::Error;

use crate::frame::{Backend, EyeView, Fov, FrameInput, GazeSample, Pose};
use crate::trace::{MAX_SAMPLE_GAP_NS, MAX_TRACE_SPAN_NS, TraceError, TraceReader, TraceSample};

/// How the null backend turns a trace into frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NullConfig {
    /// Frames per second of the replayed display, hertz.
    pub frame_rate_hz: f64,
    /// Stop after this many frames even if the trace goes on.
    pub max_frames: Option<u64>,
    /// Field of view of both eyes.
    pub fov: Fov,
    /// Eye separation used until the trace has a valid gaze origin for an eye, metres.
    pub ipd_m: f32,
}

impl Default for NullConfig {
    fn default() -> Self {
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: None,
            fov: Fov::symmetric(90f32.to_radians(), 90f32.to_radians()),
            ipd_m: 0.063,
        }
    }
}

/// Errors of the null backend.
#[derive(Debug, Error)]
pub enum NullError {
    /// The trace has no samples.
    #[error("{source_name}: trace has no samples; nothing to replay")]
    EmptyTrace {
        /// Name of the trace (file name or description).
        source_name: String,
    },
    /// Reading the trace failed.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// A configuration value is out of range.
    #[error("null backend config `{field}` is {value}; expected {expected}")]
    BadConfig {
        /// The field of [`NullConfig`].
        field: &'static str,
        /// Its value, printed.
        value: String,
        /// What it should be.
        expected: &'static str,
    },
    /// Samples handed in directly span more time than a trace may
    /// ([`MAX_SAMPLE_GAP_NS`] after the previous sample, [`MAX_TRACE_SPAN_NS`] after the first).
    #[error(
        "{source_name}: sample {index}: time_ns {time_ns} is too far after {what} {reference_ns} (at most {limit_s} s)"
    )]
    TooLong {
        /// Name of the trace.
        source_name: String,
        /// Index of the offending sample (0-based).
        index: u64,
        /// Its time.
        time_ns: i64,
        /// Which earlier sample the limit is measured from.
        what: &'static str,
        /// That sample's time.
        reference_ns: i64,
        /// The limit, seconds.
        limit_s: i64,
    },
    /// Samples handed in directly are not in time order.
    #[error(
        "{source_name}: sample {index}: {what} (time_ns {time_ns}, previous time_ns {previous_ns}); samples must have strictly increasing time_ns, non-decreasing gaze times and gaze time <= time_ns"
    )]
    OutOfOrder {
        /// Name of the trace.
        source_name: String,
        /// Index of the offending sample (0-based).
        index: u64,
        /// Which rule it breaks.
        what: &'static str,
        /// Its time.
        time_ns: i64,
        /// The previous sample's time.
        previous_ns: i64,
    },
    /// `wait_frame` and `end_frame` were not called alternately for the same frame.
    #[error("frame order: {0}")]
    FrameOrder(String),
}

/// Where samples come from: a vector or a streaming reader, behind one interface.
type SampleSource = Box<dyn Iterator<Item = Result<TraceSample, TraceError>> + Send>;

/// A [`Backend`] that replays a trace. See the module documentation for the timing rules.
pub struct NullBackend {
    /// Replay settings.
    config: NullConfig,
    /// Name of the trace, for errors.
    name: String,
    /// Remaining samples not yet buffered.
    source: SampleSource,
    /// True once the source has ended.
    exhausted: bool,
    /// Samples still needed (head bracket and newest gaze onwards), oldest first.
    buffer: VecDeque<TraceSample>,
    /// Absolute index (in the trace) of `buffer[0]`.
    buffer_base: u64,
    /// Number of samples read from the source so far.
    read_count: u64,
    /// Samples with absolute index below this have been added to the eye-position means.
    gaze_counted: u64,
    /// Sum of valid gaze-ray origins per eye (left, right), head frame, metres.
    origin_sum_m: [Vec3; 2],
    /// Number of valid gaze-ray origins per eye.
    origin_count: [u64; 2],
    /// Time of the first sample, nanoseconds.
    t0_ns: i64,
    /// Time of the first sample, once read (for the span check).
    first_ns: Option<i64>,
    /// Index of the next frame to hand out.
    next_index: u64,
    /// The frame handed out and not yet ended.
    pending: Option<u64>,
    /// True once the replay has ended (or failed).
    done: bool,
}

impl NullBackend {
    /// Replays samples held in memory. They must be in time order (as a trace file is).
    pub fn new(samples: Vec<TraceSample>, config: NullConfig) -> Result<Self, NullError> {
        NullBackend::from_source(
            Box::new(samples.into_iter().map(Ok)),
            "<samples>".to_owned(),
            config,
        )
    }

    /// Replays a trace file as it is read.
    pub fn from_reader<R: BufRead + Send + 'static>(
        reader: TraceReader<R>,
        config: NullConfig,
    ) -> Result<Self, NullError> {
        let name = reader.name().to_owned();
        NullBackend::from_source(Box::new(reader), name, config)
    }

    /// Opens and replays a trace file.
    pub fn open(path: impl AsRef<std::path::Path>, config: NullConfig) -> Result<Self, NullError> {
        NullBackend::from_reader(TraceReader::open(path)?, config)
    }

    fn from_source(
        source: SampleSource,
        name: String,
        config: NullConfig,
    ) -> Result<Self, NullError> {
        if !(config.frame_rate_hz.is_finite() && config.frame_rate_hz > 0.0) {
            return Err(NullError::BadConfig {
                field: "frame_rate_hz",
                value: config.frame_rate_hz.to_string(),
                expected: "a finite rate > 0 Hz",
            });
        }
        if !(config.ipd_m.is_finite() && config.ipd_m >= 0.0) {
            return Err(NullError::BadConfig {
                field: "ipd_m",
                value: config.ipd_m.to_string(),
                expected: "a finite distance >= 0 m",
            });
        }
        let mut this = NullBackend {
            config,
            name,
            source,
            exhausted: false,
            buffer: VecDeque::new(),
            buffer_base: 0,
            read_count: 0,
            gaze_counted: 0,
            origin_sum_m: [Vec3::ZERO; 2],
            origin_count: [0; 2],
            t0_ns: 0,
            first_ns: None,
            next_index: 0,
            pending: None,
            done: false,
        };
        if !this.pull()? {
            return Err(NullError::EmptyTrace {
                source_name: this.name,
            });
        }
        this.t0_ns = this.buffer[0].time_ns;
        Ok(this)
    }

    /// The replay settings.
    pub fn config(&self) -> &NullConfig {
        &self.config
    }

    /// Time of the first sample, which is the time of frame 0, nanoseconds.
    pub fn start_time_ns(&self) -> i64 {
        self.t0_ns
    }

    /// Current estimate of the left and right eye positions in the head frame, metres.
    pub fn eye_positions_head_m(&self) -> [Vec3; 2] {
        let default_m = [
            Vec3::new(-self.config.ipd_m / 2.0, 0.0, 0.0),
            Vec3::new(self.config.ipd_m / 2.0, 0.0, 0.0),
        ];
        std::array::from_fn(|eye| match self.origin_count[eye] {
            0 => default_m[eye],
            n => self.origin_sum_m[eye] / n as f32,
        })
    }

    /// Reads one sample into the buffer, checking its order; `false` at the end of the source.
    fn pull(&mut self) -> Result<bool, NullError> {
        let Some(next) = self.source.next() else {
            self.exhausted = true;
            return Ok(false);
        };
        let sample = next?;
        let index = self.read_count;
        let out_of_order = |what, previous_ns| NullError::OutOfOrder {
            source_name: self.name.clone(),
            index,
            what,
            time_ns: sample.time_ns,
            previous_ns,
        };
        if sample.gaze.sample_time_ns > sample.time_ns {
            return Err(out_of_order("gaze time after time_ns", sample.time_ns));
        }
        if let Some(prev) = self.buffer.back() {
            if sample.time_ns <= prev.time_ns {
                return Err(out_of_order("time_ns not increasing", prev.time_ns));
            }
            if sample.gaze.sample_time_ns < prev.gaze.sample_time_ns {
                return Err(out_of_order("gaze time decreasing", prev.time_ns));
            }
            // The trace reader checks the same limits with the line; samples handed in
            // directly get them here.
            let first_ns = self.first_ns.unwrap_or(prev.time_ns);
            let too_long = |reference_ns: i64, what, limit_ns: i64| {
                (i128::from(sample.time_ns) - i128::from(reference_ns) > i128::from(limit_ns)).then(
                    || NullError::TooLong {
                        source_name: self.name.clone(),
                        index,
                        time_ns: sample.time_ns,
                        what,
                        reference_ns,
                        limit_s: limit_ns / 1_000_000_000,
                    },
                )
            };
            if let Some(e) = too_long(prev.time_ns, "the previous sample's", MAX_SAMPLE_GAP_NS)
                .or_else(|| too_long(first_ns, "the first sample's", MAX_TRACE_SPAN_NS))
            {
                return Err(e);
            }
        }
        self.first_ns.get_or_insert(sample.time_ns);
        self.buffer.push_back(sample);
        self.read_count += 1;
        Ok(true)
    }

    /// The frame at `time_ns`, or `None` past the end of the trace.
    fn frame_at(&mut self, index: u64, time_ns: i64) -> Result<Option<FrameInput>, NullError> {
        // Gaze times never decrease, so once one is after the frame time no later sample can
        // be this frame's gaze; and since gaze time <= time_ns, the head bracket is covered too.
        while !self.exhausted
            && self
                .buffer
                .back()
                .is_none_or(|s| s.gaze.sample_time_ns <= time_ns)
        {
            self.pull()?;
        }
        let Some(last) = self.buffer.back() else {
            return Ok(None);
        };
        if time_ns > last.time_ns {
            return Ok(None);
        }
        // Last sample at or before the frame (exists: the buffer starts at or before it).
        let a = self
            .buffer
            .iter()
            .rposition(|s| s.time_ns <= time_ns)
            .unwrap_or(0);
        let head = match self.buffer.get(a + 1) {
            Some(b) if self.buffer[a].time_ns < time_ns => {
                let sa = &self.buffer[a];
                // In 128 bits: the differences of any two i64 times fit.
                let f = (i128::from(time_ns) - i128::from(sa.time_ns)) as f64
                    / (i128::from(b.time_ns) - i128::from(sa.time_ns)) as f64;
                interpolate(&sa.head, &b.head, f as f32)
            }
            _ => self.buffer[a].head,
        };
        let g = self
            .buffer
            .iter()
            .rposition(|s| s.gaze.sample_time_ns <= time_ns);
        let gaze = g.map(|g| self.buffer[g].gaze);
        if let Some(g) = g {
            self.count_gaze_up_to(self.buffer_base + g as u64);
        }

        let eyes = self.eye_positions_head_m();
        let views = eyes.map(|eye_m| EyeView {
            pose: Pose {
                position: head.transform_point(eye_m),
                orientation: head.orientation,
            },
            fov: self.config.fov,
        });

        // Frame times increase: samples before both the head bracket and the gaze are done.
        let keep_from = g.map_or(0, |g| g.min(a));
        for _ in 0..keep_from {
            self.buffer.pop_front();
            self.buffer_base += 1;
        }
        Ok(Some(FrameInput {
            index,
            time_ns,
            head,
            views,
            gaze,
        }))
    }

    /// Adds the gaze origins of samples up to absolute index `last` (inclusive) to the means.
    fn count_gaze_up_to(&mut self, last: u64) {
        while self.gaze_counted <= last {
            let sample = &self.buffer[(self.gaze_counted - self.buffer_base) as usize];
            add_origins(&sample.gaze, &mut self.origin_sum_m, &mut self.origin_count);
            self.gaze_counted += 1;
        }
    }
}

/// Adds each valid eye's ray origin to its running sum.
fn add_origins(gaze: &GazeSample, sum_m: &mut [Vec3; 2], count: &mut [u64; 2]) {
    for (eye, ray) in [gaze.left, gaze.right].into_iter().enumerate() {
        if ray.valid && ray.origin.is_finite() {
            sum_m[eye] += ray.origin;
            count[eye] += 1;
        }
    }
}

/// The pose a fraction `f` of the way from `a` to `b`: lerp position, slerp orientation.
pub fn interpolate(a: &Pose, b: &Pose, f: f32) -> Pose {
    Pose {
        position: a.position.lerp(b.position, f),
        orientation: a.orientation.slerp(b.orientation, f).normalize(),
    }
}

impl Backend for NullBackend {
    type Error = NullError;

    fn wait_frame(&mut self) -> Result<Option<FrameInput>, NullError> {
        if let Some(index) = self.pending {
            return Err(NullError::FrameOrder(format!(
                "wait_frame called before end_frame for frame {index}"
            )));
        }
        if self.done {
            return Ok(None);
        }
        let index = self.next_index;
        if self.config.max_frames.is_some_and(|max| index >= max) {
            self.done = true;
            return Ok(None);
        }
        // A frame time past the end of i64 is past the last sample: the replay ends (saturating
        // instead would show the last sample forever).
        let offset_ns = (index as f64 * 1e9 / self.config.frame_rate_hz).round();
        let time_ns = if offset_ns < i64::MAX as f64 {
            self.t0_ns.checked_add(offset_ns as i64)
        } else {
            None
        };
        let Some(time_ns) = time_ns else {
            self.done = true;
            return Ok(None);
        };
        match self.frame_at(index, time_ns) {
            Ok(Some(frame)) => {
                self.next_index += 1;
                self.pending = Some(index);
                Ok(Some(frame))
            }
            Ok(None) => {
                self.done = true;
                Ok(None)
            }
            Err(e) => {
                self.done = true;
                Err(e)
            }
        }
    }

    fn end_frame(&mut self, frame: &FrameInput) -> Result<(), NullError> {
        match self.pending {
            Some(index) if index == frame.index => {
                self.pending = None;
                Ok(())
            }
            Some(index) => Err(NullError::FrameOrder(format!(
                "end_frame for frame {} but frame {index} is the one in flight",
                frame.index
            ))),
            None => Err(NullError::FrameOrder(format!(
                "end_frame for frame {} with no frame in flight",
                frame.index
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::GazeRay;
    use crate::synth::{SynthParams, synthesize};
    use crate::trace::TraceWriter;
    use glam::Quat;

    fn sample(time_ns: i64, position: Vec3, yaw_rad: f32) -> TraceSample {
        TraceSample {
            time_ns,
            head: Pose {
                position,
                orientation: Quat::from_rotation_y(yaw_rad),
            },
            gaze: GazeSample {
                sample_time_ns: time_ns,
                left: GazeRay::INVALID,
                right: GazeRay::INVALID,
                combined: None,
                fixation: None,
            },
        }
    }

    fn run(backend: &mut NullBackend) -> Vec<FrameInput> {
        let mut frames = Vec::new();
        while let Some(f) = backend.wait_frame().unwrap() {
            backend.end_frame(&f).unwrap();
            frames.push(f);
        }
        frames
    }

    fn ten_ms_trace() -> Vec<TraceSample> {
        (0..=10)
            .map(|i| sample(5_000_000_000 + i * 10_000_000, Vec3::ZERO, 0.0))
            .collect()
    }

    #[test]
    fn frame_count_and_times_follow_the_frame_rate() {
        let mut b = NullBackend::new(ten_ms_trace(), NullConfig::default()).unwrap();
        let frames = run(&mut b);
        let times: Vec<i64> = frames.iter().map(|f| f.time_ns - 5_000_000_000).collect();
        assert_eq!(
            times,
            [
                0,
                16_666_667,
                33_333_333,
                50_000_000,
                66_666_667,
                83_333_333,
                100_000_000
            ]
        );
        assert!(frames.iter().enumerate().all(|(i, f)| f.index == i as u64));
        assert!(b.wait_frame().unwrap().is_none());

        let config = NullConfig {
            max_frames: Some(3),
            ..NullConfig::default()
        };
        let mut b = NullBackend::new(ten_ms_trace(), config).unwrap();
        assert_eq!(run(&mut b).len(), 3);
    }

    #[test]
    fn fast_loop_repeats_tracker_samples_without_inventing_any() {
        let samples = synthesize(&SynthParams {
            duration_s: 1.0,
            rate_hz: 30.0,
            blink_every_s: 0.0,
            ..SynthParams::default()
        });
        assert_eq!(samples.len(), 31);
        let config = NullConfig {
            frame_rate_hz: 90.0,
            ..NullConfig::default()
        };
        let mut b = NullBackend::new(samples.clone(), config).unwrap();
        let frames = run(&mut b);
        assert_eq!(frames.len(), 91);
        for (k, f) in frames.iter().enumerate() {
            let gaze = f.gaze.unwrap();
            // Each 30 Hz sample serves three 90 Hz frames, unchanged.
            assert_eq!(gaze, samples[k / 3].gaze, "frame {k}");
            assert!(gaze.sample_time_ns <= f.time_ns);
        }
    }

    #[test]
    fn views_are_an_ipd_apart_along_head_x() {
        let samples = vec![
            sample(0, Vec3::new(1.0, 1.6, 0.0), 0.7),
            sample(1_000_000_000, Vec3::new(1.0, 1.6, 0.0), 0.7),
        ];
        let mut b = NullBackend::new(samples, NullConfig::default()).unwrap();
        let f = b.wait_frame().unwrap().unwrap();
        let head_x = f.head.transform_vector(Vec3::X);
        let d = f.views[1].pose.position - f.views[0].pose.position;
        assert!(d.abs_diff_eq(head_x * 0.063, 1e-6), "{d}");
        assert_eq!(f.views[0].pose.orientation, f.head.orientation);
        assert_eq!(f.views[1].fov, NullConfig::default().fov);
        let mid = (f.views[0].pose.position + f.views[1].pose.position) / 2.0;
        assert!(mid.abs_diff_eq(f.head.position, 1e-6));
    }

    #[test]
    fn eye_positions_are_the_mean_of_valid_gaze_origins() {
        let mut samples = ten_ms_trace();
        let ray = |x: f32| GazeRay {
            origin: Vec3::new(x, 0.0, 0.03),
            direction: Vec3::NEG_Z,
            valid: true,
        };
        samples[0].gaze.left = ray(-0.030);
        samples[1].gaze.left = ray(-0.034);
        samples[1].gaze.right = ray(0.031);
        let config = NullConfig {
            frame_rate_hz: 100.0,
            ..NullConfig::default()
        };
        let mut b = NullBackend::new(samples, config).unwrap();
        let f0 = b.wait_frame().unwrap().unwrap();
        b.end_frame(&f0).unwrap();
        assert!(
            f0.views[0]
                .pose
                .position
                .abs_diff_eq(Vec3::new(-0.030, 0.0, 0.03), 1e-6)
        );
        assert!(
            f0.views[1]
                .pose
                .position
                .abs_diff_eq(Vec3::new(0.0315, 0.0, 0.0), 1e-6)
        );
        let f1 = b.wait_frame().unwrap().unwrap();
        assert!(
            f1.views[0]
                .pose
                .position
                .abs_diff_eq(Vec3::new(-0.032, 0.0, 0.03), 1e-6)
        );
        assert!(
            f1.views[1]
                .pose
                .position
                .abs_diff_eq(Vec3::new(0.031, 0.0, 0.03), 1e-6)
        );
    }

    #[test]
    fn head_pose_is_interpolated_midway() {
        let samples = vec![
            sample(0, Vec3::ZERO, 0.0),
            sample(
                1_000_000_000,
                Vec3::new(1.0, 0.0, 0.0),
                std::f32::consts::FRAC_PI_2,
            ),
        ];
        let config = NullConfig {
            frame_rate_hz: 2.0,
            ..NullConfig::default()
        };
        let mut b = NullBackend::new(samples.clone(), config).unwrap();
        let frames = run(&mut b);
        assert_eq!(frames.len(), 3);
        let mid = frames[1].head;
        assert!(mid.position.abs_diff_eq(Vec3::new(0.5, 0.0, 0.0), 1e-6));
        let expected = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(
            mid.orientation.abs_diff_eq(expected, 1e-6),
            "{}",
            mid.orientation
        );
        // Gaze is the newest sample at or before the frame, not an interpolation.
        assert_eq!(frames[1].gaze.unwrap().sample_time_ns, 0);
        assert_eq!(frames[2].head, samples[1].head);
    }

    #[test]
    fn streams_from_a_trace_reader() {
        let samples = synthesize(&SynthParams {
            duration_s: 2.0,
            ..SynthParams::default()
        });
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        for s in &samples {
            w.write(s).unwrap();
        }
        let text = w.finish().unwrap();
        let reader = TraceReader::new(std::io::Cursor::new(text), "synth.trace").unwrap();
        let mut streamed = NullBackend::from_reader(reader, NullConfig::default()).unwrap();
        let mut in_memory = NullBackend::new(samples, NullConfig::default()).unwrap();
        assert_eq!(run(&mut streamed), run(&mut in_memory));
    }

    #[test]
    fn empty_or_broken_traces_are_errors_not_panics() {
        let e = NullBackend::new(Vec::new(), NullConfig::default())
            .err()
            .unwrap();
        assert!(matches!(e, NullError::EmptyTrace { .. }), "{e}");
        let header_only = format!(
            "{}\n{}\n",
            crate::trace::VERSION_LINE,
            crate::trace::COLUMNS.join(",")
        );
        let reader = TraceReader::new(std::io::Cursor::new(header_only), "empty.trace").unwrap();
        let e = NullBackend::from_reader(reader, NullConfig::default())
            .err()
            .unwrap();
        assert!(e.to_string().contains("empty.trace"), "{e}");

        let backwards = vec![sample(10, Vec3::ZERO, 0.0), sample(5, Vec3::ZERO, 0.0)];
        let mut b = NullBackend::new(backwards, NullConfig::default()).unwrap();
        assert!(matches!(
            b.wait_frame(),
            Err(NullError::OutOfOrder { index: 1, .. })
        ));
        assert!(b.wait_frame().unwrap().is_none());

        let bad_rate = NullConfig {
            frame_rate_hz: 0.0,
            ..NullConfig::default()
        };
        assert!(NullBackend::new(ten_ms_trace(), bad_rate).is_err());
    }

    #[test]
    fn samples_spanning_too_long_are_refused() {
        let gap = vec![
            sample(0, Vec3::ZERO, 0.0),
            sample(MAX_SAMPLE_GAP_NS + 1, Vec3::ZERO, 0.0),
        ];
        let mut b = NullBackend::new(gap, NullConfig::default()).unwrap();
        let e = b.wait_frame().unwrap_err();
        assert!(matches!(e, NullError::TooLong { index: 1, .. }), "{e}");
        let overflow = vec![
            sample(i64::MIN, Vec3::ZERO, 0.0),
            sample(i64::MAX, Vec3::ZERO, 0.0),
        ];
        let mut b = NullBackend::new(overflow, NullConfig::default()).unwrap();
        assert!(matches!(b.wait_frame(), Err(NullError::TooLong { .. })));
        let step = MAX_SAMPLE_GAP_NS;
        let long: Vec<_> = (0..=MAX_TRACE_SPAN_NS / step + 1)
            .map(|i| sample(i * step, Vec3::ZERO, 0.0))
            .collect();
        let config = NullConfig {
            frame_rate_hz: 1e-3,
            ..NullConfig::default()
        };
        let mut b = NullBackend::new(long, config).unwrap();
        let e = loop {
            match b.wait_frame() {
                Ok(Some(f)) => b.end_frame(&f).unwrap(),
                Ok(None) => panic!("replay ended without refusing the trace"),
                Err(e) => break e,
            }
        };
        assert!(e.to_string().contains("the first sample's"), "{e}");
    }

    #[test]
    fn a_trace_ending_near_the_end_of_time_ends_the_replay() {
        let near_end = vec![
            sample(i64::MAX - 20_000_000, Vec3::ZERO, 0.0),
            sample(i64::MAX, Vec3::ZERO, 0.0),
        ];
        let mut b = NullBackend::new(near_end, NullConfig::default()).unwrap();
        let mut frames = 0;
        while let Some(f) = b.wait_frame().unwrap() {
            b.end_frame(&f).unwrap();
            frames += 1;
            assert!(frames < 10, "replay does not end");
        }
        assert_eq!(frames, 2);
    }

    #[test]
    fn frame_calls_must_alternate() {
        let mut b = NullBackend::new(ten_ms_trace(), NullConfig::default()).unwrap();
        let f = b.wait_frame().unwrap().unwrap();
        assert!(matches!(b.wait_frame(), Err(NullError::FrameOrder(_))));
        b.end_frame(&f).unwrap();
        assert!(matches!(b.end_frame(&f), Err(NullError::FrameOrder(_))));
    }

    #[test]
    fn backend_is_send() {
        fn is_send<T: Send>() {}
        is_send::<NullBackend>();
    }
}
