//! Gaze: from eye-tracker samples to the gaze image and the focus distance, and the defocus
//! that follows from them (METHOD.md sections 4 and 5, paper eq. 9-15).
//!
//! Per frame, [`GazePipeline::update`] runs:
//! 1. [`vergence`]: the fixation depth of the newest tracker sample (closest approach of the
//!    two gaze rays), held through blinks for a bounded time;
//! 2. [`filter`]: eq. 15's 20-sample moving average (or another depth filter) over tracker
//!    samples, each ingested once however many frames see it;
//! 3. [`image`]: the gaze image (surface or refracted) with hysteresis, or the experimenter's
//!    override; the focus distance d_f is that image's distance.
//!
//! With the `evidence` filter (the default), stages 2 and 3 are [`evidence`] instead: each
//! sample adds evidence for one image, weighed by the tracker's noise, and the image changes
//! when the evidence for the other one has piled up; with `fixation` they are [`fixation`]:
//! the image is decided per classified fixation. Whatever decides, [`separability`] estimates
//! the tracker's vergence noise and how far apart the two images are in it (`d'`).
//!
//! [`blur`] then turns d_f into the blur of the image not looked at (eq. 10-14).
//! [`analysis`] replays a whole trace through the pipeline per filter and scores how fast and
//! how steadily each decision follows the gaze (`vitreous trace analyze`).
//! `docs/gaze.md` maps each equation to its function.

pub mod analysis;
pub mod blur;
pub mod evidence;
pub mod filter;
pub mod fixation;
pub mod image;
pub mod pupil;
pub mod separability;
#[cfg(test)]
mod test_samples;
pub mod vergence;

pub use blur::{DefocusError, GaussianKernel, ImageBlur, blur_reference, image_blur};
pub use evidence::{EvidenceFilter, EvidenceParams, ObjectInView, Withheld};
pub use filter::{DepthFilter, FilterKind, FilterParseError, OneEuroParams, SampleFilter};
pub use fixation::{FixationFilter, FixationParams, SampleClass};
pub use image::{GazeImage, GazeOverride, ImageDistances, ImageSelector};
pub use pupil::{PupilEstimate, PupilFilter, PupilSource, PupilSourceParseError};
pub use separability::{Separability, SeparabilityMonitor};
pub use vergence::{FixationDepth, VergenceConfig, VergenceEstimator};

use vitreous_trace::GazeSample;

/// Everything the gaze pipeline needs to know.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeConfig {
    /// Vergence estimation (depth caps, blink hold time).
    pub vergence: VergenceConfig,
    /// Which depth filter runs.
    pub filter: FilterKind,
    /// Distances of the surface and refracted images from the head, metres.
    pub distances: ImageDistances,
    /// Hysteresis band of the gaze-image decision, fraction of the log gap (see [`image`]).
    pub band: f32,
    /// The experimenter's override.
    pub override_image: GazeOverride,
}

impl GazeConfig {
    /// Defaults (`fixation` filter, 10 m cap, 300 ms hold, band 0.2, auto) for given
    /// distances.
    pub fn new(distances: ImageDistances) -> Self {
        GazeConfig {
            vergence: VergenceConfig::default(),
            filter: FilterKind::default(),
            distances,
            band: image::DEFAULT_BAND,
            override_image: GazeOverride::Auto,
        }
    }
}

/// The gaze pipeline's output for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeState {
    /// Fixation depth of the newest tracker sample (held through blinks), unfiltered.
    pub raw_depth: FixationDepth,
    /// The filtered depth (sample time = newest sample ingested).
    pub filtered_depth: FixationDepth,
    /// The gaze image after the override.
    pub image: GazeImage,
    /// d_f: the distance of the gaze image from the head, metres; `None` while unknown (no
    /// defocus then).
    pub focus_distance_m: Option<f32>,
    /// How far apart the two images are in the tracker's vergence noise, at the newest sample
    /// with a depth; `None` before the first.
    pub separability: Option<Separability>,
}

/// Vergence, filter and gaze-image selection, run once per frame.
#[derive(Debug)]
pub struct GazePipeline {
    /// Settings it was built with.
    config: GazeConfig,
    /// Stage 1.
    vergence: VergenceEstimator,
    /// Stages 2 and 3.
    decision: Decision,
    /// The separability, for the decisions that do not estimate it themselves, with the time
    /// of the last sample it saw.
    monitor: Option<(SeparabilityMonitor, Option<i64>)>,
}

