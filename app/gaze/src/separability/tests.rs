//! Tests of `separability`.

use glam::Vec3;
use vitreous_trace::GazeRay;
use vitreous_trace::synth::SplitMix64;

use super::*;

fn sample(left_dir: Vec3, right_dir: Vec3, baseline_m: f32) -> GazeSample {
    let ray = |x: f32, d: Vec3| GazeRay {
        origin: Vec3::new(x, 0.0, 0.0),
        direction: d.normalize(),
        valid: true,
    };
    GazeSample {
        left: ray(-baseline_m / 2.0, left_dir),
        right: ray(baseline_m / 2.0, right_dir),
        ..GazeSample::none(0)
    }
}

#[test]
fn a_symmetric_fixation_reads_the_geometric_vergence() {
    for depth in [0.125f32, 0.4, 1.48, 2.03, 10.0] {
        let b = 0.064;
        let target = Vec3::new(0.0, 0.0, -depth);
        let s = sample(
            target - Vec3::new(-b / 2.0, 0.0, 0.0),
            target - Vec3::new(b / 2.0, 0.0, 0.0),
            b,
        );
        let r = reading(&s, depth);
        assert!((r.baseline_m - b).abs() < 1e-6);
        let expected = vergence_deg(depth, b);
        assert!(
            (r.vergence_deg - expected).abs() < 1e-3,
            "{depth} m: {} against {expected}",
            r.vergence_deg
        );
    }
}

#[test]
fn diverging_rays_read_negative() {
    let turn = 0.5f32.to_radians();
    let s = sample(
        Vec3::new(-turn.sin(), 0.0, -turn.cos()),
        Vec3::new(turn.sin(), 0.0, -turn.cos()),
        0.063,
    );
    let r = reading(&s, 10.0);
    assert!((r.vergence_deg + 1.0).abs() < 1e-3, "{}", r.vergence_deg);
}

#[test]
fn glass_sphere_images_are_two_thirds_of_a_degree_apart() {
    let d = ImageDistances {
        surface_m: 1.48,
        refracted_m: 2.03,
    };
    let s = Separability::new(&d, 0.063, 0.7, true);
    assert!((s.gap_deg - 0.66).abs() < 0.01, "{}", s.gap_deg);
    assert!(!s.separable());
    let paper = ImageDistances {
        surface_m: 0.125,
        refracted_m: 0.4,
    };
    assert!(Separability::new(&paper, 0.063, 0.7, true).d_prime() > 25.0);
}

/// Normal noise of known sigma on fixations whose vergence changes in steps (the wearer
/// looking from one depth to another every 3-5 s), with saccades and gaps between them:
/// the estimate is within 15 % of sigma (a window that straddles a step leans toward the
/// other side: the estimate runs a little high, never low).
#[test]
fn noise_estimate_recovers_the_sigma_of_normal_noise() {
    for (seed, sigma) in [(1u64, 0.3f32), (2, 0.7), (3, 1.5)] {
        let mut rng = SplitMix64(seed);
        let mut est = VergenceNoise::new();
        let mut t = 0i64;
        for _ in 0..40 {
            // A stretch of tracking: dwells of 3-5 s at one depth each, then a blink.
            for _ in 0..(1 + rng.below(4)) {
                let centre = 10.0 * rng.unit() as f32;
                let n = 90 + rng.below(60);
                for _ in 0..n {
                    let v = centre + sigma * rng.gaussian() as f32;
                    est.push(t, Some(v), true);
                    t += 33_333_333;
                }
                // A saccade's samples are left out.
                est.push(t, Some(50.0), false);
                t += 33_333_333;
            }
            est.push(t, None, false);
            t += 150_000_000;
        }
        est.close();
        let got = est.sigma_deg().unwrap();
        assert!(
            (0.97..1.15).contains(&(got / sigma)),
            "seed {seed}: {got} for {sigma}"
        );
    }
}

#[test]
fn the_warning_comes_only_from_an_estimated_noise_too_large() {
    let d = ImageDistances {
        surface_m: 1.48,
        refracted_m: 2.03,
    };
    assert_eq!(Separability::new(&d, 0.063, 1.0, false).warning(), None);
    assert_eq!(Separability::new(&d, 0.063, 0.3, true).warning(), None);
    let warning = Separability::new(&d, 0.063, 0.8, true).warning().unwrap();
    assert!(warning.contains("cannot tell the surface from the refracted image apart"));
    assert!(warning.contains("d' = 0.83"), "{warning}");
    let line = Separability::new(&d, 0.063, 0.8, true).summary().line();
    assert!(line.contains("d' = 0.83, below 1"), "{line}");
}

#[test]
fn no_estimate_from_too_little_or_from_saccades() {
    let mut est = VergenceNoise::new();
    for k in 0..(MIN_WINDOW as i64 - 1) {
        est.push(k * 10_000_000, Some(k as f32), true);
    }
    est.close();
    assert_eq!(est.sigma_deg(), None);
    for k in 0..100 {
        est.push(k * 10_000_000, Some(k as f32), false);
    }
    est.close();
    assert_eq!(est.sigma_deg(), None);
    assert_eq!(est.pooled(), 0);
}

/// The pooled evidence is the time the fixations lasted, whatever the tracker's rate: 8 s of
/// fixation at 30 Hz and at 120 Hz pool about 8 s each (less the few samples at each stretch's
/// ends whose window is too small), so the prior's 10 s weigh about the same against both,
/// although one has four times the samples; and no more than [`MAX_POOLED_S`] are kept.
#[test]
fn pooled_evidence_is_counted_in_seconds_not_samples() {
    let mut pooled_s = Vec::new();
    for rate_hz in [30i64, 120] {
        let mut rng = SplitMix64(7);
        let mut est = VergenceNoise::new();
        let step = 1_000_000_000 / rate_hz;
        // Two stretches of 4 s, a blink between them.
        let mut t = 0i64;
        for _ in 0..2 {
            for _ in 0..4 * rate_hz {
                est.push(t, Some(1.0 + 0.5 * rng.gaussian() as f32), true);
                t += step;
            }
            est.push(t, None, false);
            t += 200_000_000;
        }
        est.close();
        let pooled = est.pooled_s();
        assert!((7.5..=8.0).contains(&pooled), "{rate_hz} Hz: {pooled} s");
        assert!(est.pooled() as i64 > 7 * rate_hz, "{rate_hz} Hz");
        pooled_s.push(pooled);
    }
    assert!((pooled_s[0] - pooled_s[1]).abs() < 0.5, "{pooled_s:?}");
    let mut est = VergenceNoise::new();
    for k in 0..(60 * 30) {
        est.push(k * 33_333_333, Some(1.0), true);
    }
    est.close();
    assert!(est.pooled_s() <= MAX_POOLED_S, "{}", est.pooled_s());
    assert!(est.pooled_s() > MAX_POOLED_S - 0.1, "{}", est.pooled_s());
}
