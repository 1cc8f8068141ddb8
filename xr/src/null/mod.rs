//! The null backend: replays a trace as frames, with no headset and no real-time pacing.
//!
//! Frame `k` is displayed at `t0 + k / frame_rate_hz` (rounded to the nanosecond), where `t0`
//! is the first sample's time, for as long as that time is not after the last sample's time
//! (or until `max_frames`). With [`NullConfig::at_samples`], frame `k` is displayed at sample
//! `k`'s own time instead: one frame per sample, as the live session that recorded the trace
//! rendered it. For each frame:
//! - the head pose is interpolated between the samples around the frame time (position
//!   linearly, orientation by slerp);
//! - the gaze is that of the newest sample (line) at or before the frame time, what was known
//!   then: a 30 Hz tracker seen by a 90 Hz loop gives the same gaze sample (same
//!   `sample_time_ns`) to about three frames, and a gaze sample stamped before the frame but
//!   written on a later line (it reached the recorder later: a tracker's latency) is not yet
//!   the frame's; samples are never invented or interpolated;
//! - each eye's view is the one the recording's newest views line at or before the frame time
//!   gives (version 1.5: the eyes the headset drew from, in the head's frame), with the
//!   configured field of view (the replay's images are its own size) or, asked
//!   ([`NullBackend::with_recorded_fields`]), the line's own; before any, or without
//!   views lines, each eye's position in the head frame is the running mean of that eye's
//!   valid gaze-ray origins over every gaze sample up to the frame time (±`ipd_m / 2` along
//!   head x until one is valid), the view the head's orientation (displays fixed to the head,
//!   parallel).
//!
//! Samples are pulled from the source only as far as needed, so a streaming [`TraceReader`]
//! replays arbitrarily long traces in constant memory (apart from gaze samples repeated
//! across many head samples).
mod sampling;
#[cfg(test)]
mod tests;

use std::collections::VecDeque;
use std::io::BufRead;

use glam::Vec3;
use thiserror::Error;
use vitreous_trace::format::{EventRecord, TraceError, TraceReader, TraceSample, ViewsRecord};
use vitreous_trace::session_event::SessionEvent;
use vitreous_trace::{Fov, FrameInput};

use crate::Backend;

pub use sampling::interpolate;

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
    /// One frame per sample, at the sample's time, instead of `frame_rate_hz`.
    pub at_samples: bool,
}

