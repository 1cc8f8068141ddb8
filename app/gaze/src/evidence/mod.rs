//! Gaze-image decisions from accumulated evidence (filter name `evidence`, the default).
//!
//! The fixation filter ([`super::fixation`]) decides from the median vergence of the last
//! 100 ms: one stretch of near-vergence noise as long as that decides, and where the two
//! images are closer in vergence than the tracker's noise every decision is a coin toss. Here
//! each tracker sample adds evidence for one image or the other, weighed by what the tracker
//! can resolve, and the decision changes only when the evidence for the other image has piled
//! up past a threshold.
//!
//! # Evidence
//! A sample's vergence `v` (degrees, [`separability::reading`]) is compared with the
//! vergences `v_s` and `v_r` of the two images at the sample's eye baseline. Under a normal
//! model of the tracker's vergence noise `sigma` (estimated from the data by
//! [`VergenceNoise`]; [`EvidenceParams::prior_noise_deg`] until there is an estimate), the
//! log-likelihood ratio of "refracted" over "surface" is
//! `l = (v_r - v_s) (v - (v_s + v_r) / 2) / sigma^2`. It is clipped to +-1 per sample, so
//! neither a spike nor a fixation far from both images (a wearer looking at the room) counts
//! as more than one clear sample, and weighed by `min(dt / step, 1)` with `dt` the time since
//! the previous sample and `step` [`EvidenceParams::step_ms`] (33 ms): a 120 Hz tracker's
//! neighbouring samples share much of their error, so evidence accrues per unit of time, not
//! per sample.
//!
//! Two CUSUM statistics (Page, "Continuous inspection schemes", Biometrika 1954) accumulate it,
//! one per direction: `S_r = max(0, S_r + w l)` and `S_s = max(0, S_s - w l)`. The image
//! switches to the refracted one when `S_r` reaches [`EvidenceParams::threshold`] (2: two
//! clear samples at 30 Hz, 66 ms of them at any rate), and back when `S_s` does; a switch
//! empties both. A threshold of 3 rejects longer spikes but, with the clip, needs a net lead
//! of three clear samples: two noisy samples on the wrong side of the midpoint right after a
//! change (about 1 change in 80 at d' = 3.4) then delay the switch to 200 ms, past the
//! 150 ms bar of docs/gaze.md. With no image yet, the first statistic to reach the threshold decides.
//!
//! # What gives no evidence
//! - a sample inside a saccade: the I-VT classifier of [`super::fixation`] sees the gaze move
//!   faster than 30 deg/s into it and out of it (the eyes are between targets). A sample moved
//!   to fast whose successor moves no more is the first of a new fixation, or a noise spike
//!   merged back (as the fixation filter merges it): its evidence counts, late by a sample;
//! - a sample the tracker itself calls a saccade or gives with LOW confidence (Magic Leap 2's
//!   `XR_ML_eye_tracker`);
//! - a sample whose gaze ray misses the glass object's projection
//!   ([`PipelineInputs::object`](super::ObjectInView), widened by
//!   [`EvidenceParams::margin_deg`] for the tracker's accuracy): the wearer looks elsewhere,
//!   the gaze image is not visible, and the decision holds. Both statistics are emptied, so
//!   evidence gathered before the gaze left does not count after it returns;
//! - any sample while the separability `d'` ([`Separability`]) is below
//!   [`EvidenceParams::min_separability`] (1): the tracker cannot tell the images apart, so the
//!   decision holds (unknown before any decision: no defocus).
//!
//! # Holding
//! As with the fixation filter: a gap (no depth or no direction, a dropout of more than
//! 75 ms, or a blink or closed eyes as the tracker reports them) empties both statistics; no
//! decision is taken within [`EvidenceParams::settle_ms`] (150 ms) after a gap ends (the start
//! of tracking counts as one) or after the previous switch; after a gap longer than the
//! vergence hold (300 ms) the image is unknown until the evidence decides again.

use glam::Vec3;
use vitreous_trace::{GazeSample, TrackerConfidence};

use super::fixation::{DEFAULT_VELOCITY_DEG_S, Step};
use super::image::{GazeImage, ImageDistances};
use super::separability::{MIN_NOISE_DEG, Separability, SeparabilityMonitor, vergence_deg};
use super::vergence::{FixationDepth, Measurement, newer_sample};

