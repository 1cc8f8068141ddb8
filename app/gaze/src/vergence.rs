//! Fixation depth from the two eyes' gaze rays (METHOD.md section 5: "the intersection
//! (closest approach) of the calibrated left and right gaze rays").
//!
//! # Definition of depth
//! With eye origins `o_l`, `o_r` and unit directions `d_l`, `d_r` (head frame), the fixation
//! point `p` is the midpoint of the shortest segment between the two rays. Its depth is
//! measured from the midpoint between the eyes `m = (o_l + o_r) / 2` along the combined
//! forward direction `f = normalize(d_l + d_r)` (the bisector of the two gaze directions):
//! `depth_m = (p - m) . f`. For a fixated point this differs from the Euclidean distance
//! `|p - m|` by the cosine of the angle between `f` and the direction to `p`. Straight ahead
//! the two agree; off axis `f` meets the baseline where the angle bisector of the triangle
//! eye-point-eye does, not at `m`, so near eccentric fixations read short: 30 degrees off axis
//! with a 63 mm baseline the bisector depth is 1.9e-3 (0.15 mm) short at 8 cm, 9.7e-3 at 5 cm,
//! 8e-4 at 10 cm and under 1e-4 from 20 cm on (docs/gaze.md). Unlike the Euclidean distance it
//! stays signed, so a crossing behind the eyes is recognisable.
//!
//! # Degenerate cases
//! - **Near-parallel rays** (vergence angle below what gives [`VergenceConfig::max_depth_m`])
//!   are a far fixation: the depth is reported as `max_depth_m`.
//! - **Divergent rays** (the closest approach lies behind either eye): with the tracker's
//!   angular noise, rays aimed at a far point diverge about as often as they converge far
//!   away, so by default they are also a far fixation at `max_depth_m`
//!   ([`DivergentRays::Far`]). [`DivergentRays::Unknown`] treats them as no measurement
//!   instead (held like a blink).
//! - **Missing eyes** (blink, glare; either eye invalid): when the sample carries a ready
//!   fixation point, its distance from the head origin (between the eyes) is used; else when
//!   it carries a valid combined ray and one eye is valid, the closest approach of those two
//!   rays is used (half the baseline, same definition of depth); each fallback is logged once
//!   per process with `tracing::info!`, however many estimators a command builds. A combined
//!   ray alone has no depth. Otherwise the last known depth is held for
//!   [`VergenceConfig::hold_ns`] of sample time, then the depth is [`FixationDepth::Unknown`].

use std::sync::atomic::{AtomicBool, Ordering};

use vitreous_trace::GazeSample;
pub use vitreous_trace::crossing::{RayCrossing, closest_approach};

/// Default cap on the reported depth (far fixations and near-parallel rays), metres.
pub const DEFAULT_MAX_DEPTH_M: f32 = 10.0;
/// Default floor on the reported depth, metres (closer crossings are tracker error).
pub const DEFAULT_MIN_DEPTH_M: f32 = 0.05;
/// Default time a depth is held through invalid samples, nanoseconds (300 ms: longer than a
/// normal blink, about 100-150 ms, short enough that a lost tracker is noticed).
pub const DEFAULT_HOLD_NS: i64 = 300_000_000;

/// A fixation depth, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FixationDepth {
    /// A depth measured (or held) from a tracker sample.
    Known {
        /// Depth from the midpoint between the eyes along the gaze bisector, metres
        /// (see the module docs), within `[min_depth_m, max_depth_m]`.
        depth_m: f32,
        /// Tracker time of the sample the depth was measured from, nanoseconds. A held depth
        /// keeps the time of its sample, so filters do not count it twice.
        sample_time_ns: i64,
    },
    /// No depth: no tracker, or no valid measurement for longer than the hold time.
    Unknown,
}

impl FixationDepth {
    /// The depth in metres, if known.
    pub fn depth_m(&self) -> Option<f32> {
        match *self {
            FixationDepth::Known { depth_m, .. } => Some(depth_m),
            FixationDepth::Unknown => None,
        }
    }

    /// The tracker time of the measurement, if known.
    pub fn sample_time_ns(&self) -> Option<i64> {
        match *self {
            FixationDepth::Known { sample_time_ns, .. } => Some(sample_time_ns),
            FixationDepth::Unknown => None,
        }
    }
}

/// What divergent rays (closest approach behind the eyes) mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DivergentRays {
    /// A far fixation at `max_depth_m` (default: noise around a far target).
    #[default]
    Far,
    /// No measurement: the last depth is held, like during a blink.
    Unknown,
}

