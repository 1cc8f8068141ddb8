//! Synthetic traces: a viewer who fixates a list of points in turn, with known ground truth.
//!
//! The head stands at [`SynthParams::head_position`] facing the first of
//! [`SynthParams::targets`] (with +y up), plus a slow, small sway (a few millimetres, a
//! fraction of a degree) that is deterministic for a seed. The schedule visits the targets in
//! list order, each for [`SynthParams::switch_period_s`], and starts over after the last. Both
//! eye rays start at `∓ipd/2` along head x and point at the current target, plus Gaussian
//! angular noise; during blinks both eyes are invalid. What the targets stand for is the
//! caller's business.
//!
//! Over 600 lines only because its tests (about 220 lines) sit beside the generator they
//! check; the generator itself is under 440.
//!
//! `fixation` and `combined` are `None` in every sample: the consumer computes vergence from
//! the two rays, as with a real tracker. The true target of each moment is in
//! [`SynthTrace::phases`]. Each eye's pupil diameter drifts slowly between 3.5 and 5 mm
//! (`synth/pupil.rs`); it is unknown (`None`) while the eye blinks.

mod pupil;

use glam::{Mat3, Quat, Vec3};
use thiserror::Error;

use crate::format::TraceSample;
use crate::frame::{GazeRay, GazeSample, Pose};

/// Amplitude of the head's positional sway along each world axis, metres.
const SWAY_POSITION_M: f32 = 0.003;
/// Amplitude of the head's rotational sway about each head axis, degrees.
const SWAY_ANGLE_DEG: f32 = 0.3;
/// Most samples a synthetic trace may have (about 38 days at 30 Hz).
const MAX_SAMPLES: f64 = 1e8;

/// A point the synthetic viewer fixates.
#[derive(Clone, Debug, PartialEq)]
pub struct FixationTarget {
    /// A name for messages (e.g. `near`); not interpreted.
    pub name: String,
    /// The point in the world frame, metres.
    pub point_m: Vec3,
}

impl FixationTarget {
    /// A target named `name` at `point_m`.
    pub fn new(name: impl Into<String>, point_m: Vec3) -> Self {
        FixationTarget {
            name: name.into(),
            point_m,
        }
    }
}

/// What to synthesise. Points are in the world frame (OpenXR axes, metres).
#[derive(Clone, Debug, PartialEq)]
pub struct SynthParams {
    /// Where the head (between the eyes) stands, metres.
    pub head_position: Vec3,
    /// The fixated points in schedule order (at least one); the head faces the first.
    pub targets: Vec<FixationTarget>,
    /// Distance between the eyes' ray origins, metres.
    pub ipd_m: f32,
    /// Length of the trace, seconds (samples at 0 .. duration inclusive).
    pub duration_s: f32,
    /// Tracker sample rate, hertz.
    pub rate_hz: f32,
    /// Time each target is fixated before the next, seconds; 0 (or less) stays on the first.
    pub switch_period_s: f32,
    /// Standard deviation of the angular gaze noise per axis, degrees; 0 for exact rays.
    pub noise_deg: f32,
    /// Time between blink starts, seconds; the first blink starts at this time. 0 (or less)
    /// for no blinks.
    pub blink_every_s: f32,
    /// How long each blink lasts, seconds.
    pub blink_duration_s: f32,
    /// Seed of the sway and noise; the same parameters give the same trace.
    pub seed: u64,
}

impl Default for SynthParams {
    fn default() -> Self {
        SynthParams {
            head_position: Vec3::ZERO,
            targets: vec![
                FixationTarget::new("near", Vec3::new(0.0, 0.0, -0.6)),
                FixationTarget::new("far", Vec3::new(0.0, -0.05, -1.5)),
            ],
            ipd_m: 0.063,
            duration_s: 10.0,
            rate_hz: 30.0,
            switch_period_s: 3.0,
            noise_deg: 0.5,
            blink_every_s: 4.0,
            blink_duration_s: 0.15,
            seed: 1,
        }
    }
}