/// Default decision threshold of the accumulated evidence (clear samples).
pub const DEFAULT_THRESHOLD: f32 = 2.0;
/// Default time one clear sample stands for, milliseconds.
pub const DEFAULT_STEP_MS: f32 = 33.0;
/// Default quiet time after a gap ends and after a switch, milliseconds.
pub const DEFAULT_SETTLE_MS: f32 = 150.0;
/// Default separability below which no decision is taken.
pub const DEFAULT_MIN_SEPARABILITY: f32 = super::separability::SEPARABLE;
/// Default vergence noise until the data give an estimate, degrees (a head-worn tracker's).
pub const DEFAULT_PRIOR_NOISE_DEG: f32 = 1.0;
/// Default widening of the object's projection for the tracker's accuracy, degrees.
pub const DEFAULT_MARGIN_DEG: f32 = 3.0;
/// Time constant of the smoothed depth the filter reports, nanoseconds.
const SMOOTHING_NS: f64 = 100e6;

/// Parameters of the evidence decision (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EvidenceParams {
    /// I-VT threshold on the angular velocity of the combined gaze direction, degrees/second.
    pub velocity_deg_s: f32,
    /// Accumulated evidence that switches the image, clear samples.
    pub threshold: f32,
    /// Time one clear sample stands for, milliseconds.
    pub step_ms: f32,
    /// No decision within this long after a gap ends or after a switch, milliseconds.
    pub settle_ms: f32,
    /// No evidence counts while the separability `d'` is below this.
    pub min_separability: f32,
    /// Vergence noise assumed until the data give an estimate, degrees.
    pub prior_noise_deg: f32,
    /// Widening of the object's projection, degrees.
    pub margin_deg: f32,
}

impl Default for EvidenceParams {
    fn default() -> Self {
        EvidenceParams {
            velocity_deg_s: DEFAULT_VELOCITY_DEG_S,
            threshold: DEFAULT_THRESHOLD,
            step_ms: DEFAULT_STEP_MS,
            settle_ms: DEFAULT_SETTLE_MS,
            min_separability: DEFAULT_MIN_SEPARABILITY,
            prior_noise_deg: DEFAULT_PRIOR_NOISE_DEG,
            margin_deg: DEFAULT_MARGIN_DEG,
        }
    }
}

/// Where the glass object is as seen from the head: the direction of its centre (head frame,
/// unit) and the angular radius of its bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectInView {
    /// Direction from the head to the object's centre, head frame, unit.
    pub direction: Vec3,
    /// Half the angle the object's bounding sphere subtends, radians.
    pub angular_radius_rad: f32,
}

impl ObjectInView {
    /// The object with centre `center_m` and radius `radius_m` (world frame) seen from a head
    /// at `head_position_m` turned by `head_orientation`; `None` when the head is inside it.
    pub fn from_head(
        head_position_m: Vec3,
        head_orientation: glam::Quat,
        center_m: Vec3,
        radius_m: f32,
    ) -> Option<ObjectInView> {
        let to = center_m - head_position_m;
        let distance = to.length();
        if distance.partial_cmp(&radius_m) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        Some(ObjectInView {
            direction: (head_orientation.inverse() * to / distance).normalize(),
            angular_radius_rad: (radius_m / distance).asin(),
        })
    }

    /// Whether a gaze direction (head frame, unit) falls within the projection widened by
    /// `margin_rad`.
    pub fn contains(&self, gaze: Vec3, margin_rad: f32) -> bool {
        let angle = gaze.dot(self.direction).clamp(-1.0, 1.0).acos();
        angle <= self.angular_radius_rad + margin_rad
    }
}

/// Why the newest sample gave no evidence, if it did not.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Withheld {
    /// It gave evidence.
    No,
    /// A gap (no depth, no direction, a blink, closed eyes).
    Gap,
    /// A saccade (I-VT or the tracker's own call).
    Saccade,
    /// The tracker's confidence was LOW.
    LowConfidence,
    /// The gaze missed the object.
    OffObject,
    /// The separability is below the minimum.
    Inseparable,
}

