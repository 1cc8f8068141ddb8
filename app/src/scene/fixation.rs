//! Where a viewer of a scene looks: the point on the object's surface facing the viewer (the
//! surface image) and the point of the background plane seen through the object's centre
//! (where the refracted image lies). The gaze pipeline's image distances and the synthetic
//! traces of a scene both come from these points, so the two always agree.
//!
//! The synthetic-trace generator knows only a list of fixation targets; this module fixes
//! their meaning: target [`SURFACE_TARGET`] is the surface point, [`REFRACTED_TARGET`] the
//! refracted one ([`gaze_image_of_target`]).

use glam::Vec3;
use vitreous_render::Refraction;
use vitreous_render::two_surface::{Ball, MAX_INTERNAL_REFLECTIONS, pass_through};
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

/// Farthest a two-surface refracted image is placed, as a multiple of the background point's
/// distance: a virtual image near the ball's focal length runs off to infinity, and eq. 13-14
/// measure its blur on the background photo, whose blur stack must stay small.
pub const MAX_IMAGE_OVER_BACKGROUND: f32 = 2.0;

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
    /// The object's relative index of refraction when it refracts through both surfaces
    /// (`refraction = "two-surface"`): the refracted image is then where the light of the
    /// background point converges after the object. `None`: the paper's refraction, where the
    /// refracted image is the background point itself.
    pub two_surface_ior: Option<f32>,
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
        let refracted_m = match self.two_surface_ior {
            Some(ior) => self.lens_image(head_m, refracted_m, ior),
            None => refracted_m,
        };
        FixationPoints {
            head_m,
            surface_m,
            refracted_m,
        }
    }

    /// Where the light of `source_m` (on the line from `head_m` through the centre) converges
    /// after passing through both surfaces of the object's bounding ball: the point on that
    /// line where a paraxial ray from the source crosses it (the thick-lens image). A virtual
    /// image (rays diverging from a point behind the ball) is where they seem to come from, at
    /// most [`MAX_IMAGE_OVER_BACKGROUND`] times as far as the source. When the light reaches
    /// the viewer parallel or still converging (the image at or behind them) there is no image
    /// to focus on, and the source itself stands for it, as in the paper's model.
    fn lens_image(&self, head_m: Vec3, source_m: Vec3, ior: f32) -> Vec3 {
        let axis = (head_m - source_m).normalize_or(Vec3::Z);
        let far_m = head_m.distance(source_m) * MAX_IMAGE_OVER_BACKGROUND;
        let ball = Ball {
            center_m: self.center_m,
            radius_m: self.radius_m,
        };
        // A ray 1 % of the radius off the axis: paraxial, so the thick-lens image.
        let side = axis.any_orthonormal_vector();
        let aim = self.center_m + side * (0.01 * self.radius_m);
        let dir = (aim - source_m).normalize();
        let Some(p) = pass_through(&ball, source_m, dir, ior, MAX_INTERNAL_REFLECTIONS) else {
            return source_m;
        };
        // Where the exit ray meets the axis: its height above the axis falls to zero.
        let height = (p.exit_m - self.center_m).dot(side);
        let climb = p.direction.dot(side);
        if !p.escaped || climb.abs() < 1e-9 {
            return source_m;
        }
        let image = p.exit_m + p.direction * (-height / climb);
        // Along the axis towards the viewer, from the viewer: positive in front of them.
        let in_front_m = (head_m - image).dot(axis);
        if in_front_m <= 0.0 {
            source_m
        } else if in_front_m > far_m {
            head_m - axis * far_m
        } else {
            image
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
            two_surface_ior: (self.object.refraction == Refraction::TwoSurface)
                .then_some(self.object.ior),
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

    fn ball_geometry(background_z_m: f32) -> ViewingGeometry {
        ViewingGeometry {
            center_m: Vec3::new(0.0, 0.0, -0.2),
            radius_m: 0.075,
            plane_point_m: Vec3::new(0.0, 0.0, background_z_m),
            plane_normal: Vec3::Z,
            two_surface_ior: Some(1.51),
        }
    }

    #[test]
    fn two_surface_refracted_image_is_the_ball_lens_image_of_the_background() {
        // Background 1 m behind the centre: a real image f s / (s - f) in front of the centre,
        // 0.125 m from it, 0.075 m in front of the viewer (on the ball's surface plane).
        let g = ball_geometry(-1.2);
        let p = g.points_from(Vec3::ZERO);
        let (image_m, _) = vitreous_render::two_surface::ball_image(1.0, 0.075, 1.51);
        let expected = Vec3::new(0.0, 0.0, -0.2 + image_m);
        assert!(
            p.refracted_m.distance(expected) < 1e-3,
            "{} vs {expected}",
            p.refracted_m
        );
        let d = g.distances_from(Vec3::ZERO);
        assert!((d.refracted_m - (0.2 - image_m)).abs() < 1e-3, "{d:?}");
        // The paper's model puts the refracted image at the background point.
        let paper = ViewingGeometry {
            two_surface_ior: None,
            ..g
        };
        assert!((paper.distances_from(Vec3::ZERO).refracted_m - 1.2).abs() < 1e-5);
    }

    #[test]
    fn an_image_behind_the_viewer_falls_back_to_the_background_point() {
        // The visual-effects geometry: the image forms 0.25 m in front of the centre, 0.05 m
        // behind the viewer; the light reaches the eye converging.
        let d = ball_geometry(-0.4).distances_from(Vec3::ZERO);
        assert!((d.refracted_m - 0.4).abs() < 1e-5, "{d:?}");
        // A virtual image far behind (background just inside the focal length) is capped.
        let d = ball_geometry(-0.3).distances_from(Vec3::ZERO);
        assert!((d.refracted_m - 0.6).abs() < 1e-4, "{d:?}");
    }
}
