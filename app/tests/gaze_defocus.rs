//! Defocus maths (eq. 10-14) through the public API.

use proptest::prelude::*;
use vitreous_gaze::blur::{
    DefocusError, blur_circle_diameter_m, blur_reference, check_pupil_diameter_m, gaussian_kernel,
    gaussian_variance_px2, kernel_radius_px, kernel_width_px, px_per_m,
};

proptest! {
    #[test]
    fn kernel_weights_sum_to_one(k_g in 0.0f32..80.0) {
        let g = gaussian_kernel(k_g);
        let s2: f64 = g.weights_2d.iter().map(|&w| f64::from(w)).sum();
        let s1: f64 = g.weights_1d.iter().map(|&w| f64::from(w)).sum();
        prop_assert!((s2 - 1.0).abs() < 1e-5, "{}", s2);
        prop_assert!((s1 - 1.0).abs() < 1e-5, "{}", s1);
        prop_assert_eq!(g.radius_px, (k_g / 2.0).floor() as usize);
        prop_assert_eq!(g.variance_px2, k_g / 2.0);
    }
}

#[test]
fn eq14_against_hand_computed_values() {
    // A_p = 4 mm, focus at 0.5 m, image at 2 m: 4 mm * 1.5 / 0.5 = 12 mm.
    assert!((blur_circle_diameter_m(0.004, 2.0, 0.5) - 0.012).abs() < 1e-7);
    // Focus at 2 m, image at 0.5 m: 4 mm * 1.5 / 2 = 3 mm.
    assert!((blur_circle_diameter_m(0.004, 0.5, 2.0) - 0.003).abs() < 1e-7);
    // The paper's layout (6 mm; surface 0.125 m, background 0.4 m).
    assert!((blur_circle_diameter_m(0.006, 0.4, 0.125) - 0.0132).abs() < 1e-7);
    // eq. 13 on a 1024 px photo 0.5 m wide: 2048 px/m * 3 mm = 6.144 px; eq. 11 and 12.
    let k = kernel_width_px(px_per_m(1024.0, 0.5), 0.003);
    assert!((k - 6.144).abs() < 1e-4);
    assert!((gaussian_variance_px2(k) - 3.072).abs() < 1e-4);
    assert_eq!(kernel_radius_px(k), 3);
}

#[test]
fn pupil_out_of_range_is_refused_with_a_clear_message() {
    for ok in [0.001, 0.002, 0.006, 0.008, 0.009] {
        assert_eq!(check_pupil_diameter_m(ok), Ok(ok));
    }
    for bad in [0.0005, 0.0099, 0.012, 0.0, -0.003, f32::INFINITY, f32::NAN] {
        let err = check_pupil_diameter_m(bad).unwrap_err();
        assert!(matches!(err, DefocusError::PupilOutOfRange { .. }));
        let msg = err.to_string();
        assert!(
            msg.contains("pupil diameter") && msg.contains("1..=9 mm"),
            "{msg}"
        );
    }
}

#[test]
fn reference_blur_conserves_energy_and_smooths() {
    let (w, h) = (24, 16);
    let image: Vec<f32> = (0..w * h)
        .map(|i| {
            if (i % w / 3 + i / w / 3) % 2 == 0 {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    let blurred = blur_reference(&image, w, h, 8.0);
    let variance = |v: &[f32]| {
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        v.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / v.len() as f32
    };
    assert!(variance(&blurred) < 0.5 * variance(&image));
    assert!(blurred.iter().all(|&v| (-1e-6..=1.0 + 1e-6).contains(&v)));
}