/// How the gaze image is decided from the fixation depths.
#[derive(Debug)]
enum Decision {
    /// A depth filter, then the image with hysteresis.
    Depth {
        /// Stage 2.
        filter: SampleFilter,
        /// Stage 3.
        selector: ImageSelector,
    },
    /// Per fixation ([`fixation`]).
    Fixation(FixationFilter),
    /// By accumulated evidence ([`evidence`]).
    Evidence(EvidenceFilter),
}

impl GazePipeline {
    /// A pipeline with no history.
    pub fn new(config: GazeConfig) -> Self {
        GazePipeline {
            config,
            vergence: VergenceEstimator::new(config.vergence),
            decision: match config.filter {
                FilterKind::Fixation(params) => {
                    Decision::Fixation(FixationFilter::new(params, config.distances, config.band))
                }
                FilterKind::Evidence(params) => {
                    Decision::Evidence(EvidenceFilter::new(params, config.distances))
                }
                kind => Decision::Depth {
                    filter: SampleFilter::new(kind),
                    selector: ImageSelector::new(config.distances, config.band),
                },
            },
            monitor: match config.filter {
                FilterKind::Evidence(_) => None,
                _ => Some((
                    SeparabilityMonitor::new(
                        fixation::DEFAULT_VELOCITY_DEG_S,
                        evidence::DEFAULT_PRIOR_NOISE_DEG,
                    ),
                    None,
                )),
            },
        }
    }

    /// The settings.
    pub fn config(&self) -> &GazeConfig {
        &self.config
    }

    /// Changes the override (e.g. a live experimenter action); the tracking state is kept.
    pub fn set_override(&mut self, override_image: GazeOverride) {
        self.config.override_image = override_image;
    }

    /// Moves the two images to new distances (the viewer moved): the next update decides with
    /// the switch depths of these distances, and d_f is the gaze image's new distance. The
    /// current decision and the filters' history are kept.
    pub fn set_distances(&mut self, distances: ImageDistances) {
        self.config.distances = distances;
        match &mut self.decision {
            Decision::Depth { selector, .. } => selector.distances = distances,
            Decision::Fixation(f) => f.set_distances(distances),
            Decision::Evidence(f) => f.set_distances(distances),
        }
    }

    /// Where the glass object is in the head frame this frame (`None`: unknown). Only the
    /// `evidence` decision uses it: a gaze that misses the object gives no evidence.
    pub fn set_object(&mut self, object: Option<ObjectInView>) {
        if let Decision::Evidence(f) = &mut self.decision {
            f.set_object(object);
        }
    }

    /// Runs one frame: `gaze` is the newest tracker sample at or before the frame (as in
    /// `FrameInput::gaze`), `head_time_ns` the frame's time (used for the blink-hold timeout
    /// only when there is no sample).
    pub fn update(&mut self, gaze: Option<&GazeSample>, head_time_ns: i64) -> GazeState {
        // A depth filter averages whatever it is given: a sample the tracker itself reports
        // with LOW confidence is no measurement for it (the depth is held, as through a blink);
        // the per-fixation and evidence decisions read the report themselves.
        let doubted = gaze.is_some_and(|g| {
            g.report
                .is_some_and(|r| r.confidence == vitreous_trace::TrackerConfidence::Low)
        });
        let measured = match self.decision {
            Decision::Depth { .. } if doubted => None,
            _ => gaze,
        };
        let raw_depth = self.vergence.update(measured, head_time_ns);
        let (filtered_depth, tracked) = match &mut self.decision {
            Decision::Depth { filter, selector } => {
                let filtered = filter.feed(&raw_depth);
                (filtered, selector.update_on(&filtered))
            }
            Decision::Fixation(f) => f.update(gaze, &raw_depth, self.vergence.measurement()),
            Decision::Evidence(f) => f.update(gaze, &raw_depth, self.vergence.measurement()),
        };
        let separability = match (&mut self.monitor, &self.decision) {
            (Some((monitor, last)), _) => {
                if raw_depth == FixationDepth::Unknown {
                    monitor.reset();
                    *last = None;
                } else if let Some(g) = vergence::newer_sample(gaze, last) {
                    let depth = self
                        .vergence
                        .measurement()
                        .filter(|m| m.sample_time_ns == g.sample_time_ns)
                        .map(|m| m.depth_m);
                    monitor.push(g, depth, &self.config.distances);
                }
                monitor.separability()
            }
            (None, Decision::Evidence(f)) => f.separability(),
            (None, _) => None,
        };
        let image = self.config.override_image.apply(tracked);
        GazeState {
            raw_depth,
            filtered_depth,
            image,
            focus_distance_m: self.config.distances.of(image),
            separability,
        }
    }
}

