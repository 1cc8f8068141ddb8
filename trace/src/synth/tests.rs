//! Tests of `synth`.

use super::*;

/// Closest point between two rays (midpoint of the shortest segment); `None` if parallel.
fn closest_approach(a: &GazeRay, b: &GazeRay) -> Option<Vec3> {
    let w = a.origin - b.origin;
    let (d1, d2) = (a.direction, b.direction);
    let (bb, d, e) = (d1.dot(d2), d1.dot(w), d2.dot(w));
    let denom = 1.0 - bb * bb;
    if denom < 1e-12 {
        return None;
    }
    let s = (bb * e - d) / denom;
    let t = (e - bb * d) / denom;
    Some((a.origin + d1 * s + b.origin + d2 * t) / 2.0)
}

fn params() -> SynthParams {
    SynthParams {
        head_position: Vec3::new(0.2, 1.6, 0.5),
        targets: vec![
            FixationTarget::new("near", Vec3::new(0.0, 1.2, -0.3)),
            FixationTarget::new("far", Vec3::new(0.1, 1.1, -1.4)),
        ],
        noise_deg: 0.0,
        ..SynthParams::default()
    }
}

#[test]
fn vergence_of_exact_rays_is_on_the_target() {
    let trace = synthesize_with_truth(&params()).unwrap();
    let mut checked = [0, 0];
    for s in &trace.samples {
        if !s.gaze.left.valid {
            continue;
        }
        let p = closest_approach(&s.gaze.left, &s.gaze.right).unwrap();
        let world = s.head.transform_point(p);
        let phase = trace.phase_at(s.time_ns).unwrap();
        assert!(
            world.distance(phase.point_world) < 1e-3,
            "t={} {world} vs {}",
            s.time_ns,
            phase.point_world
        );
        checked[phase.target] += 1;
        assert!((s.gaze.left.origin.distance(s.gaze.right.origin) - 0.063).abs() < 1e-6);
    }
    assert!(checked[0] > 100 && checked[1] > 50, "{checked:?}");
}

#[test]
fn head_faces_the_first_target_and_sways_a_little() {
    let p = params();
    let trace = synthesize_with_truth(&p).unwrap();
    let mut max_offset: f32 = 0.0;
    for s in &trace.samples {
        let forward = s.head.transform_vector(Vec3::NEG_Z);
        let to_first = (p.targets[0].point_m - s.head.position).normalize();
        assert!(forward.angle_between(to_first).to_degrees() < 1.0);
        max_offset = max_offset.max(s.head.position.distance(p.head_position));
        assert!((s.head.orientation.length() - 1.0).abs() < 1e-5);
    }
    assert!(max_offset > 1e-4 && max_offset < 0.01, "{max_offset}");
}

#[test]
fn phases_alternate_every_switch_period() {
    let trace = synthesize_with_truth(&params()).unwrap();
    let targets: Vec<_> = trace.phases.iter().map(|p| p.target).collect();
    assert_eq!(targets, [0, 1, 0, 1]);
    assert_eq!(trace.phases[1].start_ns, 3_000_000_000);
    assert_eq!(trace.phases[0].end_ns, 3_000_000_000);
    assert_eq!(
        trace.phases[3].end_ns,
        trace.samples.last().unwrap().time_ns + 1
    );
}

#[test]
fn blinks_make_both_eyes_invalid() {
    let trace = synthesize_with_truth(&params()).unwrap();
    assert_eq!(trace.blinks.len(), 2);
    let mut blinked = 0;
    for s in &trace.samples {
        let in_blink = trace
            .blinks
            .iter()
            .any(|b| b.start_ns <= s.time_ns && s.time_ns < b.end_ns);
        assert_eq!(!s.gaze.left.valid, in_blink);
        assert_eq!(!s.gaze.right.valid, in_blink);
        blinked += in_blink as usize;
    }
    // 150 ms at 30 Hz: 4 or 5 samples per blink.
    assert!((8..=10).contains(&blinked), "{blinked}");
}

#[test]
fn same_seed_same_trace_other_seed_other_trace() {
    let p = SynthParams {
        noise_deg: 1.0,
        ..params()
    };
    assert_eq!(synthesize(&p), synthesize(&p));
    let other = SynthParams {
        seed: 2,
        ..p.clone()
    };
    assert_ne!(synthesize(&p), synthesize(&other));
}

#[test]
fn noise_has_about_the_requested_spread() {
    let noisy = SynthParams {
        noise_deg: 1.0,
        blink_every_s: 0.0,
        duration_s: 60.0,
        ..params()
    };
    let exact = SynthParams {
        noise_deg: 0.0,
        ..noisy.clone()
    };
    let (a, b) = (synthesize(&noisy), synthesize(&exact));
    let sq: f32 = a
        .iter()
        .zip(&b)
        .map(|(a, b)| {
            a.gaze
                .left
                .direction
                .angle_between(b.gaze.left.direction)
                .to_degrees()
                .powi(2)
        })
        .sum();
    // Two independent axes of 1 degree each: mean squared angle about 2.
    let mean_sq = sq / a.len() as f32;
    assert!((1.6..2.4).contains(&mean_sq), "{mean_sq}");
}

#[test]
fn three_targets_are_visited_in_list_order_and_over_again() {
    let mut p = params();
    p.targets
        .push(FixationTarget::new("left", Vec3::new(-0.4, 1.2, -0.8)));
    p.duration_s = 12.0;
    let trace = synthesize_with_truth(&p).unwrap();
    let targets: Vec<_> = trace.phases.iter().map(|ph| ph.target).collect();
    assert_eq!(targets, [0, 1, 2, 0, 1]);
    assert_eq!(trace.phases[2].point_world, p.targets[2].point_m);
    let still = SynthParams {
        switch_period_s: 0.0,
        ..p
    };
    let phases = synthesize_with_truth(&still).unwrap().phases;
    assert_eq!(phases.len(), 1);
    assert_eq!(phases[0].target, 0);
}

#[test]
fn times_strictly_increase_and_trace_round_trips() {
    let samples = synthesize(&SynthParams {
        rate_hz: 90.0,
        ..SynthParams::default()
    });
    assert_eq!(samples.len(), 901);
    assert!(samples.windows(2).all(|w| w[0].time_ns < w[1].time_ns));
    let mut w = crate::format::TraceWriter::new(Vec::new()).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    let text = w.finish().unwrap();
    let back: Vec<TraceSample> = crate::format::TraceReader::new(&text[..], "synth")
        .unwrap()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(back, samples);
}

#[test]
fn bad_params_are_reported_not_panicked_on() {
    let bad = [
        SynthParams {
            rate_hz: 0.0,
            ..params()
        },
        SynthParams {
            duration_s: f32::NAN,
            ..params()
        },
        SynthParams {
            targets: vec![FixationTarget::new("at the head", params().head_position)],
            ..params()
        },
        SynthParams {
            targets: Vec::new(),
            ..params()
        },
        SynthParams {
            duration_s: 1e12,
            ..params()
        },
    ];
    for p in bad {
        assert!(synthesize_with_truth(&p).is_err());
        assert!(synthesize(&p).is_empty());
    }
    let zero = synthesize(&SynthParams {
        duration_s: 0.0,
        ..params()
    });
    assert_eq!(zero.len(), 1);
}
