//! Replaying traces through the gaze pipeline: the synthetic alternating trace (ground
//! truth), blinks, the real SRanipal recordings, and the plot.

use glam::Vec3;
use vitreous::trace_analyze::{FILTER_COLOURS, Truth, analyze, plot};
use vitreous_gaze::analysis::{AnalyzeConfig, replay};
use vitreous_gaze::{FilterKind, GazeConfig, GazeImage, GazeOverride, ImageDistances};
use vitreous_trace::synth::{FixationTarget, SynthParams, SynthTrace, synthesize_with_truth};

/// The synthetic trace the alternative is tuned on: 30 Hz, 0.5 degree noise, blinks every
/// 4 s, gaze switching every 3 s between 0.6 m (the surface, target 0) and 1.5 m (the
/// refracted image, target 1), one minute long.
fn alternating(seed: u64) -> (SynthTrace, ImageDistances) {
    let p = SynthParams {
        duration_s: 60.0,
        seed,
        ..SynthParams::default()
    };
    let trace = synthesize_with_truth(&p).unwrap();
    let d = ImageDistances::from_points(
        p.head_position,
        p.targets[vitreous_scene::SURFACE_TARGET].point_m,
        p.targets[vitreous_scene::REFRACTED_TARGET].point_m,
    );
    (trace, d)
}

#[test]
fn default_and_alternatives_follow_the_synthetic_truth() {
    for seed in 1..=3 {
        let (trace, d) = alternating(seed);
        let report = analyze(
            &trace.samples,
            Truth::Phases(&trace.phases),
            &AnalyzeConfig::new(d),
        );
        assert_eq!(report.truth.changes.len(), 20);
        let mean20 = &report.filters[0];
        assert_eq!(mean20.filter, FilterKind::PAPER);
        for r in &report.filters {
            assert_eq!(r.missed, 0, "seed {seed}:\n{report}");
            assert!(r.agreement.unwrap() > 0.8, "seed {seed}:\n{report}");
            assert!(
                r.false_switches <= mean20.false_switches,
                "seed {seed}:\n{report}"
            );
        }
        // The paper's estimate: ~9.5 samples (~0.32 s) of delay, plus the hysteresis band.
        let m = mean20.mean_latency_ms().unwrap();
        assert!((250.0..600.0).contains(&m), "seed {seed}:\n{report}");
    }
}

#[test]
fn one_euro_meets_the_latency_target_at_30_hz() {
    let mut latencies = Vec::new();
    for seed in 1..=5 {
        let (trace, d) = alternating(seed);
        let mut config = AnalyzeConfig::new(d);
        config.filters = vec![FilterKind::PAPER, "one-euro".parse().unwrap()];
        let report = analyze(&trace.samples, Truth::Phases(&trace.phases), &config);
        let (mean20, alt) = (&report.filters[0], &report.filters[1]);
        assert!(
            alt.false_switches <= mean20.false_switches,
            "seed {seed}:\n{report}"
        );
        latencies.extend(&alt.latencies_ns);
    }
    let mean_ms = latencies.iter().sum::<i64>() as f64 / latencies.len() as f64 / 1e6;
    assert!(mean_ms <= 100.0, "mean switch latency {mean_ms:.0} ms");
}

#[test]
fn blinks_produce_no_spurious_switch() {
    for target in [Vec3::new(0.0, 0.0, -0.6), Vec3::new(0.0, -0.05, -1.5)] {
        let p = SynthParams {
            targets: vec![FixationTarget::new("still", target)],
            switch_period_s: 0.0,
            duration_s: 60.0,
            blink_every_s: 1.5,
            blink_duration_s: 0.25,
            ..SynthParams::default()
        };
        let trace = synthesize_with_truth(&p).unwrap();
        assert!(trace.blinks.len() >= 39);
        let d = ImageDistances {
            surface_m: 0.6,
            refracted_m: 1.5,
        };
        let report = analyze(&trace.samples, Truth::FromRawDepth, &AnalyzeConfig::new(d));
        for r in &report.filters {
            assert_eq!(r.switches, 0, "{report}");
        }
        // During each blink the image stays what it was: never unknown once decided (250 ms <
        // 300 ms hold), with the default filter and with eq. 15.
        for filter in [FilterKind::default(), FilterKind::PAPER] {
            let frames = replay(
                &trace.samples,
                GazeConfig {
                    filter,
                    ..GazeConfig::new(d)
                },
                None,
            );
            let first = frames
                .iter()
                .position(|(_, s)| s.image != GazeImage::Unknown)
                .unwrap();
            assert!(
                first * 33 <= 200,
                "{filter}: first decision at frame {first}"
            );
            assert!(
                frames[first..]
                    .iter()
                    .all(|(_, s)| s.image != GazeImage::Unknown),
                "{filter}"
            );
        }
    }
}

#[test]
fn override_forces_the_image_and_its_focus_distance() {
    let (trace, d) = alternating(1);
    let config = GazeConfig {
        override_image: GazeOverride::Refracted,
        ..GazeConfig::new(d)
    };
    for (_, s) in replay(&trace.samples[..200], config, None) {
        assert_eq!(s.image, GazeImage::Refracted);
        assert_eq!(s.focus_distance_m, Some(d.refracted_m));
    }
}