/// Parameters that cannot give a trace.
#[derive(Debug, Error, PartialEq)]
pub enum SynthError {
    /// A parameter is NaN, infinite or out of its range.
    #[error("synthetic trace parameter `{field}` is {value}; expected {expected}")]
    BadParam {
        /// The field of [`SynthParams`].
        field: &'static str,
        /// Its value, printed.
        value: String,
        /// What it should be.
        expected: &'static str,
    },
}

impl SynthParams {
    /// Checks that the parameters describe a trace.
    pub fn validate(&self) -> Result<(), SynthError> {
        let bad = |field: &'static str, value: String, expected: &'static str| {
            Err(SynthError::BadParam {
                field,
                value,
                expected,
            })
        };
        if !self.head_position.is_finite() {
            return bad(
                "head_position",
                format!("{}", self.head_position),
                "finite coordinates",
            );
        }
        if self.targets.is_empty() {
            return bad("targets", "empty".into(), "at least one fixation target");
        }
        for t in &self.targets {
            let v = t.point_m;
            if !v.is_finite() {
                return bad(
                    "targets",
                    format!("`{}` at {v}", t.name),
                    "finite coordinates",
                );
            }
            if v.distance(self.head_position) < 0.01 {
                return bad(
                    "targets",
                    format!("`{}` at {v}", t.name),
                    "a point at least 1 cm from head_position",
                );
            }
        }
        let non_negative = [
            ("ipd_m", self.ipd_m),
            ("duration_s", self.duration_s),
            ("noise_deg", self.noise_deg),
            ("blink_duration_s", self.blink_duration_s),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("{v}"), "a finite number >= 0");
            }
        }
        for (field, v) in [
            ("switch_period_s", self.switch_period_s),
            ("blink_every_s", self.blink_every_s),
        ] {
            if !v.is_finite() {
                return bad(field, format!("{v}"), "a finite number (<= 0 to disable)");
            }
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= 1e6) {
            return bad(
                "rate_hz",
                format!("{}", self.rate_hz),
                "a rate in (0, 1e6] Hz",
            );
        }
        if f64::from(self.duration_s) * f64::from(self.rate_hz) > MAX_SAMPLES {
            return bad(
                "duration_s",
                format!("{}", self.duration_s),
                "at most 1e8 samples (duration_s * rate_hz)",
            );
        }
        Ok(())
    }
}

/// A stretch of time with one gaze target: the ground truth for switch-latency tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazePhase {
    /// First nanosecond of the phase (trace clock).
    pub start_ns: i64,
    /// End of the phase, nanoseconds, exclusive; the last phase ends after the last sample.
    pub end_ns: i64,
    /// Which target is fixated: an index into [`SynthParams::targets`].
    pub target: usize,
    /// That point in the world frame, metres.
    pub point_world: Vec3,
}

/// A blink: both eyes invalid from `start_ns` (inclusive) to `end_ns` (exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Blink {
    /// Start, nanoseconds.
    pub start_ns: i64,
    /// End, nanoseconds, exclusive.
    pub end_ns: i64,
}

/// A synthetic trace and what is true about it.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthTrace {
    /// The samples, times from 0 at `rate_hz`.
    pub samples: Vec<TraceSample>,
    /// The gaze phases in time order, covering the whole trace.
    pub phases: Vec<GazePhase>,
    /// The blinks that start within the trace.
    pub blinks: Vec<Blink>,
}

impl SynthTrace {
    /// The phase at a time, if the time is within the trace.
    pub fn phase_at(&self, time_ns: i64) -> Option<&GazePhase> {
        self.phases
            .iter()
            .find(|p| p.start_ns <= time_ns && time_ns < p.end_ns)
    }
}

/// Synthesises a trace; empty (with a warning logged) if the parameters are invalid — use
/// [`synthesize_with_truth`] to get the reason.
pub fn synthesize(params: &SynthParams) -> Vec<TraceSample> {
    match synthesize_with_truth(params) {
        Ok(trace) => trace.samples,
        Err(e) => {
            tracing::warn!("{e}");
            Vec::new()
        }
    }
}

