//! The gaze of a Neon recording from its gaze stream: the visual gaze direction (a scene
//! camera pixel) from each eyeball centre, with the eye state nearest in time, one sample per
//! gaze record.

use glam::Vec3;

use super::raw::Stream;
use super::{
    Counts, EYE_STATE_MAX_GAP_NS, Inputs, Timeline, eye_ray, neon_to_openxr, pupil_m, sample_time,
};
use crate::format::{TraceSample, clean_ray};
use crate::frame::{GazeRay, GazeSample};
use crate::import::RecordingError;

impl Inputs {
    /// The samples of the gaze stream: the visual gaze direction from each eyeball centre.
    pub(super) fn samples_from_gaze(
        &self,
        gaze: &Stream,
        timeline: &Timeline,
        counts: &mut Counts,
    ) -> Result<Vec<TraceSample>, RecordingError> {
        let eye_order = sorted_by_time(&self.eyes.times_ns);
        let mut samples: Vec<TraceSample> = Vec::with_capacity(gaze.len());
        for i in 0..gaze.len() {
            let t = gaze.times_ns[i];
            let Some(time_ns) = sample_time(gaze, i, timeline.t0, samples.last(), counts)? else {
                continue;
            };
            let blink = timeline.in_blink(t);
            counts.in_blinks += usize::from(blink);
            let px = gaze.record(i);
            let direction = self
                .camera
                .direction(px[0], px[1])
                .map(|d| neon_to_openxr(d.as_vec3()))
                .filter(|_| !blink);
            let eye = nearest(&eye_order, &self.eyes.times_ns, t).map(|k| self.eyes.record(k));
            counts.no_eye_state += usize::from(eye.is_none());
            let mut rays = [GazeRay::INVALID; 2];
            let mut pupils = [None; 2];
            if let Some(e) = eye.filter(|_| !blink) {
                for side in 0..2 {
                    let v = &e[4 * side..4 * side + 4];
                    if let Some(d) = direction {
                        rays[side] = eye_ray(v, d);
                    }
                    pupils[side] = pupil_m(v[3], &mut counts.pupils_out);
                }
            }
            let combined = direction.map_or(GazeRay::INVALID, |d| {
                clean_ray(GazeRay {
                    origin: Vec3::ZERO,
                    direction: d,
                    valid: true,
                })
            });
            samples.push(TraceSample {
                time_ns,
                head: timeline.head(t),
                gaze: GazeSample {
                    sample_time_ns: time_ns,
                    left: rays[0],
                    right: rays[1],
                    combined: Some(combined),
                    fixation: None,
                    pupil_diameter_m: pupils,
                    report: None,
                },
            });
        }
        Ok(samples)
    }
}

/// Indices of `times` in increasing time order.
fn sorted_by_time(times: &[i64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..times.len()).collect();
    order.sort_by_key(|&i| times[i]);
    order
}

/// The index of the time in `times` (visited in `order`) nearest `t`, if within
/// [`EYE_STATE_MAX_GAP_NS`].
fn nearest(order: &[usize], times: &[i64], t: i64) -> Option<usize> {
    let k = order.partition_point(|&i| times[i] <= t);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter_map(|j| order.get(j).copied())
        .min_by_key(|&i| (times[i] - t).unsigned_abs())
        .filter(|&i| (times[i] - t).unsigned_abs() <= EYE_STATE_MAX_GAP_NS as u64)
}
