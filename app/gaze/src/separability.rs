//! How well an eye tracker can tell the two images of a glass apart by vergence alone.
//!
//! The two candidate depths (surface and refracted image) differ in vergence angle by
//! `gap = v(d_s) - v(d_r)`, with `v(d) = 2 atan(b / 2d)` for an eye baseline `b`. A tracker
//! measures vergence with noise of standard deviation `sigma`; the separability is the
//! signal-detection index `d' = |gap| / sigma`. Below `d' = 1` a single fixation's vergence
//! says little about which image the wearer looks at: in `config/scenes/glass-sphere.toml`
//! (1.48 m and 2.03 m) the gap is 0.66 degree at a 63 mm baseline, against 0.5-1 degree of
//! noise for a head-worn tracker.
//!
//! # Vergence of a sample
//! With both eyes valid, the signed angle between the two gaze directions in the plane of the
//! baseline, `2 asin(((d_l - d_r) . e) / 2)` with `e` the unit vector from the left eye to the
//! right one: positive when the rays converge, negative when they diverge (so the tail of far
//! fixations is not folded onto the depth cap). Otherwise it is the vergence of the sample's
//! depth, `v(depth)`, at the default baseline.
//!
//! # Noise
//! What decides is how far one sample's vergence lies from the true vergence. A head-worn
//! tracker's error is not white: besides sample-to-sample noise it has a bias that wanders
//! with the gaze direction and over seconds, and within one fixation that bias hardly
//! changes. So the spread of a fixation's samples about their own mean misses most of it
//! (on the shipped SRanipal recordings it gives 0.15-0.2 degree where the whole recording,
//! at a constant true vergence, spreads by 0.8-1.3 degree).
//!
//! [`VergenceNoise`] estimates `sigma` from the data, robustly, over the time scale on which a
//! decision stands: each fixation sample's deviation from the MEDIAN vergence of the samples
//! within [`WINDOW_NS`] (1.5 s) on either side of it. A median over a centred window keeps a
//! vergence step (the wearer looking from one image to the other) on its own side, so true
//! changes that last longer than the window add little; the window is shrunk symmetrically
//! near the ends of a stretch of tracking (a gap longer than [`BREAK_NS`] ends one), so a
//! step near the end of a stretch is not folded in either. Samples in saccades are left out;
//! a window needs [`MIN_WINDOW`] samples. `sigma = 1.4826 * median(|deviation|)` (the median
//! absolute deviation of a normal distribution) over the deviations of the newest
//! [`MAX_POOLED_S`] seconds of fixation, so a spike disturbs only its own deviation. Until
//! [`MIN_RESIDUALS`] deviations are pooled there is no estimate, and the noise is the prior
//! (1 degree, a head-worn tracker's).
//!
//! The estimate is then shrunk toward the prior, which counts as [`PRIOR_S`] seconds of
//! fixation: `sigma^2 = (10 prior^2 + T s^2) / (10 + T)` with `s` the estimate from the
//! deviations of `T` seconds of fixation (each deviation standing for the time since its
//! sample's predecessor). Evidence is counted in time, not in samples: within a window the
//! bias hardly changes, so a tracker that samples four times as often does not know its bias
//! four times as well (the SRanipal recordings sample at 120 Hz, the Tobii Pro Glasses 3 at
//! 50 Hz, Neon at 200 Hz). A short recording, or the first seconds of a session, then does not
//! stake the decision on a few seconds of data (the importers' test fixtures, for one, are
//! noiseless: 0 degree from their own data). Each deviation is taken once its window has
//! passed: the online estimate runs 1.5 s behind the newest sample.

use std::collections::VecDeque;

use vitreous_trace::{GazeBehaviour, GazeSample};

use super::fixation::{Step, VelocityClassifier, combined_direction};
use super::image::ImageDistances;

/// Eye baseline used when a sample does not give one, metres (the scenes' default IPD).
pub const DEFAULT_BASELINE_M: f32 = 0.063;

/// Half the width of the window whose median a sample's deviation is taken from,
/// nanoseconds.
pub const WINDOW_NS: i64 = 1_500_000_000;

/// A stretch without a sample longer than this ends a stretch of tracking, nanoseconds (the
/// vergence hold).
pub const BREAK_NS: i64 = 300_000_000;

/// Fewest samples in a window that give a deviation.
pub const MIN_WINDOW: usize = 7;

/// Fewest pooled deviations that give an estimate.
pub const MIN_RESIDUALS: usize = 30;

/// How many seconds of fixation the prior noise counts as when the estimate is shrunk toward
/// it.
pub const PRIOR_S: f32 = 10.0;

/// Most seconds of fixation whose deviations are pooled (the newest are kept).
pub const MAX_POOLED_S: f32 = 40.0;

