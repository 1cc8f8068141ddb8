//! Where a viewer of a scene looks: the point on the object's surface facing the viewer (the
//! surface image) and the point of the background plane seen through the object's centre
//! (where the refracted image lies). The gaze pipeline's image distances and the synthetic
//! traces of a scene both come from these points, so the two always agree.
//!
//! The synthetic-trace generator knows only a list of fixation targets; this module fixes
//! their meaning: target [`SURFACE_TARGET`] is the surface point, [`REFRACTED_TARGET`] the
//! refracted one ([`gaze_image_of_target`]).

use glam::Vec3;
use vitreous_xr::synth::{FixationTarget, SynthParams};

use super::Scene;
use crate::gaze::{GazeImage, ImageDistances};

/// Index of the surface point among the targets of [`synth_params_for`] (fixated first).
pub const SURFACE_TARGET: usize = 0;

/// Index of the refracted-image point among the targets of [`synth_params_for`].
pub const REFRACTED_TARGET: usize = 1;

/// Distance behind the object's centre where the refracted image is assumed to lie when the
/// scene's background plane is not in line with the object, metres.
const FALLBACK_REFRACTED_DEPTH_M: f32 = 0.2;

/// The viewer's head and the two points it fixates, world frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixationPoints {
    /// The viewer's head position (between the eyes), metres.
    pub head_m: Vec3,
    /// The front of the object's surface as seen from the head, metres.
    pub surface_m: Vec3,
    /// The point of the background plane seen through the object's centre, metres; 0.2 m
    /// behind the centre when the plane is not behind the object along that line.
    pub refracted_m: Vec3,
}

/// What the fixation points depend on besides where the viewer is: the object's centre and
/// radius and the background plane, in the scene (world) frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewingGeometry {
    /// Centre of the object, metres.
    pub center_m: Vec3,
    /// Radius of the object's bounding sphere, metres.
    pub radius_m: f32,
    /// A point of the background plane (its centre), metres.
    pub plane_point_m: Vec3,
    /// Unit normal of the background plane.
    pub plane_normal: Vec3,
}

impl ViewingGeometry {
    /// The points a viewer at `head_m` fixates: the surface point facing the viewer on the line
    /// to the object's centre, and the background point on that line behind the object (0.2 m
    /// behind the centre when the plane is not behind the object along it).
    pub fn points_from(&self, head_m: Vec3) -> FixationPoints {
        let center = self.center_m;
        let to_object = (center - head_m).normalize_or(Vec3::NEG_Z);
        let surface_m = center - to_object * self.radius_m;
        let normal = self.plane_normal;
        let denom = to_object.dot(normal);
        let behind = center + to_object * FALLBACK_REFRACTED_DEPTH_M;
        let refracted_m = if denom.abs() > 1e-3 {
            let t = (self.plane_point_m - head_m).dot(normal) / denom;
            if t > (center - head_m).length() {
                head_m + to_object * t
            } else {
                behind
            }
        } else {
            behind
        };
        FixationPoints {
            head_m,
            surface_m,
            refracted_m,
        }
    }

    /// The distances of the surface and refracted images from a viewer at `head_m`, to the
    /// points of [`ViewingGeometry::points_from`]. Eq. 13-14 take these every frame with the
    /// frame's viewing position.
    pub fn distances_from(&self, head_m: Vec3) -> ImageDistances {
        let p = self.points_from(head_m);
        ImageDistances::from_points(p.head_m, p.surface_m, p.refracted_m)
    }
}

impl Scene {
    /// The object and background plane the fixation points are found on.
    pub fn viewing_geometry(&self) -> ViewingGeometry {
        ViewingGeometry {
            center_m: self.object.center_m,
            radius_m: self.object.radius_m,
            plane_point_m: self.background.pose.position,
            plane_normal: self.background.normal(),
        }
    }

    /// The points a viewer at the scene's head position fixates.
    pub fn fixation_points(&self) -> FixationPoints {
        self.viewing_geometry()
            .points_from(self.viewer.head_position_m)
    }

    /// The distances of the surface and refracted images from the viewer's head, to the
    /// points of [`Scene::fixation_points`].
    pub fn image_distances(&self) -> ImageDistances {
        self.viewing_geometry()
            .distances_from(self.viewer.head_position_m)
    }
}

/// Synthetic-trace parameters for a scene: the head at the viewer's position looking at the
/// object; the gaze alternates between the points of [`Scene::fixation_points`], surface first
/// ([`SURFACE_TARGET`], [`REFRACTED_TARGET`]).
pub fn synth_params_for(scene: &Scene) -> SynthParams {
    let p = scene.fixation_points();
    SynthParams {
        head_position: p.head_m,
        // In index order: SURFACE_TARGET, REFRACTED_TARGET.
        targets: vec![
            FixationTarget::new("surface", p.surface_m),
            FixationTarget::new("refracted", p.refracted_m),
        ],
        ipd_m: scene.viewer.ipd_m,
        ..SynthParams::default()
    }
}

/// The gaze image a fixation target of [`synth_params_for`] stands for; `Unknown` for an
/// index that is neither.
pub fn gaze_image_of_target(target: usize) -> GazeImage {
    match target {
        SURFACE_TARGET => GazeImage::Surface,
        REFRACTED_TARGET => GazeImage::Refracted,
        _ => GazeImage::Unknown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_targets_are_the_fixation_points_in_gaze_image_order() {
        let scene = crate::scene::load_scene(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../config/scenes/visual-effects.toml"),
        )
        .expect("shipped scene");
        let p = scene.fixation_points();
        let synth = synth_params_for(&scene);
        assert_eq!(synth.head_position, p.head_m);
        assert_eq!(synth.targets[SURFACE_TARGET].point_m, p.surface_m);
        assert_eq!(synth.targets[REFRACTED_TARGET].point_m, p.refracted_m);
        assert_eq!(gaze_image_of_target(SURFACE_TARGET), GazeImage::Surface);
        assert_eq!(gaze_image_of_target(REFRACTED_TARGET), GazeImage::Refracted);
        assert_eq!(gaze_image_of_target(2), GazeImage::Unknown);
        let d = scene.image_distances();
        assert!((d.surface_m - p.head_m.distance(p.surface_m)).abs() < 1e-6);
        assert!(d.refracted_m > d.surface_m, "{d:?}");
    }
}