/// Synthesises a trace with its ground truth (gaze phases, blinks).
pub fn synthesize_with_truth(params: &SynthParams) -> Result<SynthTrace, SynthError> {
    params.validate()?;
    let p = params;
    let seconds_to_ns = |s: f64| (s * 1e9).round() as i64;
    let n = (f64::from(p.duration_s) * f64::from(p.rate_hz)).floor() as u64 + 1;
    let time_of = |k: u64| seconds_to_ns(k as f64 / f64::from(p.rate_hz));
    let end_ns = time_of(n - 1) + 1;

    let mut rng = SplitMix64(p.seed);
    let sway = Sway::new(&mut rng);
    let base = look_at(p.head_position, p.targets[0].point_m);

    let phases = phases(p, end_ns, seconds_to_ns);
    let blinks = blinks(p, end_ns, seconds_to_ns);
    let mut noise = SplitMix64(p.seed ^ 0x9e37_79b9_7f4a_7c15);
    let noise_rad = p.noise_deg.to_radians();

    let mut samples = Vec::with_capacity(n as usize);
    let mut phase = 0;
    for k in 0..n {
        let time_ns = time_of(k);
        let t_s = k as f32 / p.rate_hz;
        while phase + 1 < phases.len() && phases[phase].end_ns <= time_ns {
            phase += 1;
        }
        let (offset_m, rotation) = sway.at(t_s);
        let head = Pose {
            position: p.head_position + offset_m,
            orientation: (base * rotation).normalize(),
        };
        let blinking = blinks
            .iter()
            .any(|b| b.start_ns <= time_ns && time_ns < b.end_ns);
        // Draw noise even during blinks so a blink does not shift later noise.
        let mut eye = |side: f32| {
            let origin = Vec3::new(side * p.ipd_m / 2.0, 0.0, 0.0);
            let target_head = head
                .orientation
                .inverse()
                .mul_vec3(phases[phase].point_world - head.position);
            let direction = add_noise(
                (target_head - origin).normalize(),
                noise.gaussian() as f32 * noise_rad,
                noise.gaussian() as f32 * noise_rad,
            );
            if blinking {
                GazeRay::INVALID
            } else {
                GazeRay {
                    origin,
                    direction,
                    valid: true,
                }
            }
        };
        let left = eye(-1.0);
        let right = eye(1.0);
        let pupils = pupil::pupil_diameters_m(p.seed, t_s);
        samples.push(TraceSample {
            time_ns,
            head,
            gaze: GazeSample {
                sample_time_ns: time_ns,
                left,
                right,
                combined: None,
                fixation: None,
                pupil_diameter_m: [
                    left.valid.then_some(pupils[0]),
                    right.valid.then_some(pupils[1]),
                ],
                report: None,
            },
        });
    }
    Ok(SynthTrace {
        samples,
        phases,
        blinks,
    })
}

/// The gaze phases: the targets in list order, one per `switch_period_s`, over and over.
fn phases(p: &SynthParams, end_ns: i64, seconds_to_ns: impl Fn(f64) -> i64) -> Vec<GazePhase> {
    let mut phases = Vec::new();
    let period = f64::from(p.switch_period_s);
    let mut i = 0u64;
    loop {
        let target = (i % p.targets.len() as u64) as usize;
        let start_ns = seconds_to_ns(i as f64 * period);
        let phase_end = if period > 0.0 {
            seconds_to_ns((i + 1) as f64 * period).min(end_ns)
        } else {
            end_ns
        };
        phases.push(GazePhase {
            start_ns,
            end_ns: phase_end,
            target,
            point_world: p.targets[target].point_m,
        });
        if phase_end >= end_ns {
            return phases;
        }
        i += 1;
    }
}

