//! Tests of the evidence decision.

use super::*;
use crate::test_samples::looking;
use vitreous_trace::{GazeBehaviour, GazeRay, TrackerReport};

const D: ImageDistances = ImageDistances {
    surface_m: 0.6,
    refracted_m: 1.5,
};

const MS: i64 = 1_000_000;

/// Runs samples through the vergence estimator and an evidence filter set up by `setup`;
/// the decisions.
fn run_with(
    params: EvidenceParams,
    distances: ImageDistances,
    setup: impl Fn(&mut EvidenceFilter),
    samples: &[GazeSample],
) -> Vec<(i64, GazeImage)> {
    use super::super::vergence::{VergenceConfig, VergenceEstimator};
    let mut v = VergenceEstimator::new(VergenceConfig::default());
    let mut f = EvidenceFilter::new(params, distances);
    setup(&mut f);
    samples
        .iter()
        .map(|g| {
            let raw = v.update(Some(g), g.sample_time_ns);
            (g.sample_time_ns, f.update(Some(g), &raw, v.measurement()).1)
        })
        .collect()
}

fn run(samples: &[GazeSample]) -> Vec<(i64, GazeImage)> {
    run_with(EvidenceParams::default(), D, |_| {}, samples)
}

/// `n` samples every `dt_ms` from `t0_ms`, at `depth_m`.
fn fixating(t0_ms: i64, n: i64, dt_ms: i64, depth_m: f32) -> Vec<GazeSample> {
    (0..n)
        .map(|k| looking((t0_ms + k * dt_ms) * MS, depth_m, 0.0))
        .collect()
}

/// The first time the decision is `image`, milliseconds.
fn first(decisions: &[(i64, GazeImage)], image: GazeImage) -> Option<i64> {
    decisions.iter().find(|d| d.1 == image).map(|d| d.0 / MS)
}

#[test]
fn a_sustained_fixation_decides_after_two_clear_samples_at_30_hz() {
    // Tracking starts at 0: no decision before 150 ms; the evidence is full by then.
    let mut s = fixating(0, 10, 33, 0.6);
    s.extend(fixating(330, 10, 33, 1.5));
    let d = run(&s);
    assert_eq!(first(&d, GazeImage::Surface), Some(165));
    // The second refracted sample (330, 363 ms) carries the evidence to 2.
    assert_eq!(first(&d, GazeImage::Refracted), Some(363));
}

#[test]
fn at_120_hz_evidence_accrues_per_unit_of_time_not_per_sample() {
    let mut s = fixating(0, 40, 8, 0.6);
    s.extend(fixating(320, 40, 8, 1.5));
    let d = run(&s);
    let switch = first(&d, GazeImage::Refracted).unwrap();
    // 2 x 33 ms of clear samples: the 9th refracted sample (8 ms apart), 64 ms after the
    // change.
    assert_eq!(switch, 384);
}

#[test]
fn a_spike_shorter_than_the_threshold_does_not_switch() {
    // 120 Hz far fixation with a 50 ms near-vergence spike in the middle: no switch.
    let spiked = |spike: i64| {
        let mut s = fixating(0, 60, 8, 1.5);
        s.extend(fixating(480, spike, 8, 0.3));
        s.extend(fixating(480 + 8 * spike, 60, 8, 1.5));
        run(&s)
    };
    let d = spiked(6);
    assert_eq!(first(&d, GazeImage::Refracted), Some(152));
    assert_eq!(first(&d, GazeImage::Surface), None);
    // 80 ms of it is a fixation: the surface image, after 64 ms.
    assert_eq!(first(&spiked(10), GazeImage::Surface), Some(544));
}

/// [`looking`] with normal noise of `sigma_deg` on each eye's direction, per axis.
fn noisy(rng: &mut vitreous_trace::synth::SplitMix64, g: GazeSample, sigma_deg: f32) -> GazeSample {
    let mut turn = |r: GazeRay| {
        let yaw = sigma_deg.to_radians() * rng.gaussian() as f32;
        let pitch = sigma_deg.to_radians() * rng.gaussian() as f32;
        GazeRay {
            direction: glam::Quat::from_euler(glam::EulerRot::YXZ, yaw, pitch, 0.0) * r.direction,
            ..r
        }
    };
    GazeSample {
        left: turn(g.left),
        right: turn(g.right),
        ..g
    }
}

