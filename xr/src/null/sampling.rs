//! Sampling the trace at frame times: pulling samples as far as needed (checking their
//! order and the trace time limits), the head pose between samples, the newest gaze sample,
//! and the running eye positions.

use glam::Vec3;
use vitreous_trace::format::{MAX_SAMPLE_GAP_NS, MAX_TRACE_SPAN_NS};
use vitreous_trace::{EyeView, FrameInput, GazeSample, Pose};

use super::{NullBackend, NullError};

impl NullBackend {
    /// Reads one sample into the buffer, checking its order; `false` at the end of the source.
    pub(super) fn pull(&mut self) -> Result<bool, NullError> {
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
    pub(super) fn frame_at(
        &mut self,
        index: u64,
        time_ns: i64,
    ) -> Result<Option<FrameInput>, NullError> {
        // The samples up to the first after the frame time: the head bracket and the gaze.
        while !self.exhausted && self.buffer.back().is_none_or(|s| s.time_ns <= time_ns) {
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
        // The gaze known at the frame time is the newest line's at or before it: a sample
        // stamped before the frame but written on a later line reached the recorder later (an
        // eye tracker's latency, or its clock behind the runtime's).
        let g = (self.buffer[a].time_ns <= time_ns).then_some(a);
        let gaze = g.map(|g| self.buffer[g].gaze);
        if let Some(g) = g {
            self.count_gaze_up_to(self.buffer_base + g as u64);
        }

        self.views.extend(self.source.take_views());
        while let Some(v) = self.views.front().filter(|v| v.time_ns <= time_ns) {
            self.views_now = Some(*v);
            self.views.pop_front();
        }
        let views = match &self.views_now {
            Some(recorded) => recorded.eyes.map(|eye| EyeView {
                pose: eye.in_world(&head),
                fov: if self.recorded_fields {
                    eye.fov
                } else {
                    self.config.fov
                },
            }),
            None => self.eye_positions_head_m().map(|eye_m| EyeView {
                pose: Pose {
                    position: head.transform_point(eye_m),
                    orientation: head.orientation,
                },
                fov: self.config.fov,
            }),
        };

        // Frame times increase: samples before the head bracket, whose first holds the gaze,
        // are done.
        for _ in 0..a {
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