/// The evidence decision (module docs), fed once per frame like the other filters; each
/// tracker sample is ingested once.
#[derive(Clone, Debug)]
pub struct EvidenceFilter {
    /// Parameters.
    params: EvidenceParams,
    /// The images' distances.
    distances: ImageDistances,
    /// Where the object is in the head frame, when known.
    object: Option<ObjectInView>,
    /// Sample classes, vergence noise and separability.
    monitor: SeparabilityMonitor,
    /// Evidence for switching to the refracted image and to the surface image.
    toward: [f32; 2],
    /// The current decision.
    image: GazeImage,
    /// Sample time of the last sample ingested.
    last_sample_ns: Option<i64>,
    /// Sample time of the last sample with a depth (for the weight of the next one).
    last_measured_ns: Option<i64>,
    /// When the last gap ended (the first sample after it), nanoseconds.
    gap_end_ns: Option<i64>,
    /// When the decision last changed, or was first taken, nanoseconds.
    last_switch_ns: Option<i64>,
    /// Smoothed vergence, degrees, with the baseline and the time of its newest sample.
    smoothed: Option<(f32, f32, i64)>,
    /// Why the newest sample gave no evidence.
    withheld: Withheld,
    /// The weighed evidence of a sample the gaze moved to fast, until the next sample says
    /// whether a fixation starts there (it counts) or it was a saccade or a spike (it does not).
    pending: Option<f32>,
}

impl EvidenceFilter {
    /// A filter with no history choosing between images at `distances`.
    pub fn new(params: EvidenceParams, distances: ImageDistances) -> Self {
        EvidenceFilter {
            params,
            distances,
            object: None,
            monitor: SeparabilityMonitor::new(params.velocity_deg_s, params.prior_noise_deg),
            toward: [0.0; 2],
            image: GazeImage::Unknown,
            last_sample_ns: None,
            last_measured_ns: None,
            gap_end_ns: None,
            last_switch_ns: None,
            smoothed: None,
            withheld: Withheld::No,
            pending: None,
        }
    }

    /// Moves the images (the viewer moved); the decision and the evidence are kept.
    pub fn set_distances(&mut self, distances: ImageDistances) {
        self.distances = distances;
    }

    /// Where the object is in the head frame (`None`: unknown, every gaze direction counts).
    pub fn set_object(&mut self, object: Option<ObjectInView>) {
        self.object = object;
    }

    /// The separability at the newest sample with a depth.
    pub fn separability(&self) -> Option<Separability> {
        self.monitor.separability()
    }

    /// Why the newest sample gave no evidence ([`Withheld::No`] if it did).
    pub fn withheld(&self) -> Withheld {
        self.withheld
    }

    /// The evidence for switching to the refracted and to the surface image.
    pub fn evidence(&self) -> [f32; 2] {
        self.toward
    }

    /// Feeds one frame: `gaze` is the frame's newest tracker sample, `raw` the vergence
    /// estimator's (held) depth for it and `measurement` what that sample itself measured.
    /// Returns the smoothed depth and the gaze image.
    pub fn update(
        &mut self,
        gaze: Option<&GazeSample>,
        raw: &FixationDepth,
        measurement: Option<Measurement>,
    ) -> (FixationDepth, GazeImage) {
        if *raw == FixationDepth::Unknown {
            self.reset();
        } else if let Some(g) = newer_sample(gaze, &mut self.last_sample_ns) {
            let measured = measurement.filter(|m| m.sample_time_ns == g.sample_time_ns);
            self.ingest(g, measured);
        }
        let depth = match self.smoothed {
            Some((v, baseline_m, sample_time_ns)) => FixationDepth::Known {
                depth_m: depth_of(v, baseline_m),
                sample_time_ns,
            },
            None => FixationDepth::Unknown,
        };
        (depth, self.image)
    }

