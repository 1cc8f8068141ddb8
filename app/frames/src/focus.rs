//! The distance a headset's focus (reprojection) plane follows: the wearer's filtered fixation
//! depth, for `XrFrameEndInfoML::focusDistance` on Magic Leap 2. The gaze pipeline's vergence and
//! depth filter run on every frame's gaze, whatever the frame's look: the scene's `[gaze] filter`
//! when it is a depth filter (a moving mean or median, the one-euro filter), else eq. 15's
//! 20-sample mean (the per-fixation and evidence decisions choose an image, not a depth).

use vitreous_gaze::{FilterKind, GazeConfig, GazePipeline};
use vitreous_scene::Scene;
use vitreous_trace::FrameInput;

/// Follows the wearer's filtered fixation depth frame by frame.
#[derive(Debug)]
pub struct FocusFollower {
    /// Vergence and the depth filter (its gaze-image decision is not used).
    pipeline: GazePipeline,
    /// The newest known depth, metres: held while the tracker has none.
    last_m: Option<f32>,
}

impl FocusFollower {
    /// A follower for `scene`'s viewer, filtering with `filter` (the scene's when `None`).
    pub fn new(scene: &Scene, filter: Option<FilterKind>) -> FocusFollower {
        let mut config = GazeConfig::new(scene.image_distances());
        config.filter = match filter.unwrap_or(scene.gaze.filter) {
            f @ (FilterKind::Mean { .. } | FilterKind::Median { .. } | FilterKind::OneEuro(_)) => f,
            FilterKind::Fixation(_) | FilterKind::Evidence(_) => FilterKind::PAPER,
        };
        FocusFollower {
            pipeline: GazePipeline::new(config),
            last_m: None,
        }
    }

    /// The filtered fixation depth after frame `input`'s gaze, metres; `None` until the
    /// tracker has given one.
    pub fn update(&mut self, input: &FrameInput) -> Option<f32> {
        let state = self.pipeline.update(input.gaze.as_ref(), input.time_ns);
        if let Some(depth) = state.filtered_depth.depth_m() {
            self.last_m = Some(depth);
        }
        self.last_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_frame::frame_fixating;

    #[test]
    fn the_focus_settles_on_the_fixated_depth_after_the_filter_window() {
        let scene = vitreous_scene::load_scene(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../config/scenes/glass-sphere-real.toml"),
        )
        .unwrap();
        let mut focus = FocusFollower::new(&scene, None);
        // Nothing before the tracker says anything.
        let mut last = None;
        for (i, depth) in [0.8f32; 30].into_iter().chain([1.6; 30]).enumerate() {
            last = focus.update(&frame_fixating(i as u64, depth));
            if i == 29 {
                let d = last.unwrap();
                assert!((d - 0.8).abs() < 0.008, "{d}");
            }
        }
        let d = last.unwrap();
        assert!((d - 1.6).abs() < 0.016, "{d}");
    }
}
