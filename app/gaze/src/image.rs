//! The gaze image: which image of the glass the wearer looks at (METHOD.md section 5), chosen
//! from the filtered fixation depth with hysteresis, and the experimenter's override.
//!
//! # Threshold and hysteresis
//! With the surface image at `d_s` and the refracted image at `d_r` (distances from the head,
//! metres), the decision threshold is their geometric mean `T = sqrt(d_s * d_r)`, the
//! midpoint on a log-depth scale. A selector that shows the nearer image switches to the
//! farther one only when the depth exceeds `T * (d_far / T)^h`, and back only when the depth
//! falls below `T * (d_near / T)^h`, where `h` is [`ImageSelector::band`] (0 = no hysteresis,
//! 1 = the depth must reach the other image's own distance). The band is a fraction of the
//! log gap so it scales with the scene: for 0.6 m / 1.5 m and `h = 0.2` it is +-9.6 % about
//! T = 0.95 m. With no current image (start-up, or after the tracker was lost) the first
//! depth is compared with `T` alone.
//!
//! A decision is taken on a new tracker sample only ([`ImageSelector::update_on`]): the image
//! distances move with the head every frame, and a depth held from an earlier sample (through a
//! blink, while the tracker is out or doubted, on a frame between two samples) measures nothing
//! new about the gaze, so the head's movement alone never switches the image.

use std::fmt;
use std::str::FromStr;

use glam::Vec3;
use thiserror::Error;

use crate::vergence::FixationDepth;

/// Default hysteresis band, as a fraction of the log gap between threshold and image.
pub const DEFAULT_BAND: f32 = 0.2;

/// Which image of the glass the gaze is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GazeImage {
    /// The surface image (the texture on the glass).
    Surface,
    /// The refracted image of the background.
    Refracted,
    /// Not known (no tracker, or tracker lost): no defocus is applied.
    Unknown,
}

impl fmt::Display for GazeImage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GazeImage::Surface => "surface",
            GazeImage::Refracted => "refracted",
            GazeImage::Unknown => "unknown",
        })
    }
}

/// Distances of the two images from the head, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDistances {
    /// Head to the surface image (the glass surface facing the viewer), metres.
    pub surface_m: f32,
    /// Head to the refracted image (the background seen through the glass), metres.
    pub refracted_m: f32,
}

impl ImageDistances {
    /// Distances from a head position to a surface point and a refracted-image point.
    pub fn from_points(head_m: Vec3, surface_point_m: Vec3, refracted_point_m: Vec3) -> Self {
        ImageDistances {
            surface_m: head_m.distance(surface_point_m),
            refracted_m: head_m.distance(refracted_point_m),
        }
    }

    /// The decision threshold: the geometric mean of the two distances, metres.
    pub fn threshold_m(&self) -> f32 {
        (self.surface_m * self.refracted_m).sqrt()
    }

    /// The distance of an image, metres (`None` for [`GazeImage::Unknown`]).
    pub fn of(&self, image: GazeImage) -> Option<f32> {
        match image {
            GazeImage::Surface => Some(self.surface_m),
            GazeImage::Refracted => Some(self.refracted_m),
            GazeImage::Unknown => None,
        }
    }

    /// The image a depth is closer to on a log scale (no hysteresis); surface on a tie.
    pub fn nearest(&self, depth_m: f32) -> GazeImage {
        let t = self.threshold_m();
        let surface_is_near = self.surface_m <= self.refracted_m;
        if (depth_m <= t) == surface_is_near {
            GazeImage::Surface
        } else {
            GazeImage::Refracted
        }
    }
}

/// Chooses the gaze image from filtered depths, with hysteresis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSelector {
    /// The two image distances.
    pub distances: ImageDistances,
    /// Hysteresis band as a fraction of the log gap (module docs), 0..=1.
    pub band: f32,
    /// The current decision.
    current: GazeImage,
    /// Tracker time of the sample the current decision was taken on.
    decided_on_ns: Option<i64>,
}

impl ImageSelector {
    /// A selector with no current image; `band` is clamped to 0..=1.
    pub fn new(distances: ImageDistances, band: f32) -> Self {
        ImageSelector {
            distances,
            band: if band.is_finite() {
                band.clamp(0.0, 1.0)
            } else {
                DEFAULT_BAND
            },
            current: GazeImage::Unknown,
            decided_on_ns: None,
        }
    }

    /// The current decision.
    pub fn current(&self) -> GazeImage {
        self.current
    }

    /// Depths beyond which the selector leaves the surface image and the refracted image,
    /// metres: `(leave_surface_m, leave_refracted_m)`.
    pub fn switch_depths_m(&self) -> (f32, f32) {
        let d = &self.distances;
        let t = d.threshold_m();
        let toward = |target: f32| t * (target / t).powf(self.band);
        (toward(d.refracted_m), toward(d.surface_m))
    }

    /// Updates the decision with this frame's filtered depth, on a sample it has not decided
    /// on yet; a depth held from the sample of the current decision keeps it (module docs).
    pub fn update_on(&mut self, filtered: &FixationDepth) -> GazeImage {
        match *filtered {
            FixationDepth::Unknown => {
                self.decided_on_ns = None;
                self.update(None)
            }
            FixationDepth::Known {
                depth_m,
                sample_time_ns,
            } => {
                if self.decided_on_ns == Some(sample_time_ns) && self.current != GazeImage::Unknown
                {
                    return self.current;
                }
                self.decided_on_ns = Some(sample_time_ns);
                self.update(Some(depth_m))
            }
        }
    }