#[cfg(test)]
mod tests {
    use vitreous_trace::{GazeBehaviour, TrackerConfidence, TrackerReport};

    use super::*;
    use crate::test_samples::looking;

    #[test]
    fn a_depth_filter_takes_no_sample_the_tracker_doubts() {
        let mut config = GazeConfig::new(ImageDistances {
            surface_m: 0.6,
            refracted_m: 1.5,
        });
        config.filter = FilterKind::PAPER;
        let mut p = GazePipeline::new(config);
        let ms = 1_000_000;
        for k in 0..30 {
            p.update(Some(&looking(k * 33 * ms, 0.6, 0.0)), k * 33 * ms);
        }
        // The eyes turn to the refracted image, but the tracker says LOW: no measurement, the
        // depth held through the 300 ms hold, then none; never the doubted 1.5 m.
        let doubted = TrackerReport {
            confidence: TrackerConfidence::Low,
            behaviour: GazeBehaviour::Fixation,
        };
        for k in 30..60 {
            let mut s = looking(k * 33 * ms, 1.5, 0.0);
            s.report = Some(doubted);
            let state = p.update(Some(&s), k * 33 * ms);
            assert_ne!(state.image, GazeImage::Refracted, "sample {k}");
            if let Some(d) = state.filtered_depth.depth_m() {
                assert!((d - 0.6).abs() < 0.01, "sample {k}: {d} m");
            }
        }
        // HIGH again: the same samples decide.
        let mut last = GazeImage::Unknown;
        for k in 60..100 {
            last = p
                .update(Some(&looking(k * 33 * ms, 1.5, 0.0)), k * 33 * ms)
                .image;
        }
        assert_eq!(last, GazeImage::Refracted);
    }

    #[test]
    fn a_depth_held_through_a_dropout_keeps_the_image_while_the_head_moves() {
        // A glass close by (its surface image 0.125 m away, the refracted 0.30 m: the switch from
        // the surface at 0.211 m). The gaze on the surface, then at 0.20 m, inside the band: the
        // surface stays. Then the tracker is out (LOW, as a doubted tracker or the simulated
        // headset's `low` dropout) while the wearer leans in 5 mm a frame: after 2 cm the held
        // 0.20 m lies past the switch, but nothing new is measured, so the image stays.
        let near = ImageDistances {
            surface_m: 0.125,
            refracted_m: 0.30,
        };
        let mut config = GazeConfig::new(near);
        config.filter = FilterKind::PAPER;
        let mut p = GazePipeline::new(config);
        let ms = 1_000_000;
        for k in 0..60 {
            let depth = if k < 30 { 0.13 } else { 0.20 };
            let state = p.update(Some(&looking(k * 33 * ms, depth, 0.0)), k * 33 * ms);
            assert_eq!(state.image, GazeImage::Surface, "sample {k}");
        }
        let doubted = TrackerReport {
            confidence: TrackerConfidence::Low,
            behaviour: GazeBehaviour::Fixation,
        };
        let mut crossed = false;
        for k in 60..69 {
            let closer = (k - 59) as f32 * 0.005;
            let now = ImageDistances {
                surface_m: near.surface_m - closer,
                refracted_m: near.refracted_m - closer,
            };
            p.set_distances(now);
            let mut s = looking(k * 33 * ms, 0.20, 0.0);
            s.report = Some(doubted);
            let state = p.update(Some(&s), k * 33 * ms);
            let leave_surface_m = ImageSelector::new(now, image::DEFAULT_BAND)
                .switch_depths_m()
                .0;
            crossed |= state
                .filtered_depth
                .depth_m()
                .is_some_and(|d| d > leave_surface_m);
            assert_eq!(
                state.image,
                GazeImage::Surface,
                "frame {k}, {closer} m closer"
            );
        }
        assert!(
            crossed,
            "the held depth never lay past the switch: the test tests nothing"
        );
    }
}
