//! Moving an imported trace's head-frame origin from the tracker's scene camera to the middle
//! of the eyes, where the trace format puts the head position.

use glam::Vec3;

use crate::format::TraceSample;

/// Moves the head-frame origin of `samples` to the middle of the eyes: the per-axis median,
/// over the samples with both eyes valid, of the midpoint of the two eye origins. Ray
/// origins (eyes and combined) and fixation points are shifted by it; directions and head
/// orientations do not change. Returns the new origin in the old frame, or `None` (nothing
/// changed) when no sample has both eyes valid.
pub(crate) fn centre_on_eyes(samples: &mut [TraceSample]) -> Option<Vec3> {
    let mids: Vec<Vec3> = samples
        .iter()
        .filter(|s| s.gaze.left.valid && s.gaze.right.valid)
        .map(|s| (s.gaze.left.origin + s.gaze.right.origin) / 2.0)
        .collect();
    if mids.is_empty() {
        return None;
    }
    let median = |axis: usize| {
        let mut v: Vec<f32> = mids.iter().map(|m| m[axis]).collect();
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let centre = Vec3::new(median(0), median(1), median(2));
    for s in samples.iter_mut() {
        let g = &mut s.gaze;
        for ray in [&mut g.left, &mut g.right]
            .into_iter()
            .chain(g.combined.as_mut())
        {
            if ray.valid {
                ray.origin -= centre;
            }
        }
        if let Some(p) = g.fixation.as_mut() {
            *p -= centre;
        }
    }
    Some(centre)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{GazeRay, GazeSample, Pose};

    fn sample(left: Vec3, right: Vec3, valid: bool) -> TraceSample {
        let ray = |origin| GazeRay {
            origin,
            direction: Vec3::NEG_Z,
            valid,
        };
        TraceSample {
            time_ns: 0,
            head: Pose::IDENTITY,
            gaze: GazeSample {
                sample_time_ns: 0,
                left: ray(left),
                right: ray(right),
                combined: Some(ray(Vec3::ZERO)),
                fixation: Some(Vec3::new(0.0, 0.0, -1.0)),
                pupil_diameter_m: [None, None],
                report: None,
            },
        }
    }

    #[test]
    fn origin_moves_to_the_median_eye_midpoint() {
        let (l, r) = (Vec3::new(-0.03, -0.01, 0.03), Vec3::new(0.033, -0.01, 0.03));
        let mut samples = vec![
            sample(l, r, true),
            sample(l, r, true),
            // An outlier does not move the median.
            sample(l + Vec3::X, r + Vec3::X, true),
            sample(Vec3::ONE, Vec3::ONE, false),
        ];
        let centre = centre_on_eyes(&mut samples).unwrap();
        assert!(
            centre.abs_diff_eq(Vec3::new(0.0015, -0.01, 0.03), 1e-7),
            "{centre}"
        );
        let g = samples[0].gaze;
        assert!((g.left.origin + g.right.origin).abs_diff_eq(Vec3::ZERO, 1e-7));
        assert!(g.combined.unwrap().origin.abs_diff_eq(-centre, 1e-7));
        assert!(
            g.fixation
                .unwrap()
                .abs_diff_eq(Vec3::new(-0.0015, 0.01, -1.03), 1e-6)
        );
        // Invalid rays keep their (unread) origin.
        assert_eq!(samples[3].gaze.left.origin, Vec3::ONE);
        let mut none = vec![sample(l, r, false)];
        assert_eq!(centre_on_eyes(&mut none), None);
        assert_eq!(none[0].gaze.left.origin, l);
    }
}