/// Least vergence noise any figure is computed with, degrees: a tracker is never exact, and a
/// noiseless synthetic trace would otherwise give an infinite separability.
pub const MIN_NOISE_DEG: f32 = 0.05;

/// Below this separability the vergence cannot tell the two images apart (`d' < 1`).
pub const SEPARABLE: f32 = 1.0;

/// Scale from the median absolute deviation to the standard deviation of a normal
/// distribution.
const MAD_TO_SIGMA: f32 = 1.4826;

/// A sample's vergence and the baseline it was measured with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VergenceReading {
    /// Vergence angle, degrees; negative when the rays diverge.
    pub vergence_deg: f32,
    /// The eye baseline, metres.
    pub baseline_m: f32,
}

/// The vergence angle of a fixation at `depth_m` for eyes `baseline_m` apart, degrees.
pub fn vergence_deg(depth_m: f32, baseline_m: f32) -> f32 {
    (2.0 * (baseline_m / (2.0 * depth_m.max(1e-4))).atan()).to_degrees()
}

/// The vergence of a tracker sample whose depth is `depth_m` (module docs).
pub fn reading(g: &GazeSample, depth_m: f32) -> VergenceReading {
    if g.left.valid && g.right.valid {
        let axis = g.right.origin - g.left.origin;
        let baseline_m = axis.length();
        if baseline_m.is_finite() && baseline_m > 0.01 {
            let e = axis / baseline_m;
            let half = ((g.left.direction - g.right.direction).dot(e) / 2.0).clamp(-1.0, 1.0);
            let v = (2.0 * half.asin()).to_degrees();
            if v.is_finite() {
                return VergenceReading {
                    vergence_deg: v,
                    baseline_m,
                };
            }
        }
    }
    VergenceReading {
        vergence_deg: vergence_deg(depth_m, DEFAULT_BASELINE_M),
        baseline_m: DEFAULT_BASELINE_M,
    }
}

/// The separability of a scene's two images for a tracker.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separability {
    /// Vergence of the surface image minus that of the refracted image, degrees.
    pub gap_deg: f32,
    /// The tracker's vergence noise (standard deviation), degrees.
    pub noise_deg: f32,
    /// Whether `noise_deg` rests on the data (their estimate shrunk toward the prior; false:
    /// the prior alone).
    pub estimated: bool,
}

impl Separability {
    /// The separability of images at `distances` for eyes `baseline_m` apart and vergence
    /// noise `noise_deg`.
    pub fn new(
        distances: &ImageDistances,
        baseline_m: f32,
        noise_deg: f32,
        estimated: bool,
    ) -> Self {
        Separability {
            gap_deg: vergence_deg(distances.surface_m, baseline_m)
                - vergence_deg(distances.refracted_m, baseline_m),
            noise_deg,
            estimated,
        }
    }

    /// `d' = |gap| / noise`, the noise no less than [`MIN_NOISE_DEG`].
    pub fn d_prime(&self) -> f32 {
        self.gap_deg.abs() / self.noise_deg.max(MIN_NOISE_DEG)
    }

    /// Whether the vergence can tell the images apart (`d' >= 1`).
    pub fn separable(&self) -> bool {
        self.d_prime() >= SEPARABLE
    }
}

/// The separability as the summaries of `run` and `replay` write it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SeparabilitySummary {
    /// `d'`: the images' vergence difference over the tracker's vergence noise.
    pub d_prime: f32,
    /// Vergence of the surface image minus that of the refracted image, degrees.
    pub vergence_gap_deg: f32,
    /// The tracker's vergence noise (standard deviation), degrees.
    pub vergence_noise_deg: f32,
    /// Whether the noise was estimated from the session's fixations (false: the prior).
    pub noise_estimated: bool,
}

impl SeparabilitySummary {
    /// One line for a summary: `d'`, the gap and the noise.
    pub fn line(&self) -> String {
        format!(
            "gaze images {:.2} degree apart in vergence, tracker noise {:.2} degree ({}): d' = \
             {:.2}{}",
            self.vergence_gap_deg.abs(),
            self.vergence_noise_deg,
            if self.noise_estimated {
                "estimated"
            } else {
                "assumed"
            },
            self.d_prime,
            if self.d_prime >= SEPARABLE {
                ""
            } else {
                ", below 1: the tracker cannot tell them apart"
            }
        )
    }
}

impl Separability {
    /// The figures a summary writes.
    pub fn summary(&self) -> SeparabilitySummary {
        SeparabilitySummary {
            d_prime: self.d_prime(),
            vergence_gap_deg: self.gap_deg,
            vergence_noise_deg: self.noise_deg,
            noise_estimated: self.estimated,
        }
    }

