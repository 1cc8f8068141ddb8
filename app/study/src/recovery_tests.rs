//! Property tests of the whole analysis path: a simulated participant answers from known scale
//! values ([`SimulatedObserver`], as `vitreous study run --simulate` does), the answers go
//! through a responses file, and the analysis recovers the scale values.

use std::fmt::Write;
use std::path::Path;

use proptest::prelude::*;

use super::answers::{SimulatedObserver, answer_text};
use super::report::{Analysis, analyze};
use super::responses::{ResponseKind, Responses};

/// Responses of `participants` simulated participants (each rating or judging every ordered
/// pair `repeats` times), parsed as a file.
fn simulate(
    kind: ResponseKind,
    truth: &[f64],
    participants: usize,
    repeats: usize,
    seed: u64,
) -> Responses {
    let names: Vec<String> = (0..truth.len()).map(|i| format!("c{i}")).collect();
    let scale: Vec<String> = names
        .iter()
        .zip(truth)
        .map(|(n, v)| format!("{n}={v}"))
        .collect();
    let mut observer = SimulatedObserver::parse(&scale.join(","), &names, seed).unwrap();
    let mut csv = String::from("participant,trial,first,second,response\n");
    for p in 0..participants {
        let mut trial = 0;
        for _ in 0..repeats {
            for a in &names {
                for b in names.iter().filter(|b| *b != a) {
                    trial += 1;
                    let answer = answer_text(observer.judge(kind, a, b));
                    writeln!(csv, "p{p},{trial},{a},{b},{answer}").unwrap();
                }
            }
        }
    }
    Responses::parse(Path::new("simulated.csv"), csv.as_bytes()).unwrap()
}

/// The largest error of the recovered differences between conditions.
fn worst_difference_error(scale: &[f64], truth: &[f64]) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..truth.len() {
        for j in 0..truth.len() {
            let error = (scale[i] - scale[j]) - (truth[i] - truth[j]);
            worst = worst.max(error.abs());
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn case_v_recovers_the_scale_of_simulated_choices(
        truth in prop::collection::vec(0.0f64..1.4, 3..=5),
        seed in any::<u64>(),
    ) {
        // 1000 judgments of each pair (500 in each order): the deviates' standard error is
        // about 0.04, so 0.15 is beyond chance.
        let responses = simulate(ResponseKind::ForcedChoice, &truth, 50, 10, seed);
        let Analysis::CaseV(r) = analyze(&responses) else { panic!("forced choices") };
        let error = worst_difference_error(&r.scale, &truth);
        prop_assert!(error < 0.15, "scale {:?} truth {:?} error {}", r.scale, truth, error);
        // Case V holds for these answers: Mosteller's test rarely rejects it.
        if let Some(p) = r.test.p {
            prop_assert!(p > 1e-4, "p {}", p);
        }
    }
}

proptest! {
    // Fewer cases: each analysis computes two studentized-range quantiles by quadrature.
    #![proptest_config(ProptestConfig { cases: 5, ..ProptestConfig::default() })]

    #[test]
    fn scheffe_recovers_the_scale_of_simulated_ratings(
        truth in prop::collection::vec(-0.7f64..0.7, 3..=5),
        seed in any::<u64>(),
    ) {
        // 150 participants: the standard error of a difference of scale values is about 0.05.
        let responses = simulate(ResponseKind::Rating, &truth, 150, 1, seed);
        let Analysis::Scheffe(r) = analyze(&responses) else { panic!("ratings") };
        let error = worst_difference_error(&r.scale, &truth);
        prop_assert!(error < 0.2, "scale {:?} truth {:?} error {}", r.scale, truth, error);
        // The sums of squares add up to the total.
        let parts: f64 = r.anova[..5].iter().map(|row| row.sum_of_squares).sum();
        let total = r.anova[5].sum_of_squares;
        prop_assert!((parts - total).abs() < 1e-6 * total.max(1.0));
    }
}
