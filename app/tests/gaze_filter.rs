//! eq. 15 through the whole pipeline: tracker samples, not frames, are averaged.

use proptest::prelude::*;
use vitreous_gaze::{
    FilterKind, FixationDepth, GazeConfig, GazePipeline, ImageDistances, SampleFilter,
};
use vitreous_trace::GazeSample;

/// eq. 15 as printed: the mean of the 20 depths ending at index `n` (n >= 19).
fn eq15(depths: &[f64], n: usize) -> f64 {
    (0..20).map(|i| depths[n - i]).sum::<f64>() / 20.0
}

fn looking_at(time_ns: i64, depth_m: f32) -> GazeSample {
    vitreous_frames::test_frame::sample_looking_at(time_ns, depth_m)
}

proptest! {
    #[test]
    fn sample_filter_output_is_eq15(depths in proptest::collection::vec(0.05f32..10.0, 20..200)) {
        let mut f = SampleFilter::new(FilterKind::PAPER);
        let exact: Vec<f64> = depths.iter().map(|&d| f64::from(d)).collect();
        for (n, &d) in depths.iter().enumerate() {
            let out = f.feed(&FixationDepth::Known { depth_m: d, sample_time_ns: n as i64 });
            if n >= 19 {
                let want = eq15(&exact, n);
                let got = f64::from(out.depth_m().unwrap());
                prop_assert!((got - want).abs() <= 1e-6 * want, "n = {}: {} vs {}", n, got, want);
            }
        }
    }

    /// A 90 Hz render loop fed by a 30 Hz tracker sees each sample three times (or any
    /// number of times): the filtered depth is the same as feeding each sample once, and
    /// equals eq. 15 over the tracker samples.
    #[test]
    fn frames_repeating_tracker_samples_do_not_change_eq15(
        depths in proptest::collection::vec(0.2f32..5.0, 20..80),
        frames_per_sample in proptest::collection::vec(1usize..6, 80),
    ) {
        let distances = ImageDistances { surface_m: 0.6, refracted_m: 1.5 };
        let config = GazeConfig {
            filter: FilterKind::PAPER,
            ..GazeConfig::new(distances)
        };
        let mut once = GazePipeline::new(config);
        let mut per_frame = GazePipeline::new(config);
        let mut raw = Vec::new();
        let sample_ns = 33_333_333i64;
        for (n, &d) in depths.iter().enumerate() {
            let g = looking_at(n as i64 * sample_ns, d);
            let a = once.update(Some(&g), g.sample_time_ns);
            raw.push(f64::from(a.raw_depth.depth_m().unwrap()));
            let mut b = None;
            for k in 0..frames_per_sample[n] {
                let frame_ns = g.sample_time_ns + k as i64 * 11_111_111;
                b = Some(per_frame.update(Some(&g), frame_ns));
            }
            let b = b.unwrap();
            prop_assert_eq!(a.filtered_depth, b.filtered_depth);
            prop_assert_eq!(a.image, b.image);
            if n >= 19 {
                let want = eq15(&raw, n);
                let got = f64::from(a.filtered_depth.depth_m().unwrap());
                prop_assert!((got - want).abs() <= 1e-6 * want, "{} vs {}", got, want);
            }
        }
    }
}

proptest! {
    /// The fixation filter too ingests each tracker sample once: frames repeating a sample
    /// change neither its depth nor its decision.
    #[test]
    fn frames_repeating_tracker_samples_do_not_change_the_fixation_decision(
        depths in proptest::collection::vec(prop_oneof![0.5f32..0.7, 1.3f32..1.7], 20..120),
        frames_per_sample in proptest::collection::vec(1usize..5, 120),
    ) {
        let distances = ImageDistances { surface_m: 0.6, refracted_m: 1.5 };
        let config = GazeConfig {
            filter: "fixation".parse().unwrap(),
            ..GazeConfig::new(distances)
        };
        let mut once = GazePipeline::new(config);
        let mut per_frame = GazePipeline::new(config);
        let sample_ns = 8_333_333i64;
        for (n, &d) in depths.iter().enumerate() {
            let g = looking_at(n as i64 * sample_ns, d);
            let a = once.update(Some(&g), g.sample_time_ns);
            let mut b = None;
            for k in 0..frames_per_sample[n] {
                b = Some(per_frame.update(Some(&g), g.sample_time_ns + k as i64 * 2_000_000));
            }
            let b = b.unwrap();
            prop_assert_eq!(a.filtered_depth, b.filtered_depth);
            prop_assert_eq!(a.image, b.image);
        }
    }
}

#[test]
fn filters_parse_from_scene_style_names() {
    assert_eq!("mean20".parse::<FilterKind>().unwrap(), FilterKind::PAPER);
    assert_eq!(
        "evidence".parse::<FilterKind>().unwrap(),
        FilterKind::default()
    );
    for name in [
        "median",
        "one-euro",
        "mean:10",
        "fixation",
        "Fixation:settle=200",
        "evidence",
        "Evidence:threshold=3",
    ] {
        assert!(name.parse::<FilterKind>().is_ok(), "{name}");
    }
    let e = "kalman".parse::<FilterKind>().unwrap_err().to_string();
    assert!(e.contains("kalman") && e.contains("one-euro"), "{e}");
}
