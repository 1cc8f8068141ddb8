//! Tests of the classifier and the fixation filter.

use super::*;
use crate::test_samples::looking;
use vitreous_trace::GazeRay;

const D: ImageDistances = ImageDistances {
    surface_m: 0.6,
    refracted_m: 1.5,
};

fn blink(t_ns: i64) -> GazeSample {
    GazeSample {
        left: GazeRay::INVALID,
        right: GazeRay::INVALID,
        ..looking(t_ns, 1.0, 0.0)
    }
}

/// Runs samples through the vergence estimator and a fixation filter; the decisions.
fn run(samples: &[GazeSample]) -> Vec<(i64, GazeImage)> {
    run_with(FixationParams::default(), samples)
}

/// [`run`] with given parameters.
fn run_with(params: FixationParams, samples: &[GazeSample]) -> Vec<(i64, GazeImage)> {
    use super::super::vergence::{VergenceConfig, VergenceEstimator};
    let mut v = VergenceEstimator::new(VergenceConfig::default());
    let mut f = FixationFilter::new(params, D, 0.2);
    samples
        .iter()
        .map(|g| {
            let raw = v.update(Some(g), g.sample_time_ns);
            (g.sample_time_ns, f.update(Some(g), &raw, v.measurement()).1)
        })
        .collect()
}

const MS: i64 = 1_000_000;

#[test]
fn classifier_separates_fixations_saccades_and_gaps() {
    let mut c = VelocityClassifier::new(30.0);
    let dir = |deg: f32| {
        let a = deg.to_radians();
        Vec3::new(a.sin(), 0.0, -a.cos())
    };
    // 0.2 deg in 10 ms is 20 deg/s: a fixation; 2 deg in 10 ms is 200 deg/s: a saccade.
    let steps = [
        c.step(0, Some(dir(0.0))),
        c.step(10 * MS, Some(dir(0.2))),
        c.step(20 * MS, Some(dir(2.2))),
        c.step(30 * MS, Some(dir(4.2))),
        c.step(40 * MS, Some(dir(4.3))),
        c.step(50 * MS, None),
        c.step(60 * MS, Some(dir(4.3))),
        c.step(70 * MS, Some(dir(4.3))),
        c.step(170 * MS, Some(dir(4.3))),
    ];
    assert_eq!(
        steps,
        [
            Step::AfterGap,
            Step::Continues,
            Step::Moving,
            Step::Moving,
            Step::NewFixation { start_ns: 30 * MS },
            Step::Gap,
            Step::AfterGap,
            Step::Continues,
            // 100 ms without a sample: a dropout.
            Step::AfterGap,
        ]
    );
    let classes = classes_of(&steps);
    assert_eq!(classes[2], SampleClass::Saccade);
    assert_eq!(classes[3], SampleClass::Fixation);
    assert_eq!(classes[5], SampleClass::Gap);
    let times: Vec<i64> = (0..9).map(|i| i * 10 * MS).collect();
    assert_eq!(
        fixation_spans(&times, &steps, 10 * MS),
        [(0, 10 * MS), (30 * MS, 40 * MS), (60 * MS, 70 * MS)]
    );
}

#[test]
fn a_noise_spike_is_merged_into_the_fixation() {
    let mut c = VelocityClassifier::new(30.0);
    let dir = |deg: f32| {
        let a = deg.to_radians();
        Vec3::new(a.sin(), 0.0, -a.cos())
    };
    // 30 Hz: a 1.2 degree spike (36 deg/s) that comes back is no saccade.
    let steps: Vec<Step> = [0.0, 0.1, 1.3, 0.2, 0.1]
        .iter()
        .enumerate()
        .map(|(i, &d)| c.step(i as i64 * 33 * MS, Some(dir(d))))
        .collect();
    assert_eq!(
        steps,
        [
            Step::AfterGap,
            Step::Continues,
            Step::Moving,
            Step::Continues,
            Step::Continues
        ]
    );
    assert!(
        classes_of(&steps)
            .iter()
            .all(|c| *c == SampleClass::Fixation)
    );
}

#[test]
fn decides_only_after_the_settle_time_and_a_fixation() {
    // 120 Hz at the refracted image.
    let samples: Vec<GazeSample> = (0..40).map(|i| looking(i * 8_333_333, 1.5, 0.0)).collect();
    let out = run(&samples);
    let first = out.iter().find(|o| o.1 != GazeImage::Unknown).unwrap();
    assert_eq!(first.1, GazeImage::Refracted);
    assert!((150 * MS..170 * MS).contains(&first.0), "{first:?}");
}