/// The blinks that start before `end_ns`.
fn blinks(p: &SynthParams, end_ns: i64, seconds_to_ns: impl Fn(f64) -> i64) -> Vec<Blink> {
    let mut blinks = Vec::new();
    if p.blink_every_s <= 0.0 || p.blink_duration_s <= 0.0 {
        return blinks;
    }
    for k in 1u64.. {
        let start_s = k as f64 * f64::from(p.blink_every_s);
        let start_ns = seconds_to_ns(start_s);
        if start_ns >= end_ns {
            break;
        }
        blinks.push(Blink {
            start_ns,
            end_ns: seconds_to_ns(start_s + f64::from(p.blink_duration_s)),
        });
    }
    blinks
}

/// The orientation whose -z looks from `eye` at `target` with +y as close to up as possible.
fn look_at(eye: Vec3, target: Vec3) -> Quat {
    let forward = (target - eye).normalize();
    let up = if forward.cross(Vec3::Y).length_squared() > 1e-6 {
        Vec3::Y
    } else {
        Vec3::Z
    };
    let right = forward.cross(up).normalize();
    let up = right.cross(forward);
    Quat::from_mat3(&Mat3::from_cols(right, up, -forward)).normalize()
}

/// Tilts a unit direction by two small angles about axes perpendicular to it.
fn add_noise(direction: Vec3, a_rad: f32, b_rad: f32) -> Vec3 {
    if a_rad == 0.0 && b_rad == 0.0 {
        return direction;
    }
    let (u, v) = direction.any_orthonormal_pair();
    (direction + u * a_rad.tan() + v * b_rad.tan()).normalize()
}

/// A slow head sway: a sum of sinusoids per axis with seeded phases and frequencies.
struct Sway {
    /// Per axis (position x, y, z, rotation about x, y, z): frequency in Hz and phase in rad.
    terms: [(f32, f32); 6],
}

impl Sway {
    fn new(rng: &mut SplitMix64) -> Sway {
        let mut terms = [(0.0, 0.0); 6];
        for t in &mut terms {
            let frequency_hz = 0.05 + 0.25 * rng.unit() as f32;
            let phase_rad = std::f32::consts::TAU * rng.unit() as f32;
            *t = (frequency_hz, phase_rad);
        }
        Sway { terms }
    }

    /// Position offset (world, metres) and rotation (head frame) at time `t_s`.
    fn at(&self, t_s: f32) -> (Vec3, Quat) {
        let w = |i: usize| {
            let (f, ph) = self.terms[i];
            (std::f32::consts::TAU * f * t_s + ph).sin()
        };
        let offset = Vec3::new(w(0), w(1), w(2)) * SWAY_POSITION_M;
        let a = SWAY_ANGLE_DEG.to_radians();
        let rotation = Quat::from_rotation_y(w(4) * a)
            * Quat::from_rotation_x(w(3) * a)
            * Quat::from_rotation_z(w(5) * a);
        (offset, rotation)
    }
}

/// A small, well-mixed deterministic PRNG (SplitMix64, Steele, Lea and Flood 2014): enough for
/// noise, sway, simulated observers and study plans. Its sequence for a seed never changes,
/// which is what makes a seeded study plan reproducible across versions.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform integer in `0..n` (`n` > 0), without modulo bias (Lemire's multiply-shift with
    /// rejection).
    pub fn below(&mut self, n: u64) -> u64 {
        assert!(n > 0, "below(0)");
        let threshold = n.wrapping_neg() % n;
        loop {
            let product = u128::from(self.next_u64()) * u128::from(n);
            if (product as u64) >= threshold {
                return (product >> 64) as u64;
            }
        }
    }

    /// Shuffles `items` in place (Fisher-Yates).
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = self.below(i as u64 + 1) as usize;
            items.swap(i, j);
        }
    }

    /// Standard normal (Box-Muller).
    pub fn gaussian(&mut self) -> f64 {
        let u1 = 1.0 - self.unit(); // (0, 1]: ln is finite
        let u2 = self.unit();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests;