    /// The warning `run`, `replay` and `view` give once when the tracker cannot separate the
    /// images; `None` while it can, or while the noise is only the prior.
    pub fn warning(&self) -> Option<String> {
        (self.estimated && !self.separable()).then(|| {
            format!(
                "the eye tracker cannot tell the surface from the refracted image apart in this \
                 scene: d' = {:.2} (the images are {:.2} degree apart in vergence, the tracker's \
                 vergence noise is {:.2} degree); the gaze-image decision holds where it cannot \
                 know",
                self.d_prime(),
                self.gap_deg.abs(),
                self.noise_deg
            )
        })
    }
}

/// The robust online estimate of a tracker's vergence noise (module docs).
#[derive(Clone, Debug, Default)]
pub struct VergenceNoise {
    /// Time of the current stretch's first sample, nanoseconds.
    start_ns: Option<i64>,
    /// The current stretch's fixation samples still needed: time and vergence, degrees.
    stretch: VecDeque<(i64, f32)>,
    /// Index in `stretch` of the first sample whose deviation is not yet taken.
    next: usize,
    /// Pooled absolute deviations, degrees, and the seconds of fixation each stands for,
    /// newest last.
    deviations: VecDeque<(f32, f32)>,
    /// The seconds of fixation pooled: the sum of `deviations`' seconds.
    pooled_s: f32,
    /// The estimate from the pooled deviations, degrees.
    sigma_deg: Option<f32>,
}

impl VergenceNoise {
    /// An estimator with nothing pooled.
    pub fn new() -> Self {
        Self::default()
    }

    /// One tracker sample: its time, its vergence (`None`: no depth, a gap) and whether it
    /// belongs to a fixation (a saccade's samples are left out). Samples come once each, in
    /// time order.
    pub fn push(&mut self, time_ns: i64, vergence_deg: Option<f32>, in_fixation: bool) {
        let Some(v) = vergence_deg.filter(|v| v.is_finite()) else {
            self.close();
            return;
        };
        if !in_fixation {
            return;
        }
        if self
            .stretch
            .back()
            .is_some_and(|&(last, _)| time_ns - last > BREAK_NS)
        {
            self.close();
        }
        self.start_ns.get_or_insert(time_ns);
        self.stretch.push_back((time_ns, v));
        let mut taken = false;
        while self
            .stretch
            .get(self.next)
            .is_some_and(|&(t, _)| t + WINDOW_NS <= time_ns)
        {
            taken |= self.take(self.next, time_ns);
            self.next += 1;
        }
        // Samples no later window reaches.
        if let Some(&(oldest_needed, _)) = self.stretch.get(self.next) {
            while self
                .stretch
                .front()
                .is_some_and(|&(t, _)| t < oldest_needed - WINDOW_NS)
            {
                self.stretch.pop_front();
                self.next -= 1;
            }
        }
        if taken {
            self.estimate();
        }
    }

    /// Ends the current stretch of tracking (a gap, or the end of the data): the samples whose
    /// deviation is still pending are taken with windows that end with the stretch.
    pub fn close(&mut self) {
        let end_ns = self.stretch.back().map(|s| s.0);
        let mut taken = false;
        if let Some(end_ns) = end_ns {
            for i in self.next..self.stretch.len() {
                taken |= self.take(i, end_ns);
            }
        }
        self.stretch.clear();
        self.next = 0;
        self.start_ns = None;
        if taken {
            self.estimate();
        }
    }

    /// Pools the deviation of sample `i` from the median of its window, the stretch ending at
    /// `end_ns` so far; whether there was one.
    fn take(&mut self, i: usize, end_ns: i64) -> bool {
        let (t, v) = self.stretch[i];
        let start_ns = self.start_ns.unwrap_or(t);
        let half = WINDOW_NS.min(t - start_ns).min(end_ns - t);
        let mut window: Vec<f32> = self
            .stretch
            .iter()
            .filter(|s| (s.0 - t).abs() <= half)
            .map(|s| s.1)
            .collect();
        if window.len() < MIN_WINDOW {
            return false;
        }
        let deviation = (v - median(&mut window)).abs();
        // The time since the sample before it in the stretch (the first: until the next).
        let neighbour = if i > 0 {
            self.stretch.get(i - 1)
        } else {
            self.stretch.get(i + 1)
        };
        let seconds = neighbour.map_or(0.0, |&(n, _)| (t - n).abs() as f32 * 1e-9);
        self.deviations.push_back((deviation, seconds));
        self.pooled_s += seconds;
        while self.pooled_s > MAX_POOLED_S {
            let Some((_, oldest)) = self.deviations.pop_front() else {
                break;
            };
            self.pooled_s -= oldest;
        }
        true
    }