#[test]
fn one_diverging_pair_after_a_reset_does_not_decide() {
    // At the surface, then lost for 400 ms (longer than the 300 ms hold), then one
    // diverging pair, then the surface again.
    let mut samples: Vec<GazeSample> = (0..30).map(|i| looking(i * 10 * MS, 0.6, 0.0)).collect();
    samples.extend((30..70).map(|i| blink(i * 10 * MS)));
    let mut diverging = looking(700 * MS, 0.6, 0.0);
    diverging.left.direction = Vec3::new(-0.02, 0.0, -1.0).normalize();
    diverging.right.direction = Vec3::new(0.02, 0.0, -1.0).normalize();
    samples.push(diverging);
    samples.extend((71..120).map(|i| looking(i * 10 * MS, 0.6, 0.0)));
    let out = run(&samples);
    assert!(out.iter().all(|o| o.1 != GazeImage::Refracted), "{out:?}");
    // Unknown after the hold, the surface again 150 ms after tracking resumed.
    assert_eq!(out[69].1, GazeImage::Unknown);
    let back = out[70..]
        .iter()
        .find(|o| o.1 == GazeImage::Surface)
        .unwrap();
    assert!(back.0 >= 850 * MS, "{back:?}");
}

#[test]
fn holds_through_a_blink_and_waits_after_it() {
    // Surface, a 150 ms blink, then the refracted image right after it.
    let mut samples: Vec<GazeSample> = (0..60).map(|i| looking(i * 10 * MS, 0.6, 0.0)).collect();
    samples.extend((60..75).map(|i| blink(i * 10 * MS)));
    samples.extend((75..140).map(|i| looking(i * 10 * MS, 1.5, 0.0)));
    let out = run(&samples);
    assert!(out[60..75].iter().all(|o| o.1 == GazeImage::Surface));
    let switch = out.iter().find(|o| o.1 == GazeImage::Refracted).unwrap();
    assert!(switch.0 >= 750 * MS + 150 * MS, "{switch:?}");
}

#[test]
fn a_vergence_change_without_a_saccade_switches_within_a_fixation() {
    let mut samples: Vec<GazeSample> = (0..60).map(|i| looking(i * 10 * MS, 0.6, 0.0)).collect();
    samples.extend((60..100).map(|i| looking(i * 10 * MS, 1.5, 0.0)));
    let out = run(&samples);
    let switch = out.iter().find(|o| o.1 == GazeImage::Refracted).unwrap();
    assert!((600 * MS..=700 * MS).contains(&switch.0), "{switch:?}");
}

/// The first time the decision is `refracted`.
fn first_refracted(out: &[(i64, GazeImage)]) -> i64 {
    out.iter().find(|o| o.1 == GazeImage::Refracted).unwrap().0
}

#[test]
fn a_longer_trailing_stretch_switches_when_the_window_median_lags() {
    // 30 Hz, the surface for 1 s, then a pure vergence change to the far side with noisy
    // samples (dioptres; the decision leaves the surface below 0.96 D). Every 100 ms window
    // (4 samples) has a median of 1.0 D until the fifth new sample, when the 5 samples
    // since the change have a median of 0.9 D.
    let t = |i: i64| i * 33_333_333;
    let mut samples: Vec<GazeSample> = (0..30).map(|i| looking(t(i), 0.6, 0.0)).collect();
    for (k, dioptres) in [0.8f32, 1.1, 0.9, 1.2, 0.5, 0.7, 0.7]
        .into_iter()
        .enumerate()
    {
        samples.push(looking(t(30 + k as i64), 1.0 / dioptres, 0.0));
    }
    assert_eq!(first_refracted(&run(&samples)), t(34));
    let window_only = FixationParams {
        max_window_ms: DEFAULT_WINDOW_MS,
        ..FixationParams::default()
    };
    assert_eq!(first_refracted(&run_with(window_only, &samples)), t(35));
}

#[test]
fn the_first_decision_starts_an_episode_of_at_least_the_settle_time() {
    // 100 Hz: the surface for 160 ms (decided at 150 ms), then the refracted image.
    let samples: Vec<GazeSample> = (0..60)
        .map(|i| looking(i * 10 * MS, if i < 16 { 0.6 } else { 1.5 }, 0.0))
        .collect();
    let out = run(&samples);
    let first = out.iter().find(|o| o.1 != GazeImage::Unknown).unwrap();
    assert_eq!(first.1, GazeImage::Surface);
    assert!(first_refracted(&out) >= first.0 + 150 * MS, "{out:?}");
}

#[test]
fn alternating_fixations_never_make_an_episode_under_the_settle_time() {
    // Fixations of 80 ms alternating between the images, with saccades between them.
    let samples: Vec<GazeSample> = (0..300)
        .map(|i| {
            let k = i / 8;
            let (depth, offset) = if k % 2 == 0 { (0.6, 0.0) } else { (1.5, 5.0) };
            looking(i * 10 * MS, depth, offset)
        })
        .collect();
    let out = run(&samples);
    let mut switches: Vec<i64> = Vec::new();
    let mut shown = GazeImage::Unknown;
    for &(t, image) in &out {
        if image != GazeImage::Unknown && image != shown {
            if shown != GazeImage::Unknown {
                switches.push(t);
            }
            shown = image;
        }
    }
    assert!(!switches.is_empty());
    assert!(
        switches.windows(2).all(|w| w[1] - w[0] >= 150 * MS),
        "{switches:?}"
    );
}