/// Settings of the vergence estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VergenceConfig {
    /// Cap on the depth; near-parallel rays report this, metres.
    pub max_depth_m: f32,
    /// Floor on the depth, metres.
    pub min_depth_m: f32,
    /// How long the last depth is held through invalid samples, nanoseconds of sample time.
    pub hold_ns: i64,
    /// What divergent rays mean.
    pub divergent: DivergentRays,
}

impl Default for VergenceConfig {
    fn default() -> Self {
        VergenceConfig {
            max_depth_m: DEFAULT_MAX_DEPTH_M,
            min_depth_m: DEFAULT_MIN_DEPTH_M,
            hold_ns: DEFAULT_HOLD_NS,
            divergent: DivergentRays::Far,
        }
    }
}

/// What the newest tracker sample measured, before the hold: its depth and how the rays met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// Tracker time of the sample, nanoseconds.
    pub sample_time_ns: i64,
    /// The depth it gave, clamped like [`FixationDepth::Known`], metres.
    pub depth_m: f32,
    /// Whether the rays diverged (their closest approach lies behind the eyes); with
    /// [`DivergentRays::Far`] the depth is then `max_depth_m`.
    pub divergent: bool,
}

/// The frame's tracker sample when it is newer than `last` (the sample time last ingested),
/// which it then becomes: each tracker sample is ingested once, however many frames see it.
pub fn newer_sample<'a>(
    gaze: Option<&'a GazeSample>,
    last: &mut Option<i64>,
) -> Option<&'a GazeSample> {
    let g = gaze.filter(|g| last.is_none_or(|l| g.sample_time_ns > l))?;
    *last = Some(g.sample_time_ns);
    Some(g)
}

/// Which fallback a sample needed; each is logged once per process.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fallback {
    FixationPoint,
    CombinedRay,
    CombinedOnly,
}

/// Turns tracker samples into fixation depths, holding the last depth through blinks.
#[derive(Clone, Debug)]
pub struct VergenceEstimator {
    /// Settings.
    config: VergenceConfig,
    /// The last measured depth and its sample time.
    last_known: Option<(f32, i64)>,
    /// What the sample of the newest update measured (`None`: no sample, or no depth).
    measurement: Option<Measurement>,
}

impl VergenceEstimator {
    /// An estimator with no history.
    pub fn new(config: VergenceConfig) -> Self {
        VergenceEstimator {
            config,
            last_known: None,
            measurement: None,
        }
    }

    /// The settings.
    pub fn config(&self) -> &VergenceConfig {
        &self.config
    }

    /// What the sample of the newest [`update`](Self::update) measured: `None` when that
    /// update had no sample or the sample gave no depth (a blink, a lost eye), even while an
    /// older depth is held.
    pub fn measurement(&self) -> Option<Measurement> {
        self.measurement
    }

    /// The depth for a frame: `gaze` is the newest tracker sample (if any), `now_ns` the
    /// frame's time, used for the hold timeout only when there is no sample (with a sample,
    /// the hold is measured in that sample's time).
    pub fn update(&mut self, gaze: Option<&GazeSample>, now_ns: i64) -> FixationDepth {
        let (now_ns, measured) = match gaze {
            Some(g) => (g.sample_time_ns, self.measure(g)),
            None => (now_ns, None),
        };
        self.measurement = None;
        if let Some((depth_m, divergent)) = measured {
            let depth_m = depth_m.clamp(self.config.min_depth_m, self.config.max_depth_m);
            self.last_known = Some((depth_m, now_ns));
            self.measurement = Some(Measurement {
                sample_time_ns: now_ns,
                depth_m,
                divergent,
            });
            return FixationDepth::Known {
                depth_m,
                sample_time_ns: now_ns,
            };
        }
        match self.last_known {
            Some((depth_m, sample_time_ns))
                if now_ns.saturating_sub(sample_time_ns) <= self.config.hold_ns =>
            {
                FixationDepth::Known {
                    depth_m,
                    sample_time_ns,
                }
            }
            _ => {
                self.last_known = None;
                FixationDepth::Unknown
            }
        }
    }

    /// The unclamped depth one sample gives and whether its rays diverged, or `None` when it
    /// gives none.
    fn measure(&mut self, g: &GazeSample) -> Option<(f32, bool)> {
        let far = self.config.max_depth_m;
        let from_crossing = |c: RayCrossing, divergent: DivergentRays| match c {
            RayCrossing::Converge { depth_m, .. } => Some((depth_m.min(far), false)),
            RayCrossing::Parallel => Some((far, false)),
            RayCrossing::Divergent => match divergent {
                DivergentRays::Far => Some((far, true)),
                DivergentRays::Unknown => None,
            },
        };
        if g.left.valid && g.right.valid {
            return from_crossing(closest_approach(&g.left, &g.right), self.config.divergent);
        }
        if let Some(p) = g.fixation.filter(|p| p.is_finite()) {
            log_once(Fallback::FixationPoint);
            return Some((p.length(), false));
        }
        let combined = g.combined.filter(|c| c.valid);
        if let Some(c) = combined {
            let eye = [g.left, g.right].into_iter().find(|r| r.valid);
            if let Some(eye) = eye {
                log_once(Fallback::CombinedRay);
                return from_crossing(closest_approach(&c, &eye), self.config.divergent);
            }
            log_once(Fallback::CombinedOnly);
        }
        None
    }
}

