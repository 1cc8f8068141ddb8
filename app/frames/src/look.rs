//! Each frame's look: the effect set's fixed part plus the gaze-dependent defocus (eq. 13-14)
//! of the gaze image the gaze pipeline chose.
//!
//! Eq. 13-14 are evaluated every frame from where the wearer's eyes are: the image distances
//! are those of the frame's viewing position (the midpoint of the two eye positions,
//! [`viewing_position_m`]) to the scene's fixation points
//! ([`ViewingGeometry`](vitreous_scene::ViewingGeometry), the same geometry the scene's fixed
//! viewer uses), and the gaze-image decision compares the fixation depth with those distances. A_p is the fixed pupil diameter or the tracker's measurement,
//! smoothed ([`PupilFilter`]).
//!
//! While the gaze image is unknown (no valid gaze yet, or a blink held too long), nothing is
//! blurred.

use anyhow::Result;
use glam::Vec3;
use vitreous_render::{Defocus, Look, Reflection};
use vitreous_trace::FrameInput;

use crate::blur_stack::DefocusSetup;
pub use crate::defocus_model::DefocusModel;
use vitreous_gaze::blur::check_pupil_diameter_m;
use vitreous_gaze::{
    FilterKind, GazeConfig, GazeImage, GazeOverride, GazePipeline, GazeState, ImageDistances,
    ObjectInView, PupilFilter, PupilSource, Separability,
};
use vitreous_scene::Scene;
use vitreous_scene::effects::EffectSet;

/// How an effect set is drawn. The baseline is the conventional method (environment map and
/// Fresnel for both refraction and reflection); with the method's visual effects (disparity,
/// defocus) the reflected image is drawn as `reflection` says (the paper used a Phong
/// highlight). Defocus amounts are per frame: this gives none; the frame's gaze sets them.
pub fn base_look(effects: &EffectSet, reflection: Reflection) -> Look {
    let method = effects.disparity || effects.defocus;
    Look {
        disparity: effects.disparity,
        defocus: None,
        reflection: if method {
            reflection
        } else {
            Reflection::EnvironmentFresnel
        },
        inducer: effects.inducer,
        caustics: effects.caustics,
        blank: false,
    }
}

/// Where a frame is viewed from: the midpoint of its two eye positions (scene frame, metres).
pub fn viewing_position_m(input: &FrameInput) -> Vec3 {
    (input.views[0].pose.position + input.views[1].pose.position) * 0.5
}

/// What the defocus of one frame was decided from, for the per-frame log and the summaries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefocusFrame {
    /// The gaze image after the override (unknown: no defocus).
    pub image: GazeImage,
    /// The image distances from this frame's viewing position, metres.
    pub distances: ImageDistances,
    /// K_g of each image by eq. 13-14 (`None` while the gaze image is unknown).
    pub defocus: Option<Defocus>,
    /// A_p used, metres.
    pub pupil_m: f32,
    /// Whether A_p is a measurement (false: the fixed value).
    pub pupil_measured: bool,
    /// How far apart the images are in the tracker's vergence noise, at the newest sample.
    pub separability: Option<Separability>,
}

/// The per-frame state of defocus: the gaze pipeline, the model and the pupil filter.
struct DefocusPlan {
    /// Vergence, depth filter and gaze-image decision.
    pipeline: GazePipeline,
    /// The scene's numbers of eq. 13-14.
    model: DefocusModel,
    /// A_p frame by frame.
    pupil: PupilFilter,
    /// The newest frame's decision.
    last: Option<DefocusFrame>,
    /// Whether the tracker was found unable to separate the images (warned once).
    warned_inseparable: bool,
    /// The last image the pipeline decided: held while its decision is unknown again (the
    /// tracker lost for longer than the blink hold), so the wearer keeps the defocus they saw
    /// instead of both images turning sharp until the tracker is back.
    held: Option<GazeImage>,
}

impl DefocusPlan {
    fn new(config: GazeConfig, model: DefocusModel) -> DefocusPlan {
        DefocusPlan {
            pipeline: GazePipeline::new(config),
            pupil: PupilFilter::new(model.pupil_source, model.pupil_m),
            model,
            last: None,
            warned_inseparable: false,
            held: None,
        }
    }
}

/// Decides each frame's look: the effect set's fixed part, and the defocus that the gaze
/// pipeline (vergence -> depth filter -> gaze image, METHOD.md section 5) asks for.
pub struct LookPlanner {
    /// The effect set's look without defocus amounts.
    base: Look,
    /// Gaze pipeline, defocus model and pupil, when defocus is on.
    defocus: Option<DefocusPlan>,
}