    /// One new tracker sample.
    fn ingest(&mut self, g: &GazeSample, measured: Option<Measurement>) {
        let t = g.sample_time_ns;
        let seen = self
            .monitor
            .push(g, measured.map(|m| m.depth_m), &self.distances);
        let (Some(reading), Some(direction), Some(sep)) =
            (seen.reading, seen.direction, self.monitor.separability())
        else {
            self.gap();
            return;
        };
        let v = reading.vergence_deg;
        let dt = self.last_measured_ns.map(|last| t - last);
        self.last_measured_ns = Some(t);
        if seen.step == Step::AfterGap {
            self.gap_end_ns = Some(t);
            self.toward = [0.0; 2];
        }
        self.smooth(v, reading.baseline_m, t, dt);
        let pending = self.pending.take();
        self.withheld = if g
            .report
            .is_some_and(|r| r.behaviour == vitreous_trace::GazeBehaviour::Saccade)
        {
            Withheld::Saccade
        } else if g
            .report
            .is_some_and(|r| r.confidence == TrackerConfidence::Low)
        {
            Withheld::LowConfidence
        } else if self
            .object
            .is_some_and(|o| !o.contains(direction, self.params.margin_deg.to_radians()))
        {
            self.toward = [0.0; 2];
            Withheld::OffObject
        } else if sep.d_prime() < self.params.min_separability {
            Withheld::Inseparable
        } else {
            Withheld::No
        };
        if self.withheld != Withheld::No {
            return;
        }
        let noise_deg = sep.noise_deg.max(MIN_NOISE_DEG);
        let v_s = vergence_deg(self.distances.surface_m, reading.baseline_m);
        let v_r = vergence_deg(self.distances.refracted_m, reading.baseline_m);
        let llr =
            ((v_r - v_s) * (v - (v_s + v_r) / 2.0) / (noise_deg * noise_deg)).clamp(-1.0, 1.0);
        let step_ns = f64::from(self.params.step_ms.max(1e-3)) * 1e6;
        let weight = dt.map_or(1.0, |dt| (dt as f64 / step_ns).min(1.0)) as f32;
        match seen.step {
            // Moving fast: a saccade's sample, or the first of a new fixation, or a spike; the
            // next sample says which.
            Step::Moving => {
                self.pending = Some(weight * llr);
                self.withheld = Withheld::Saccade;
                return;
            }
            // A new fixation started at the pending sample, or it was a noise spike merged into
            // the fixation (as the fixation filter merges it): it counts.
            Step::NewFixation { .. } | Step::Continues => {
                if let Some(e) = pending {
                    self.add(e);
                }
            }
            Step::AfterGap | Step::Gap => {}
        }
        self.add(weight * llr);
        self.decide(t);
    }

    /// Adds one sample's weighed evidence (positive: toward the refracted image).
    fn add(&mut self, evidence: f32) {
        self.toward[0] = (self.toward[0] + evidence).max(0.0);
        self.toward[1] = (self.toward[1] - evidence).max(0.0);
    }

    /// Takes a decision if the evidence and the quiet times allow (module docs).
    fn decide(&mut self, t: i64) {
        let settle_ns = (f64::from(self.params.settle_ms) * 1e6) as i64;
        let settled = |since: Option<i64>| since.is_none_or(|s| t - s >= settle_ns);
        if !settled(self.gap_end_ns) {
            return;
        }
        let h = self.params.threshold;
        let next = match self.image {
            GazeImage::Refracted if self.toward[1] >= h => GazeImage::Surface,
            GazeImage::Surface if self.toward[0] >= h => GazeImage::Refracted,
            GazeImage::Unknown if self.toward[0] >= h && self.toward[0] >= self.toward[1] => {
                GazeImage::Refracted
            }
            GazeImage::Unknown if self.toward[1] >= h => GazeImage::Surface,
            _ => return,
        };
        if self.image != GazeImage::Unknown && !settled(self.last_switch_ns) {
            return;
        }
        self.image = next;
        self.last_switch_ns = Some(t);
        self.toward = [0.0; 2];
    }

    /// An exponential smoothing of the vergence over [`SMOOTHING_NS`], for the depth reported.
    fn smooth(&mut self, v: f32, baseline_m: f32, t: i64, dt: Option<i64>) {
        let previous = self.smoothed.map(|s| s.0);
        let v = match (previous, dt) {
            (Some(p), Some(dt)) => {
                let a = 1.0 - (-(dt as f64) / SMOOTHING_NS).exp() as f32;
                p + a * (v - p)
            }
            _ => v,
        };
        self.smoothed = Some((v, baseline_m, t));
    }

    /// A gap: the evidence is emptied and the next sample starts a fixation.
    fn gap(&mut self) {
        self.toward = [0.0; 2];
        self.pending = None;
        self.withheld = Withheld::Gap;
    }

    /// Forgets the tracking state after the tracker was lost for longer than the hold time:
    /// the image is unknown until the evidence decides again. The noise estimate, the time of
    /// the last switch and the separability are kept.
    pub fn reset(&mut self) {
        self.monitor.reset();
        self.gap();
        self.image = GazeImage::Unknown;
        self.last_sample_ns = None;
        self.last_measured_ns = None;
        self.smoothed = None;
    }
}

/// The depth at which eyes `baseline_m` apart verge by `vergence_deg` (the far cap of the
/// vergence estimator for parallel or diverging rays), metres.
fn depth_of(vergence_deg: f32, baseline_m: f32) -> f32 {
    let half = (vergence_deg.to_radians() / 2.0).tan();
    if half > baseline_m / (2.0 * super::vergence::DEFAULT_MAX_DEPTH_M) {
        baseline_m / (2.0 * half)
    } else {
        super::vergence::DEFAULT_MAX_DEPTH_M
    }
}

#[cfg(test)]
mod tests;