#[test]
fn no_decision_while_the_images_are_inside_the_noise() {
    // 1.48 m and 2.03 m: 0.66 degree apart.
    let close = ImageDistances {
        surface_m: 1.48,
        refracted_m: 2.03,
    };
    let trace = |sigma_deg: f32| {
        let mut rng = vitreous_trace::synth::SplitMix64(7);
        let mut s = fixating(0, 600, 33, 1.48);
        s.extend(fixating(20_000, 300, 33, 2.03));
        s.into_iter()
            .map(|g| noisy(&mut rng, g, sigma_deg))
            .collect::<Vec<_>>()
    };
    // 0.6 degree per eye and axis: about 0.85 degree of vergence noise, d' under 1.
    let d = run_with(EvidenceParams::default(), close, |_| {}, &trace(0.6));
    assert!(d.iter().all(|x| x.1 == GazeImage::Unknown));
    let mut f = EvidenceFilter::new(EvidenceParams::default(), close);
    use super::super::vergence::{VergenceConfig, VergenceEstimator};
    let mut v = VergenceEstimator::new(VergenceConfig::default());
    let mut images = Vec::new();
    for g in &trace(0.1) {
        let raw = v.update(Some(g), g.sample_time_ns);
        images.push(f.update(Some(g), &raw, v.measurement()).1);
    }
    // A tracker six times as precise separates them once its noise outweighs the prior (about
    // 400 deviations, 14 s at 30 Hz), and follows the change.
    let sep = f.separability().unwrap();
    assert!(sep.estimated && sep.separable(), "{sep:?}");
    assert_eq!(images.last(), Some(&GazeImage::Refracted));
    assert!(images.contains(&GazeImage::Surface));
}

#[test]
fn gaze_away_from_the_object_holds_the_decision() {
    let object = ObjectInView {
        direction: Vec3::NEG_Z,
        angular_radius_rad: 2f32.to_radians(),
    };
    let mut s = fixating(0, 20, 33, 0.6);
    // Looking 20 degrees to the right at something far: no evidence.
    s.extend((0..30).map(|k| looking((660 + 33 * k) * MS, 1.5, 20.0)));
    // Back on the object, far: the refracted image after three clear samples.
    s.extend((0..10).map(|k| looking((1650 + 33 * k) * MS, 1.5, 0.0)));
    let d = run_with(
        EvidenceParams::default(),
        D,
        |f| f.set_object(Some(object)),
        &s,
    );
    let switch = first(&d, GazeImage::Refracted).unwrap();
    assert!((1650..1800).contains(&switch), "{switch}");
    // Without the object known, the far look switches at once.
    let d = run(&s);
    assert!(first(&d, GazeImage::Refracted).unwrap() < 800);
}

#[test]
fn the_trackers_own_report_withholds_evidence_and_marks_blinks() {
    let report = |confidence, behaviour| {
        Some(TrackerReport {
            confidence,
            behaviour,
        })
    };
    let mut s = fixating(0, 10, 33, 0.6);
    let low: Vec<_> = fixating(330, 10, 33, 1.5)
        .into_iter()
        .map(|g| GazeSample {
            report: report(TrackerConfidence::Low, GazeBehaviour::Fixation),
            ..g
        })
        .collect();
    s.extend(low);
    let d = run(&s);
    assert_eq!(
        first(&d, GazeImage::Refracted),
        None,
        "LOW confidence decided"
    );

    // The tracker calls a blink although the rays look fine: a gap, so no decision within
    // 150 ms after it ends.
    let mut s = fixating(0, 10, 33, 0.6);
    s.extend(fixating(330, 3, 33, 1.5).into_iter().map(|g| GazeSample {
        report: report(TrackerConfidence::High, GazeBehaviour::Blink),
        ..g
    }));
    s.extend(fixating(429, 10, 33, 1.5));
    let d = run(&s);
    let switch = first(&d, GazeImage::Refracted).unwrap();
    assert!(switch >= 429 + 150, "{switch}");
}

#[test]
fn object_in_view_follows_the_head() {
    let o = ObjectInView::from_head(
        Vec3::ZERO,
        glam::Quat::from_rotation_y(90f32.to_radians()),
        Vec3::new(-1.0, 0.0, 0.0),
        0.1,
    )
    .unwrap();
    // Turned 90 degrees left, the object to the left is straight ahead.
    assert!((o.direction - Vec3::NEG_Z).length() < 1e-5);
    assert!((o.angular_radius_rad - 0.1f32.asin()).abs() < 1e-6);
    assert!(o.contains(Vec3::NEG_Z, 0.0));
    assert!(!o.contains(Vec3::X, 0.0));
    assert!(ObjectInView::from_head(Vec3::ZERO, glam::Quat::IDENTITY, Vec3::ZERO, 0.1).is_none());
}

#[test]
fn reported_depth_is_the_smoothed_vergence() {
    use super::super::vergence::{VergenceConfig, VergenceEstimator};
    let mut v = VergenceEstimator::new(VergenceConfig::default());
    let mut f = EvidenceFilter::new(EvidenceParams::default(), D);
    let mut last = FixationDepth::Unknown;
    for g in fixating(0, 30, 33, 0.8) {
        let raw = v.update(Some(&g), g.sample_time_ns);
        last = f.update(Some(&g), &raw, v.measurement()).0;
    }
    let depth = last.depth_m().unwrap();
    assert!((depth - 0.8).abs() < 1e-3, "{depth}");
}