impl LookPlanner {
    /// A planner for `base` (see [`base_look`]); with `defocus`, the gaze pipeline runs with
    /// `gaze` as its configuration.
    pub fn new(base: Look, defocus: Option<(GazeConfig, DefocusModel)>) -> LookPlanner {
        LookPlanner {
            base,
            defocus: defocus.map(|(config, model)| DefocusPlan::new(config, model)),
        }
    }

    /// A planner with the same settings and no gaze history, for a replay that starts over.
    pub fn restarted(&self) -> LookPlanner {
        LookPlanner {
            base: self.base,
            defocus: self
                .defocus
                .as_ref()
                .map(|d| DefocusPlan::new(*d.pipeline.config(), d.model.clone())),
        }
    }

    /// Forces the gaze image (or lets the tracker choose again) from now on; no effect
    /// without defocus. The gaze pipeline keeps its tracking state.
    pub fn set_gaze_override(&mut self, image: GazeOverride) {
        if let Some(d) = &mut self.defocus {
            d.pipeline.set_override(image);
        }
    }

    /// The forced gaze image; `None` without defocus.
    pub fn gaze_override(&self) -> Option<GazeOverride> {
        self.defocus
            .as_ref()
            .map(|d| d.pipeline.config().override_image)
    }

    /// Moves the object the image distances are measured to (a moving object): its centre and
    /// its model-to-world transform.
    pub fn set_object_pose(&mut self, center_m: Vec3, world_from_model: glam::Mat4) {
        if let Some(d) = &mut self.defocus {
            d.model.geometry.center_m = center_m;
            d.model.geometry.world_from_model = world_from_model;
        }
    }

    /// The look of a frame, and the gaze state behind its defocus (when defocus is on). The
    /// image distances are those of the frame's viewing position ([`viewing_position_m`]).
    pub fn plan(&mut self, input: &FrameInput) -> (Look, Option<GazeState>) {
        match &mut self.defocus {
            None => (self.base, None),
            Some(d) => {
                let distances = d.model.distances_from(viewing_position_m(input));
                d.pipeline.set_distances(distances);
                let g = &d.model.geometry;
                d.pipeline.set_object(ObjectInView::from_head(
                    input.head.position,
                    input.head.orientation,
                    g.center_m,
                    g.radius_m,
                ));
                let state = d.pipeline.update(input.gaze.as_ref(), input.time_ns);
                let pupil = d.pupil.update(input.gaze.as_ref());
                let image = match state.image {
                    GazeImage::Unknown => d.held.unwrap_or(GazeImage::Unknown),
                    decided => *d.held.insert(decided),
                };
                let defocus = d.model.defocus_at(image, &distances, pupil.diameter_m);
                d.last = Some(DefocusFrame {
                    image,
                    distances,
                    defocus,
                    pupil_m: pupil.diameter_m,
                    pupil_measured: pupil.measured,
                    separability: state.separability,
                });
                if !d.warned_inseparable
                    && let Some(warning) = state.separability.and_then(|s| s.warning())
                {
                    tracing::warn!("{warning}");
                    d.warned_inseparable = true;
                }
                let look = Look {
                    defocus,
                    ..self.base
                };
                (look, Some(state))
            }
        }
    }

    /// The defocus decision of the newest planned frame; `None` without defocus or before the
    /// first frame.
    pub fn last_defocus(&self) -> Option<&DefocusFrame> {
        self.defocus.as_ref().and_then(|d| d.last.as_ref())
    }

    /// Where A_p comes from and how many tracker samples had a measurement; `None` without
    /// defocus.
    pub fn pupil_source(&self) -> Option<(PupilSource, u64)> {
        self.defocus
            .as_ref()
            .map(|d| (d.pupil.source(), d.pupil.measured_samples()))
    }
}

/// How the gaze pipeline runs (METHOD.md section 5); `None` keeps the scene's choice.
#[derive(Clone, Copy, Debug, Default)]
pub struct GazeSettings {
    /// Depth filter overriding the scene's `[gaze] filter`.
    pub filter: Option<FilterKind>,
    /// Experimenter override of the gaze image, overriding the scene's `[gaze] image`.
    pub image: Option<GazeOverride>,
    /// Pupil diameter A_p overriding the scene's, millimetres (1-9).
    pub pupil_mm: Option<f32>,
    /// Where A_p comes from, overriding the scene's `[gaze] pupil`.
    pub pupil_source: Option<PupilSource>,
}

/// The per-frame look planner for a scene and effect set, and the defocus stacks to upload
/// (built when defocus is on).
pub fn planner_for(
    scene: &Scene,
    effects: &EffectSet,
    reflection: Reflection,
    gaze: &GazeSettings,
) -> Result<(LookPlanner, Option<DefocusSetup>)> {
    let (mut planners, setup) = planners_for(scene, &[*effects], reflection, gaze)?;
    Ok((planners.remove(0), setup))
}