impl Default for NullConfig {
    fn default() -> Self {
        NullConfig {
            frame_rate_hz: 60.0,
            max_frames: None,
            fov: Fov::symmetric(90f32.to_radians(), 90f32.to_radians()),
            ipd_m: 0.063,
            at_samples: false,
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
    /// ([`vitreous_trace::format::MAX_SAMPLE_GAP_NS`] after the previous sample,
    /// [`vitreous_trace::format::MAX_TRACE_SPAN_NS`] after the first).
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

/// Where samples come from: a vector or a streaming reader, behind one interface; a reader
/// also hands over the event lines (version 1.4) it read on the way.
trait Samples: Iterator<Item = Result<TraceSample, TraceError>> + Send {
    /// The event lines read since the last call.
    fn take_events(&mut self) -> Vec<EventRecord> {
        Vec::new()
    }

    /// The views lines read since the last call.
    fn take_views(&mut self) -> Vec<ViewsRecord> {
        Vec::new()
    }
}

impl Samples for std::vec::IntoIter<Result<TraceSample, TraceError>> {}

impl<R: std::io::Read + Send> Samples for TraceReader<R> {
    fn take_events(&mut self) -> Vec<EventRecord> {
        TraceReader::take_events(self)
    }

    fn take_views(&mut self) -> Vec<ViewsRecord> {
        TraceReader::take_views(self)
    }
}

/// The samples' source.
type SampleSource = Box<dyn Samples>;

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
    /// Display time of the last frame handed out.
    last_time_ns: Option<i64>,
    /// True once the replay has ended (or failed).
    done: bool,
    /// The recording's session events not yet handed out, oldest first.
    events: VecDeque<EventRecord>,
    /// Those that came with the frames handed out since the last [`Backend::take_events`].
    ready: Vec<SessionEvent>,
    /// The recording's views lines not yet in force, oldest first.
    views: VecDeque<ViewsRecord>,
    /// The views in force: the newest line at or before the last frame.
    views_now: Option<ViewsRecord>,
    /// Whether a views line's fields are drawn ([`NullBackend::with_recorded_fields`]) rather
    /// than the configured one.
    recorded_fields: bool,
}

impl NullBackend {
    /// Replays samples held in memory. They must be in time order (as a trace file is).
    pub fn new(samples: Vec<TraceSample>, config: NullConfig) -> Result<Self, NullError> {
        let samples: Vec<Result<TraceSample, TraceError>> = samples.into_iter().map(Ok).collect();
        NullBackend::from_source(
            Box::new(samples.into_iter()),
            "<samples>".to_owned(),
            config,
        )
    }

    /// Hands `events` (a recording's, in time order) out with the frames they came with: each
    /// with the first frame displayed at or after its time ([`Backend::take_events`]).
    pub fn with_events(mut self, events: Vec<EventRecord>) -> Self {
        self.events.extend(events);
        self
    }

    /// Draws each frame from the eyes of `views` (a recording's, in time order): the newest
    /// at or before the frame's time.
    pub fn with_views(mut self, views: Vec<ViewsRecord>) -> Self {
        self.views.extend(views);
        self
    }

    /// Draws each eye with the field of view of the views line in force (the headset's), not
    /// the configured one; frames before the first views line keep the configured field.
    pub fn with_recorded_fields(mut self) -> Self {
        self.recorded_fields = true;
        self
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
            last_time_ns: None,
            done: false,
            events: VecDeque::new(),
            ready: Vec::new(),
            views: VecDeque::new(),
            views_now: None,
            recorded_fields: false,
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

    /// The time of the first sample after the last frame handed out (the first sample for
    /// frame 0); `None` once the trace has ended.
    fn next_sample_time(&mut self) -> Result<Option<i64>, NullError> {
        let after = self.last_time_ns;
        loop {
            if let Some(s) = self
                .buffer
                .iter()
                .find(|s| after.is_none_or(|t| s.time_ns > t))
            {
                return Ok(Some(s.time_ns));
            }
            if self.exhausted || !self.pull()? {
                return Ok(None);
            }
        }
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
        let time_ns = if self.config.at_samples {
            match self.next_sample_time() {
                Ok(t) => t,
                Err(e) => {
                    self.done = true;
                    return Err(e);
                }
            }
        } else {
            // A frame time past the end of i64 is past the last sample: the replay ends
            // (saturating instead would show the last sample forever).
            let offset_ns = (index as f64 * 1e9 / self.config.frame_rate_hz).round();
            if offset_ns < i64::MAX as f64 {
                self.t0_ns.checked_add(offset_ns as i64)
            } else {
                None
            }
        };
        let Some(time_ns) = time_ns else {
            self.done = true;
            return Ok(None);
        };
        match self.frame_at(index, time_ns) {
            Ok(Some(frame)) => {
                self.next_index += 1;
                self.last_time_ns = Some(time_ns);
                self.pending = Some(index);
                self.events.extend(self.source.take_events());
                while let Some(e) = self.events.front().filter(|e| e.time_ns <= time_ns) {
                    self.ready.push(e.event);
                    self.events.pop_front();
                }
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

    fn take_events(&mut self) -> Vec<SessionEvent> {
        if self.done && self.exhausted {
            // The trace is over: what came after its last frame too.
            self.events.extend(self.source.take_events());
            self.ready.extend(self.events.drain(..).map(|e| e.event));
        }
        std::mem::take(&mut self.ready)
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
