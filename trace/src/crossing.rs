//! Where two gaze rays cross: the mid-point of the shortest segment between them (the
//! fixation point of vergence), and its depth: the distance from the mid-point of the two
//! origins along the bisector of the two directions. The app's vergence estimator and the
//! simulated headset layer's fixation pose both use it.

use glam::{DVec3, Vec3};

use crate::frame::GazeRay;

/// How two rays relate: where they cross, or why they do not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayCrossing {
    /// The closest approach lies in front of both origins.
    Converge {
        /// Depth from the midpoint of the origins along the bisector of the directions,
        /// metres (may exceed any cap; not clamped).
        depth_m: f32,
        /// The fixation point (midpoint of the shortest segment), head frame, metres.
        point_m: Vec3,
    },
    /// The rays are parallel within numerical precision: fixation at infinity.
    Parallel,
    /// The closest approach lies behind at least one origin.
    Divergent,
}

/// The closest approach of two rays. Directions
/// need not be normalised (they must be non-zero). Computed in f64: near-parallel rays
/// make the f32 form cancel badly.
pub fn closest_approach(a: &GazeRay, b: &GazeRay) -> RayCrossing {
    let (oa, ob) = (a.origin.as_dvec3(), b.origin.as_dvec3());
    let (da, db) = (
        a.direction.as_dvec3().normalize(),
        b.direction.as_dvec3().normalize(),
    );
    let w = oa - ob;
    let cos = da.dot(db);
    let (d, e) = (da.dot(w), db.dot(w));
    let denom = 1.0 - cos * cos;
    // Below ~1e-7 rad of vergence (sin^2 ~ 1e-14) the depth is beyond 10^5 km for any
    // eye baseline: call it parallel rather than divide by round-off.
    if denom < 1e-14 {
        return RayCrossing::Parallel;
    }
    let s = (cos * e - d) / denom;
    let t = (e - cos * d) / denom;
    if s <= 0.0 || t <= 0.0 {
        return RayCrossing::Divergent;
    }
    let point = (oa + da * s + ob + db * t) / 2.0;
    let mid = (oa + ob) / 2.0;
    let forward = (da + db).try_normalize().unwrap_or(DVec3::NEG_Z);
    RayCrossing::Converge {
        depth_m: (point - mid).dot(forward) as f32,
        point_m: point.as_vec3(),
    }
}