    /// Updates the estimate from the pooled deviations.
    fn estimate(&mut self) {
        if self.deviations.len() >= MIN_RESIDUALS {
            let mut all: Vec<f32> = self.deviations.iter().map(|d| d.0).collect();
            self.sigma_deg = Some(MAD_TO_SIGMA * median(&mut all));
        }
    }

    /// The estimated noise (standard deviation), degrees; `None` until enough is pooled.
    pub fn sigma_deg(&self) -> Option<f32> {
        self.sigma_deg
    }

    /// How many deviations are pooled.
    pub fn pooled(&self) -> usize {
        self.deviations.len()
    }

    /// How many seconds of fixation the pooled deviations stand for.
    pub fn pooled_s(&self) -> f32 {
        self.pooled_s.max(0.0)
    }
}

/// What [`SeparabilityMonitor::push`] saw in one tracker sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observed {
    /// How the I-VT classifier sees it ([`Step::Gap`] for a blink or closed eyes the tracker
    /// reports, too).
    pub step: Step,
    /// Whether it is part of a saccade, by I-VT or by the tracker's own call.
    pub moving: bool,
    /// Its combined gaze direction (head frame), unless a gap.
    pub direction: Option<glam::Vec3>,
    /// Its vergence, unless a gap.
    pub reading: Option<VergenceReading>,
}

/// Classifies the samples (I-VT), estimates the vergence noise from the fixations and gives
/// the separability of the images at each sample; used by every gaze-image decision, so that
/// `run`, `replay`, `view` and `trace analyze` report it whichever decides.
#[derive(Clone, Debug)]
pub struct SeparabilityMonitor {
    /// Sample classifier.
    classifier: VelocityClassifier,
    /// The noise estimate; kept across resets (it is the tracker's, not the gaze's).
    noise: VergenceNoise,
    /// The noise assumed until there is an estimate, degrees.
    prior_noise_deg: f32,
    /// The separability at the newest sample with a depth.
    last: Option<Separability>,
}

impl SeparabilityMonitor {
    /// A monitor with I-VT threshold `velocity_deg_s` that assumes `prior_noise_deg` until
    /// the data give an estimate.
    pub fn new(velocity_deg_s: f32, prior_noise_deg: f32) -> Self {
        SeparabilityMonitor {
            classifier: VelocityClassifier::new(velocity_deg_s),
            noise: VergenceNoise::new(),
            prior_noise_deg,
            last: None,
        }
    }

    /// One new tracker sample (each once, in time order) whose own depth is `depth_m`
    /// (`None`: none measured), with the images at `distances`.
    pub fn push(
        &mut self,
        g: &GazeSample,
        depth_m: Option<f32>,
        distances: &ImageDistances,
    ) -> Observed {
        let t = g.sample_time_ns;
        let behaviour = g.report.map(|r| r.behaviour);
        let closed = matches!(
            behaviour,
            Some(GazeBehaviour::Blink | GazeBehaviour::EyesClosed)
        );
        let direction = depth_m
            .filter(|_| !closed)
            .and_then(|_| combined_direction(g));
        let step = self.classifier.step(t, direction);
        let (Some(depth_m), Some(_), false) = (depth_m, direction, step == Step::Gap) else {
            self.noise.close();
            return Observed {
                step: Step::Gap,
                moving: false,
                direction: None,
                reading: None,
            };
        };
        let reading = reading(g, depth_m);
        let moving = step == Step::Moving || behaviour == Some(GazeBehaviour::Saccade);
        self.noise.push(t, Some(reading.vergence_deg), !moving);
        let prior = self.prior_noise_deg;
        let (noise_deg, estimated) = match self.noise.sigma_deg() {
            Some(s) => {
                let (n0, n) = (PRIOR_S, self.noise.pooled_s());
                (((n0 * prior * prior + n * s * s) / (n0 + n)).sqrt(), true)
            }
            None => (prior, false),
        };
        self.last = Some(Separability::new(
            distances,
            reading.baseline_m,
            noise_deg,
            estimated,
        ));
        Observed {
            step,
            moving,
            direction,
            reading: Some(reading),
        }
    }

    /// The separability at the newest sample with a depth.
    pub fn separability(&self) -> Option<Separability> {
        self.last
    }

    /// The tracker was lost for longer than the hold: the classifier starts again; the noise
    /// estimate and the last separability are kept.
    pub fn reset(&mut self) {
        self.classifier.reset();
        self.noise.close();
    }
}

/// The median of some values (reordered); 0 for none.
fn median(values: &mut [f32]) -> f32 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f32::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

#[cfg(test)]
mod tests;