fn sranipal(name: &str) -> String {
    format!(
        "{}/../trace/tests/data/sranipal/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn real_sranipal_traces_replay_without_panics() {
    let d = ImageDistances {
        surface_m: 0.6,
        refracted_m: 1.5,
    };
    for name in [
        "TESTNA01_2D_Fist3.csv",
        "TESTNA05_360VR_Spread7.csv",
        "TESTNA10_360VR_Fist3.csv",
        "TESTVA03_2D_Spread9.csv",
    ] {
        let samples = vitreous_trace::sranipal::import_sranipal(sranipal(name)).unwrap();
        let report = analyze(&samples, Truth::FromRawDepth, &AnalyzeConfig::new(d));
        assert_eq!(report.samples, samples.len());
        let text = report.to_string();
        assert!(
            text.contains("mean20") && text.contains("one-euro"),
            "{text}"
        );
        // Every frame's focus distance is that of its image.
        for (_, s) in replay(&samples, GazeConfig::new(d), None) {
            assert_eq!(s.focus_distance_m, d.of(s.image));
        }
    }
}

#[test]
fn plot_writes_a_png_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let (trace, d) = alternating(2);
    let out = dir.path().join("depth.png");
    plot(
        &trace.samples[..600],
        Truth::Phases(&trace.phases),
        &AnalyzeConfig::new(d),
        &out,
    )
    .unwrap();
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (1400, 800));
    assert!(!dir.path().join("depth.png.partial").exists());
    // Not blank: the plot drew in both image colours.
    let rgb = img.to_rgb8();
    let has = |c: [u8; 3]| rgb.pixels().any(|p| p.0 == c);
    assert!(has([31, 119, 180]) && has([230, 120, 20]));
}

/// The real recording's depths reach the far cap and its rays diverge: the lines must still
/// stay inside the depth chart, and the far and diverging samples must be drawn.
#[test]
fn plot_lines_stay_inside_the_chart_and_far_samples_are_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let d = ImageDistances {
        surface_m: 0.6,
        refracted_m: 1.5,
    };
    let samples =
        vitreous_trace::sranipal::import_sranipal(sranipal("TESTNA01_2D_Fist3.csv")).unwrap();
    let out = dir.path().join("real.png");
    let config = AnalyzeConfig::new(d);
    let layout = plot(&samples, Truth::FromRawDepth, &config, &out).unwrap();
    let rgb = image::open(&out).unwrap().to_rgb8();
    let inside = |x: u32, y: u32| {
        layout.chart_x_px.contains(&(x as i32)) && layout.chart_y_px.contains(&(y as i32))
    };
    for (i, c) in FILTER_COLOURS.iter().take(config.filters.len()).enumerate() {
        let colour = [c.0, c.1, c.2];
        let (mut drawn, mut outside) = (0, Vec::new());
        for (x, y, p) in rgb.enumerate_pixels() {
            if p.0 == colour {
                drawn += 1;
                if !inside(x, y) {
                    outside.push((x, y));
                }
            }
        }
        assert!(drawn > 0, "filter {i} drew nothing");
        assert!(
            outside.is_empty(),
            "filter {i}: {} pixels outside {layout:?}, e.g. {:?}",
            outside.len(),
            &outside[..outside.len().min(5)]
        );
    }
    // Diverging samples (red dots below 0 D) and the raw samples are visible.
    let count = |c: [u8; 3]| rgb.pixels().filter(|p| p.0 == c).count();
    assert!(count([200, 60, 60]) > 50, "{}", count([200, 60, 60]));
    assert!(count([150, 150, 150]) > 50);
}

/// With the glass-sphere scene's images (1.48 and 2.03 m, 0.68 and 0.49 D) a real recording's
/// vergence reaches far above 1.6 times the nearer image's: the axis holds nearly all of it, and
/// each sample beyond is marked on the top edge, none left unmarked there.
#[test]
fn plot_holds_or_marks_every_finite_sample() {
    let dir = tempfile::tempdir().unwrap();
    let d = ImageDistances {
        surface_m: 1.48,
        refracted_m: 2.03,
    };
    let samples =
        vitreous_trace::sranipal::import_sranipal(sranipal("TESTNA05_360VR_Spread7.csv")).unwrap();
    let out = dir.path().join("sphere.png");
    let layout = plot(&samples, Truth::FromRawDepth, &AnalyzeConfig::new(d), &out).unwrap();
    let rgb = image::open(&out).unwrap().to_rgb8();
    // The raw samples' grey markers: none pressed against the chart's top edge.
    let top = layout.chart_y_px.start as u32;
    let grey_at_top = (layout.chart_x_px.start as u32..layout.chart_x_px.end as u32)
        .flat_map(|x| (top..top + 3).map(move |y| (x, y)))
        .filter(|&(x, y)| rgb.get_pixel(x, y).0 == [150, 150, 150])
        .count();
    assert_eq!(grey_at_top, 0);
    // The samples beyond are there, as purple triangles on that edge.
    let beyond_at_top = (layout.chart_x_px.start as u32..layout.chart_x_px.end as u32)
        .flat_map(|x| (top..top + 8).map(move |y| (x, y)))
        .filter(|&(x, y)| rgb.get_pixel(x, y).0 == [128, 60, 160])
        .count();
    assert!(beyond_at_top > 20, "{beyond_at_top}");
}