    /// Updates the decision with this frame's filtered depth (`None`: unknown).
    pub fn update(&mut self, filtered_depth_m: Option<f32>) -> GazeImage {
        let Some(depth_m) = filtered_depth_m.filter(|d| d.is_finite()) else {
            self.current = GazeImage::Unknown;
            return self.current;
        };
        let (leave_surface, leave_refracted) = self.switch_depths_m();
        let surface_is_near = self.distances.surface_m <= self.distances.refracted_m;
        // "Beyond" a switch depth means past it in the direction of the other image.
        let beyond = |depth: f32, limit: f32, toward_far: bool| {
            if toward_far {
                depth > limit
            } else {
                depth < limit
            }
        };
        self.current = match self.current {
            GazeImage::Unknown => self.distances.nearest(depth_m),
            GazeImage::Surface if beyond(depth_m, leave_surface, surface_is_near) => {
                GazeImage::Refracted
            }
            GazeImage::Refracted if beyond(depth_m, leave_refracted, !surface_is_near) => {
                GazeImage::Surface
            }
            same => same,
        };
        self.current
    }

    /// Forgets the current decision.
    pub fn reset(&mut self) {
        self.current = GazeImage::Unknown;
        self.decided_on_ns = None;
    }
}

/// The experimenter's choice of gaze image (the paper's study let the experimenter choose).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub enum GazeOverride {
    /// Follow the eye tracker.
    #[default]
    Auto,
    /// Always the surface image.
    Surface,
    /// Always the refracted image.
    Refracted,
}

impl GazeOverride {
    /// The image shown given the tracker's decision.
    pub fn apply(self, tracked: GazeImage) -> GazeImage {
        match self {
            GazeOverride::Auto => tracked,
            GazeOverride::Surface => GazeImage::Surface,
            GazeOverride::Refracted => GazeImage::Refracted,
        }
    }
}

impl fmt::Display for GazeOverride {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GazeOverride::Auto => "auto",
            GazeOverride::Surface => "surface",
            GazeOverride::Refracted => "refracted",
        })
    }
}

/// A gaze override name that could not be read.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("gaze override `{0}`: expected `auto`, `surface` or `refracted`")]
pub struct GazeOverrideParseError(
    /// The text given.
    pub String,
);

impl FromStr for GazeOverride {
    type Err = GazeOverrideParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(GazeOverride::Auto),
            "surface" => Ok(GazeOverride::Surface),
            "refracted" | "refraction" => Ok(GazeOverride::Refracted),
            _ => Err(GazeOverrideParseError(s.to_owned())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: ImageDistances = ImageDistances {
        surface_m: 0.6,
        refracted_m: 1.5,
    };

    #[test]
    fn hysteresis_holds_inside_the_band() {
        let mut s = ImageSelector::new(D, 0.2);
        let t = D.threshold_m();
        let (up, down) = s.switch_depths_m();
        assert!(down < t && t < up && (up / t - 1.0 - 0.096).abs() < 1e-3);
        assert_eq!(s.update(Some(0.7)), GazeImage::Surface);
        assert_eq!(s.update(Some(t * 1.05)), GazeImage::Surface);
        assert_eq!(s.update(Some(up * 1.01)), GazeImage::Refracted);
        assert_eq!(s.update(Some(t / 1.05)), GazeImage::Refracted);
        assert_eq!(s.update(Some(down * 0.99)), GazeImage::Surface);
        assert_eq!(s.update(None), GazeImage::Unknown);
        assert_eq!(s.update(Some(t * 1.01)), GazeImage::Refracted);
    }

    #[test]
    fn a_held_depth_keeps_the_decision_as_the_head_moves() {
        let known = |depth_m, sample_time_ns| FixationDepth::Known {
            depth_m,
            sample_time_ns,
        };
        let mut s = ImageSelector::new(D, 0.2);
        assert_eq!(s.update_on(&known(0.8, 1)), GazeImage::Surface);
        // The head moves back: the images are farther, 0.8 m is now past where the selector
        // leaves the surface. The same sample decides nothing new...
        s.distances = ImageDistances {
            surface_m: 0.3,
            refracted_m: 0.6,
        };
        assert_eq!(s.update_on(&known(0.8, 1)), GazeImage::Surface);
        // ...a new sample at that depth does.
        assert_eq!(s.update_on(&known(0.8, 2)), GazeImage::Refracted);
        // Unknown forgets; the next known depth decides even on an old sample's time.
        assert_eq!(s.update_on(&FixationDepth::Unknown), GazeImage::Unknown);
        assert_eq!(s.update_on(&known(0.35, 2)), GazeImage::Surface);
    }

    #[test]
    fn works_when_the_surface_is_the_far_image() {
        let d = ImageDistances {
            surface_m: 2.0,
            refracted_m: 0.5,
        };
        let mut s = ImageSelector::new(d, 0.2);
        assert_eq!(s.update(Some(1.8)), GazeImage::Surface);
        assert_eq!(s.update(Some(0.55)), GazeImage::Refracted);
        assert_eq!(s.update(Some(1.9)), GazeImage::Surface);
    }

    #[test]
    fn override_names_parse_and_force_the_image() {
        for o in [
            GazeOverride::Auto,
            GazeOverride::Surface,
            GazeOverride::Refracted,
        ] {
            assert_eq!(o.to_string().parse::<GazeOverride>().unwrap(), o);
        }
        assert!("both".parse::<GazeOverride>().is_err());
        assert_eq!(
            GazeOverride::Refracted.apply(GazeImage::Unknown),
            GazeImage::Refracted
        );
        assert_eq!(
            GazeOverride::Auto.apply(GazeImage::Surface),
            GazeImage::Surface
        );
    }
}