/// One look planner per effect set in `sets` (in that order), sharing one defocus setup (blur
/// stacks), built when any of the sets has defocus on.
pub fn planners_for(
    scene: &Scene,
    sets: &[EffectSet],
    reflection: Reflection,
    gaze: &GazeSettings,
) -> Result<(Vec<LookPlanner>, Option<DefocusSetup>)> {
    let setup = if sets.iter().any(|e| e.defocus) {
        let pupil_m = match gaze.pupil_mm {
            Some(mm) => check_pupil_diameter_m(mm / 1000.0)?,
            None => scene.viewer.pupil_diameter_m,
        };
        let source = gaze.pupil_source.unwrap_or(scene.gaze.pupil);
        if source == PupilSource::Measured {
            tracing::info!(
                "A_p: the eye tracker's pupil diameters, smoothed ({:.1} mm until the first \
                 measurement)",
                pupil_m * 1000.0
            );
        } else {
            tracing::info!("A_p: fixed {:.1} mm", pupil_m * 1000.0);
        }
        let mut setup = DefocusSetup::new(scene, pupil_m);
        setup.model.pupil_source = source;
        Some(setup)
    } else {
        None
    };
    let planners = sets
        .iter()
        .map(|effects| {
            let base = base_look(effects, reflection);
            let defocus = match (&setup, effects.defocus) {
                (Some(setup), true) => {
                    let mut config = GazeConfig::new(setup.model.distances);
                    config.filter = gaze.filter.unwrap_or(scene.gaze.filter);
                    config.override_image = gaze.image.unwrap_or(scene.gaze.image);
                    Some((config, setup.model.clone()))
                }
                _ => None,
            };
            LookPlanner::new(base, defocus)
        })
        .collect();
    Ok((planners, setup))
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};
    use vitreous_render::Reflection;
    use vitreous_trace::format::TraceSample;
    use vitreous_trace::{GazeRay, GazeSample, Pose};
    use vitreous_xr::Backend;
    use vitreous_xr::null::{NullBackend, NullConfig};

    use super::*;

    /// The visual-effects scene: a sphere 0.15 m across centred 0.2 m ahead of the viewer's
    /// start position, the background plane 0.4 m ahead, facing the viewer.
    const SPHERE_RADIUS_M: f32 = 0.075;
    const SPHERE_Z_M: f32 = -0.2;
    const BACKGROUND_Z_M: f32 = -0.4;
    const IPD_M: f32 = 0.063;

    fn scene() -> Scene {
        vitreous_scene::load_scene(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../config/scenes/visual-effects.toml"),
        )
        .expect("shipped scene")
    }

    fn planner(scene: &Scene, image: GazeOverride) -> LookPlanner {
        let effects = EffectSet::parse("defocus").unwrap();
        let model = DefocusModel::new(scene, 0.006);
        let mut config = GazeConfig::new(model.distances);
        // The scene's filter (eq. 15), as `run` and `replay` take it.
        config.filter = scene.gaze.filter;
        config.override_image = image;
        LookPlanner::new(
            base_look(&effects, Reflection::default()),
            Some((config, model)),
        )
    }

    /// A head at `head_z_m` on the axis through the sphere, facing it, both eyes fixating
    /// the world point `target`.
    fn sample(time_ns: i64, head_z_m: f32, target: Vec3) -> TraceSample {
        let head = Vec3::new(0.0, 0.0, head_z_m);
        let eye = |x: f32| {
            let origin = Vec3::new(x, 0.0, 0.0);
            GazeRay {
                origin,
                direction: (target - head - origin).normalize(),
                valid: true,
            }
        };
        TraceSample {
            time_ns,
            head: Pose {
                position: head,
                orientation: Quat::IDENTITY,
            },
            gaze: GazeSample::binocular(time_ns, eye(-IPD_M / 2.0), eye(IPD_M / 2.0)),
        }
    }

    #[test]
    fn at_the_fixed_viewing_position_frames_get_the_scenes_distances_and_blur() {
        let scene = scene();
        let head = scene.viewer.head_position_m;
        let mut input = crate::test_frame::test_frame();
        input.head.position = head;
        input.views[0].pose.position = head - Vec3::X * scene.viewer.ipd_m / 2.0;
        input.views[1].pose.position = head + Vec3::X * scene.viewer.ipd_m / 2.0;
        let model = DefocusModel::new(&scene, 0.006);
        assert_eq!(
            model.distances_from(viewing_position_m(&input)),
            scene.image_distances()
        );
        for (image, gaze) in [
            (GazeOverride::Surface, GazeImage::Surface),
            (GazeOverride::Refracted, GazeImage::Refracted),
        ] {
            let mut p = planner(&scene, image);
            let (look, _) = p.plan(&input);
            assert_eq!(look.defocus, model.defocus(gaze));
            let d = p.last_defocus().unwrap();
            assert_eq!(d.distances, scene.image_distances());
            assert_eq!((d.pupil_m, d.pupil_measured), (0.006, false));
        }
    }

    /// The tracker lost for a second (no valid eye): the pipeline's decision turns unknown
    /// after its 300 ms hold, but the look keeps the image decided before, and its defocus,
    /// until the tracker decides again.
    #[test]
    fn the_decided_image_is_held_while_the_tracker_is_lost() {
        let scene = scene();
        let mut p = planner(&scene, GazeOverride::Auto);
        let front = Vec3::new(0.0, 0.0, SPHERE_Z_M + SPHERE_RADIUS_M);
        let frame = |i: i64, valid: bool| {
            let s = sample(i * 20_000_000, 0.0, front);
            let mut input = crate::test_frame::test_frame();
            input.time_ns = s.time_ns;
            input.gaze = Some(if valid {
                s.gaze
            } else {
                GazeSample::none(s.time_ns)
            });
            input
        };
        for i in 0..30 {
            p.plan(&frame(i, true));
        }
        let decided = *p.last_defocus().unwrap();
        assert_eq!(decided.image, GazeImage::Surface);
        for i in 30..80 {
            let (look, state) = p.plan(&frame(i, false));
            assert_eq!(
                p.last_defocus().unwrap().image,
                GazeImage::Surface,
                "frame {i}"
            );
            assert_eq!(look.defocus, decided.defocus, "frame {i}");
            if i > 60 {
                assert_eq!(
                    state.unwrap().image,
                    GazeImage::Unknown,
                    "the pipeline let go"
                );
            }
        }
    }

    /// Replays a head moving from 0.1 m behind the start position to 0.05 m in front of it
    /// while the eyes fixate the sphere's front: every frame's K_g of the refracted image is
    /// eq. 13-14 with that frame's distances, and the decision stays on the surface image
    /// (with the start position's distances the first depths would read as refracted).
    #[test]
    fn a_moving_head_changes_the_distances_the_decision_and_k_g_every_frame() {
        let scene = scene();
        let front = Vec3::new(0.0, 0.0, SPHERE_Z_M + SPHERE_RADIUS_M);
        let samples: Vec<TraceSample> = (0..=150)
            .map(|i| sample(i * 10_000_000, 0.1 - 0.001 * i as f32, front))
            .collect();
        let start_depth = 0.1 - front.z;
        assert_eq!(
            scene.image_distances().nearest(start_depth),
            GazeImage::Refracted,
            "the fixed distances would decide otherwise, so the test can tell"
        );
        let mut backend = NullBackend::new(
            samples,
            NullConfig {
                frame_rate_hz: 50.0,
                ipd_m: IPD_M,
                ..NullConfig::default()
            },
        )
        .unwrap();
        let mut p = planner(&scene, GazeOverride::Auto);
        let background_px_per_m = scene.background.photo.width as f32 / 0.6;
        let (mut frames, mut k_seen) = (0, Vec::new());
        while let Some(input) = backend.wait_frame().unwrap() {
            backend.end_frame(&input).unwrap();
            let (look, _) = p.plan(&input);
            let z = input.head.position.z;
            let d_s = (z - SPHERE_Z_M) - SPHERE_RADIUS_M;
            let d_r = z - BACKGROUND_Z_M;
            let d = p.last_defocus().unwrap();
            assert!((d.distances.surface_m - d_s).abs() < 1e-5, "{d:?} at z {z}");
            assert!(
                (d.distances.refracted_m - d_r).abs() < 1e-5,
                "{d:?} at z {z}"
            );
            assert_eq!(
                d.image,
                GazeImage::Surface,
                "frame {} at z {z}",
                input.index
            );
            let expected_k = background_px_per_m * 0.006 * (d_r - d_s) / d_s;
            let k = look.defocus.unwrap().refracted_k_g_px;
            assert!(
                (k - expected_k).abs() < 1e-3 * expected_k,
                "frame {}: K_g {k} px, expected {expected_k} px",
                input.index
            );
            assert_eq!(look.defocus.unwrap().surface_k_g_px, 0.0);
            k_seen.push(k);
            frames += 1;
        }
        assert_eq!(frames, 76);
        // Nearer the sphere the background is relatively further behind it: more blur.
        assert!(k_seen.windows(2).all(|w| w[1] > w[0]), "{k_seen:?}");
    }
}
