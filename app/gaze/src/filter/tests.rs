//! Tests of the depth filters (eq. 15 and the alternatives) and of their names.

use super::*;
use proptest::prelude::*;

/// eq. 15 as printed (for n >= 19, zero-based), computed independently in f64.
fn eq15(d: &[f32], n: usize) -> f64 {
    (0..20).map(|i| f64::from(d[n - i])).sum::<f64>() / 20.0
}

proptest! {
    #[test]
    fn mean20_equals_eq15_on_random_sequences(
        depths in proptest::collection::vec(0.05f32..10.0, 20..120)
    ) {
        let mut f = SampleFilter::new(FilterKind::PAPER);
        for (n, &d) in depths.iter().enumerate() {
            let out = f.feed(&FixationDepth::Known { depth_m: d, sample_time_ns: n as i64 })
                .depth_m().unwrap();
            if n >= 19 {
                let want = eq15(&depths, n);
                prop_assert!((f64::from(out) - want).abs() <= 1e-6 * want.max(1.0),
                    "n={} {} vs {}", n, out, want);
            }
        }
    }

    #[test]
    fn repeated_frames_of_one_sample_change_nothing(
        depths in proptest::collection::vec(0.05f32..10.0, 1..80),
        repeats in proptest::collection::vec(1usize..5, 80),
        kind_index in 0usize..4,
    ) {
        let kind = FilterKind::all_default()[kind_index];
        let (mut once, mut many) = (SampleFilter::new(kind), SampleFilter::new(kind));
        for (n, &d) in depths.iter().enumerate() {
            let raw = FixationDepth::Known { depth_m: d, sample_time_ns: n as i64 * 33_333_333 };
            let a = once.feed(&raw);
            let mut b = FixationDepth::Unknown;
            for _ in 0..repeats[n] {
                b = many.feed(&raw);
            }
            prop_assert_eq!(a, b);
        }
    }
}

#[test]
fn names_round_trip_and_bad_names_are_refused() {
    for text in [
        "mean20",
        "median5",
        "median7",
        "one-euro",
        "one-euro:min_cutoff=2,beta=0.1,d_cutoff=1,pre_median=1",
        "fixation",
        "fixation:velocity=40,min_fixation=80,window=120,max_window=160,settle=200",
        "evidence",
        "evidence:velocity=40,threshold=4,step=20,settle=200,min_separability=1.5,noise=0.7,\
         margin=2",
    ] {
        let kind: FilterKind = text.parse().unwrap();
        assert_eq!(kind.to_string(), text);
        assert_eq!(kind.to_string().parse::<FilterKind>().unwrap(), kind);
    }
    assert_eq!("mean".parse::<FilterKind>().unwrap(), FilterKind::PAPER);
    assert_eq!(
        "evidence".parse::<FilterKind>().unwrap(),
        FilterKind::default()
    );
    for bad in [
        "evidence:threshold=0",
        "evidence:noise=0",
        "evidence:speed=3",
    ] {
        assert!(bad.parse::<FilterKind>().is_err(), "{bad}");
    }
    assert_eq!(
        "MEDIAN:9".parse::<FilterKind>().unwrap(),
        FilterKind::Median { window: 9 }
    );
    for bad in [
        "",
        "mode",
        "mean0",
        "mean:x",
        "one-euro:beta",
        "one-euro:gamma=1",
        "one-euro:min_cutoff=0",
        "fixation:velocity=0",
        "fixation:speed=3",
        "fixation:window",
    ] {
        let e = bad.parse::<FilterKind>().unwrap_err();
        assert!(e.to_string().contains("mean20"), "{e}");
    }
}

#[test]
fn median_ignores_a_lone_outlier_and_follows_a_step_in_three() {
    let mut f = MedianFilter::new(5);
    let mut out = Vec::new();
    for (i, d) in [1.0, 1.0, 1.0, 10.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0]
        .into_iter()
        .enumerate()
    {
        out.push(f.push(d, i as i64));
    }
    assert_eq!(out, [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0]);
}

#[test]
fn unknown_resets_the_filter() {
    let mut f = SampleFilter::new(FilterKind::PAPER);
    f.feed(&FixationDepth::Known {
        depth_m: 5.0,
        sample_time_ns: 0,
    });
    assert_eq!(f.feed(&FixationDepth::Unknown), FixationDepth::Unknown);
    let after = f.feed(&FixationDepth::Known {
        depth_m: 1.0,
        sample_time_ns: 1,
    });
    assert_eq!(after.depth_m(), Some(1.0));
}
