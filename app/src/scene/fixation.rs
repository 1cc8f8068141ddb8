//! Where a viewer of a scene looks: the point on the object's surface facing the viewer (the
//! surface image) and the point of the background plane seen through the object's centre
//! (where the refracted image lies). The gaze pipeline's image distances and the synthetic
//! traces of a scene both come from these points, so the two always agree.

use glam::Vec3;
use vitreous_xr::synth::SynthParams;

use super::Scene;
use crate::gaze::ImageDistances;

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

impl Scene {
    /// The points a viewer at the scene's head position fixates.
    pub fn fixation_points(&self) -> FixationPoints {
        let head = self.viewer.head_position_m;
        let center = self.object.center_m;
        let to_object = (center - head).normalize_or(Vec3::NEG_Z);
        let surface_m = center - to_object * self.object.radius_m;
        let plane_point = self.background.pose.position;
        let normal = self.background.normal();
        let denom = to_object.dot(normal);
        let behind = center + to_object * FALLBACK_REFRACTED_DEPTH_M;
        let refracted_m = if denom.abs() > 1e-3 {
            let t = (plane_point - head).dot(normal) / denom;
            if t > (center - head).length() {
                head + to_object * t
            } else {
                behind
            }
        } else {
            behind
        };
        FixationPoints {
            head_m: head,
            surface_m,
            refracted_m,
        }
    }

    /// The distances of the surface and refracted images from the viewer's head, to the
    /// points of [`Scene::fixation_points`].
    pub fn image_distances(&self) -> ImageDistances {
        let p = self.fixation_points();
        ImageDistances::from_points(p.head_m, p.surface_m, p.refracted_m)
    }
}

/// Synthetic-trace parameters for a scene: the head at the viewer's position looking at the
/// object; the gaze alternates between the points of [`Scene::fixation_points`], surface first.
pub fn synth_params_for(scene: &Scene) -> SynthParams {
    let p = scene.fixation_points();
    SynthParams {
        head_position: p.head_m,
        surface_point: p.surface_m,
        refracted_point: p.refracted_m,
        ipd_m: scene.viewer.ipd_m,
        ..SynthParams::default()
    }
}