/// Fallbacks already logged in this process (indexed by `Fallback as usize`). One run builds
/// several estimators (the live pipeline, `trace analyze`'s raw depths and one per filter), and
/// the note is about the tracker, not about an estimator, so it is printed once per process.
static LOGGED: [AtomicBool; 3] = [
    AtomicBool::new(false),
    AtomicBool::new(false),
    AtomicBool::new(false),
];

/// Logs the note of a fallback the first time any estimator of this process needs it; returns
/// whether this call logged it.
fn log_once(which: Fallback) -> bool {
    if LOGGED[which as usize].swap(true, Ordering::Relaxed) {
        return false;
    }
    match which {
        Fallback::FixationPoint => tracing::info!(
            "gaze: a sample without two valid eye rays carries a fixation point; using its \
             distance from the head as the fixation depth"
        ),
        Fallback::CombinedRay => tracing::info!(
            "gaze: a sample with one valid eye ray carries a combined ray; using their \
             closest approach as the fixation point"
        ),
        Fallback::CombinedOnly => tracing::info!(
            "gaze: a sample carries only a combined gaze ray, which gives no depth; \
             holding the last depth"
        ),
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use vitreous_trace::GazeRay;

    fn ray(origin: Vec3, target: Vec3) -> GazeRay {
        GazeRay {
            origin,
            direction: (target - origin).normalize(),
            valid: true,
        }
    }

    fn sample(t_ns: i64, left: GazeRay, right: GazeRay) -> GazeSample {
        GazeSample::binocular(t_ns, left, right)
    }

    #[test]
    fn crossing_rays_give_the_target_depth() {
        let (l, r) = (Vec3::new(-0.032, 0.0, 0.0), Vec3::new(0.032, 0.0, 0.0));
        let target = Vec3::new(0.0, 0.0, -0.8);
        match closest_approach(&ray(l, target), &ray(r, target)) {
            RayCrossing::Converge { depth_m, point_m } => {
                assert!((depth_m - 0.8).abs() < 1e-4, "{depth_m}");
                assert!(point_m.distance(target) < 1e-4);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn combined_ray_with_one_eye_is_used_when_the_other_eye_is_lost() {
        let target = Vec3::new(0.0, 0.0, -0.5);
        let left = ray(Vec3::new(-0.032, 0.0, 0.0), target);
        let combined = ray(Vec3::ZERO, target);
        let mut g = sample(0, left, GazeRay::INVALID);
        g.combined = Some(combined);
        let mut v = VergenceEstimator::new(VergenceConfig::default());
        let d = v.update(Some(&g), 0).depth_m().unwrap();
        assert!((d - 0.5).abs() < 1e-3, "{d}");
        g.left = GazeRay::INVALID;
        // Combined ray alone: no depth, the last one is held.
        g.sample_time_ns = 10;
        assert_eq!(v.update(Some(&g), 10).sample_time_ns(), Some(0));
    }

    #[test]
    fn fixation_point_is_used_without_rays() {
        let mut g = sample(5, GazeRay::INVALID, GazeRay::INVALID);
        g.fixation = Some(Vec3::new(0.0, 0.3, -0.4));
        let mut v = VergenceEstimator::new(VergenceConfig::default());
        let d = v.update(Some(&g), 5).depth_m().unwrap();
        assert!((d - 0.5).abs() < 1e-6);
    }

    #[test]
    fn no_sample_at_all_times_out_on_the_frame_clock() {
        let (l, r) = (Vec3::new(-0.032, 0.0, 0.0), Vec3::new(0.032, 0.0, 0.0));
        let t = Vec3::new(0.0, 0.0, -1.0);
        let mut v = VergenceEstimator::new(VergenceConfig::default());
        v.update(Some(&sample(0, ray(l, t), ray(r, t))), 0);
        assert!(v.update(None, DEFAULT_HOLD_NS).depth_m().is_some());
        assert_eq!(v.update(None, DEFAULT_HOLD_NS + 1), FixationDepth::Unknown);
    }
}
