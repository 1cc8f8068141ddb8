//! Where a viewer of a scene looks: the point on the object's surface facing the viewer (the
//! surface image) and the point of the background plane seen through the object's centre
//! (where the refracted image lies). The gaze pipeline's image distances and the synthetic
//! traces of a scene both come from these points, so the two always agree.
//!
//! The synthetic-trace generator knows only a list of fixation targets; this module fixes
//! their meaning: target [`SURFACE_TARGET`] is the surface point, [`REFRACTED_TARGET`] the
//! refracted one ([`gaze_image_of_target`]).

use std::sync::Arc;

use glam::{Mat4, Vec3};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::two_surface::{Ball, MAX_INTERNAL_REFLECTIONS, MeshBody, pass_through};
use vitreous_trace::synth::{FixationTarget, SynthParams};

use super::{Object, Scene};
use vitreous_gaze::{GazeImage, ImageDistances};

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

/// Largest distance, as a fraction of the bundle's offset from the axis, between the image
/// point and any ray of the bundle that forms it: beyond it the rays (split between facets, or
/// by a reflection inside) form no single image.
const MAX_BUNDLE_SPREAD: f32 = 0.25;

/// The closed mesh of an object that is not a ball (model units), through which the
/// two-surface refracted image is found by tracing a bundle of rays
/// ([`ViewingGeometry::points_from`]).
pub struct MeshLens {
    /// The mesh tracer of the object, in model units.
    body: MeshBody,
}

impl std::fmt::Debug for MeshLens {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("MeshLens")
    }
}

impl PartialEq for MeshLens {
    /// The same lens: one is made per loaded object.
    fn eq(&self, other: &MeshLens) -> bool {
        std::ptr::eq(self, other)
    }
}

impl MeshLens {
    /// The lens of `object` under two-surface refraction; None for the paper's refraction, for
    /// a ball (every vertex at one distance from the centre, within 1e-4, with a normal
    /// pointing away from it: the thick ball lens stands for it exactly) and for a mesh that
    /// does not close (which two-surface refraction refuses when the renderer is made).
    pub fn of(object: &Object) -> Option<Arc<MeshLens>> {
        if object.refraction != Refraction::TwoSurface {
            return None;
        }
        if object.is_ball() {
            return None;
        }
        let m = &object.mesh;
        let body = MeshBody::new(&m.positions, &m.normals, &m.indices).ok()?;
        Some(Arc::new(MeshLens { body }))
    }
}

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
#[derive(Clone, Debug, PartialEq)]
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
    /// The object's mesh when it is not a ball (two-surface refraction): the refracted image is
    /// then found through it, placed by `world_from_model`. None: the bounding ball stands for
    /// the object.
    pub lens: Option<Arc<MeshLens>>,
    /// Model to world of the object now (a similarity), for `lens`.
    pub world_from_model: Mat4,
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
    /// after passing through both surfaces of the object: for a ball, the point on that line
    /// where a paraxial ray from the source crosses it (the thick-lens image); for another
    /// mesh, the point nearest to a bundle of paraxial rays from the source traced through it
    /// ([`ViewingGeometry::mesh_image`]). A virtual image (rays diverging from a point behind
    /// the object) is where they seem to come from, at most [`MAX_IMAGE_OVER_BACKGROUND`]
    /// times as far as the source. When the light reaches the viewer parallel or still
    /// converging (the image at or behind them), or forms no single image, there is nothing to
    /// focus on, and the source itself stands for it, as in the paper's model.
    fn lens_image(&self, head_m: Vec3, source_m: Vec3, ior: f32) -> Vec3 {
        let axis = (head_m - source_m).normalize_or(Vec3::Z);
        let far_m = head_m.distance(source_m) * MAX_IMAGE_OVER_BACKGROUND;
        let image = match &self.lens {
            Some(lens) => self.mesh_image(lens, axis, source_m, ior),
            None => self.ball_image(axis, source_m, ior),
        };
        let Some(image) = image else {
            return source_m;
        };
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

    /// The thick-lens image of `source_m` through the bounding ball, on the `axis` from the
    /// source through the centre; None when the light leaves parallel to the axis.
    fn ball_image(&self, axis: Vec3, source_m: Vec3, ior: f32) -> Option<Vec3> {
        let ball = Ball {
            center_m: self.center_m,
            radius_m: self.radius_m,
        };
        // A ray 1 % of the radius off the axis: paraxial, so the thick-lens image.
        let side = axis.any_orthonormal_vector();
        let aim = self.center_m + side * (0.01 * self.radius_m);
        let dir = (aim - source_m).normalize();
        let p = pass_through(&ball, source_m, dir, ior, MAX_INTERNAL_REFLECTIONS)?;
        // Where the exit ray meets the axis: its height above the axis falls to zero.
        let height = (p.exit_m - self.center_m).dot(side);
        let climb = p.direction.dot(side);
        if !p.escaped || climb.abs() < 1e-9 {
            return None;
        }
        Some(p.exit_m + p.direction * (-height / climb))
    }

    /// Where a bundle of four paraxial rays from `source_m`, aimed 1 % of the radius to each
    /// side of the object's centre, converges after passing through `lens`: the point nearest
    /// to the four exit rays along their mean ray (least squares). None when a ray stays
    /// inside or misses the object, when they leave parallel (no finite image), or when they
    /// pass farther than [`MAX_BUNDLE_SPREAD`] of their offset from that point (no single
    /// image: a facet edge or a reflection inside splits them).
    fn mesh_image(&self, lens: &MeshLens, axis: Vec3, source_m: Vec3, ior: f32) -> Option<Vec3> {
        let offset = 0.01 * self.radius_m;
        let (u, v) = axis.any_orthonormal_pair();
        let model_from_world = self.world_from_model.inverse();
        let mut rays = Vec::with_capacity(4);
        for side in [u, -u, v, -v] {
            let dir = (self.center_m + side * offset - source_m).normalize();
            let p = pass_through(
                &lens.body,
                model_from_world.transform_point3(source_m),
                model_from_world.transform_vector3(dir).normalize(),
                ior,
                MAX_INTERNAL_REFLECTIONS,
            )?;
            if !p.escaped {
                return None;
            }
            rays.push((
                self.world_from_model.transform_point3(p.exit_m),
                self.world_from_model
                    .transform_vector3(p.direction)
                    .normalize(),
            ));
        }
        // x(t) = mean exit + t mean direction; minimise the summed squared distances of x(t)
        // from the rays: |P_i (x - e_i)|^2 with P_i the projection across ray i.
        let n = rays.len() as f32;
        let mean_exit = rays.iter().map(|r| r.0).sum::<Vec3>() / n;
        let mean_dir = (rays.iter().map(|r| r.1).sum::<Vec3>() / n).normalize_or_zero();
        let across = |d: Vec3, w: Vec3| w - d * w.dot(d);
        let (mut num, mut den) = (0.0f32, 0.0f32);
        for &(e, d) in &rays {
            let a = across(d, mean_dir);
            num += a.dot(across(d, mean_exit - e));
            den += a.dot(a);
        }
        if den < 1e-12 {
            return None;
        }
        let image = mean_exit - mean_dir * (num / den);
        let spread = rays
            .iter()
            .map(|&(e, d)| across(d, image - e).length())
            .fold(0.0f32, f32::max);
        (spread <= MAX_BUNDLE_SPREAD * offset).then_some(image)
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
            lens: self.object.lens.clone(),
            world_from_model: self.object.world_from_model,
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
        let scene = crate::load_scene(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../config/scenes/visual-effects.toml"),
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
            lens: None,
            world_from_model: Mat4::IDENTITY,
        }
    }

    #[test]
    fn two_surface_refracted_image_is_the_ball_lens_image_of_the_background() {
        // Background 1 m behind the centre: a real image f s / (s - f) in front of the centre,
        // 0.125 m from it, 0.075 m in front of the viewer (on the ball's surface plane).
        let g = ball_geometry(-1.2);
        let p = g.points_from(Vec3::ZERO);
        let (image_m, _) = vitreous_optics::two_surface::ball_image(1.0, 0.075, 1.51);
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

    impl ViewingGeometry {
        /// The same geometry under the paper's refraction.
        fn paper(self) -> ViewingGeometry {
            ViewingGeometry {
                two_surface_ior: None,
                lens: None,
                ..self
            }
        }
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

    #[test]
    fn through_a_glass_slab_the_background_comes_nearer_by_its_thickness_times_1_minus_1_over_n() {
        // A flat-shaded glass cube 10 cm thick, face on, 0.5 m ahead; the background 1.5 m
        // ahead. Paraxially a plate of thickness T shows a point behind it T (1 - 1/n) nearer:
        // a virtual image 1.5 - 0.1 (1 - 1/1.5) = 1.4667 m away.
        let (positions, normals, indices) = vitreous_optics::solid::flat_cube(0.05);
        let lens = MeshLens {
            body: MeshBody::new(&positions, &normals, &indices).expect("a closed cube"),
        };
        let center = Vec3::new(0.0, 0.0, -0.5);
        let g = ViewingGeometry {
            center_m: center,
            radius_m: 0.05 * 3f32.sqrt(),
            plane_point_m: Vec3::new(0.0, 0.0, -1.5),
            plane_normal: Vec3::Z,
            two_surface_ior: Some(1.5),
            lens: Some(Arc::new(lens)),
            world_from_model: Mat4::from_translation(center),
        };
        let expected = 1.5 - 0.1 * (1.0 - 1.0 / 1.5);
        let d = g.distances_from(Vec3::ZERO);
        assert!(
            (d.refracted_m - expected).abs() < 1e-4,
            "{d:?}, expected {expected}"
        );
        // Turned a quarter round its vertical axis, the cube is the same slab.
        let turned = ViewingGeometry {
            world_from_model: Mat4::from_translation(center)
                * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2),
            ..g.clone()
        };
        let d = turned.distances_from(Vec3::ZERO);
        assert!(
            (d.refracted_m - expected).abs() < 1e-4,
            "{d:?}, expected {expected}"
        );
        // Seen from 0.3 m to the side, the point behind it on the line through the centre is
        // still T / cos nearer along that line, less the sideways part: only check it is
        // nearer than the background point and farther than the cube.
        let side = Vec3::new(0.3, 0.0, 0.0);
        let p = g.points_from(side);
        let background = side.distance(g.clone().paper().points_from(side).refracted_m);
        let image = side.distance(p.refracted_m);
        assert!(
            image < background && image > side.distance(center),
            "{image} {background}"
        );
    }

    #[test]
    fn a_ball_uses_the_ball_lens_and_a_faceted_object_its_mesh() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenes");
        let mut sphere = crate::load_scene(&root.join("glass-sphere.toml")).expect("shipped scene");
        let mut diamond = crate::load_scene(&root.join("diamond.toml")).expect("shipped scene");
        for scene in [&mut sphere, &mut diamond] {
            scene.object.refraction = Refraction::TwoSurface;
        }
        assert!(
            MeshLens::of(&sphere.object).is_none(),
            "the sphere is a ball"
        );
        assert!(
            MeshLens::of(&diamond.object).is_some(),
            "the diamond is not"
        );
        diamond.object.lens = MeshLens::of(&diamond.object);
        eprintln!(
            "DIAMOND two-surface {:?} paper-bg {:?}",
            diamond.image_distances(),
            diamond
                .viewing_geometry()
                .paper()
                .distances_from(diamond.viewer.head_position_m)
        );
        for dx in [-0.1f32, -0.05, 0.0, 0.02, 0.05, 0.1] {
            let h = diamond.viewer.head_position_m + Vec3::new(dx, 0.0, 0.0);
            eprintln!(
                "  head dx {dx}: {:?}",
                diamond.viewing_geometry().distances_from(h)
            );
        }
        diamond.object.refraction = Refraction::Paper;
        assert!(
            MeshLens::of(&diamond.object).is_none(),
            "the paper's model needs none"
        );
    }
}
