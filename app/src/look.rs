//! Each frame's look: the effect set's fixed part plus the gaze-dependent defocus (eq. 13-14)
//! of the gaze image the gaze pipeline chose.
//!
//! While the gaze image is unknown (no valid gaze yet, or a blink held too long), nothing is
//! blurred.

use anyhow::Result;
use vitreous_render::{Defocus, Look, Reflection};
use vitreous_xr::FrameInput;

use crate::blur_stack::DefocusSetup;
use crate::effects::EffectSet;
use crate::gaze::blur::{check_pupil_diameter_m, image_blur, px_per_m};
use crate::gaze::{
    FilterKind, GazeConfig, GazeImage, GazeOverride, GazePipeline, GazeState, ImageDistances,
};
use crate::scene::Scene;
use crate::views;

/// The numbers eq. 13-14 need of a scene: image distances, pixels per metre of each image's
/// photo, and the pupil.
#[derive(Clone, Copy, Debug)]
pub struct DefocusModel {
    /// Distances of the surface and refracted images from the viewing position, metres.
    pub distances: ImageDistances,
    /// Pupil diameter A_p, metres.
    pub pupil_m: f32,
    /// W_p / W_l of the surface texture: texels per metre on the object's surface.
    pub surface_px_per_m: f32,
    /// W_p / W_l of the background photo: pixels per metre on the background plane.
    pub background_px_per_m: f32,
}

impl DefocusModel {
    /// The model of `scene` with pupil diameter `pupil_m`.
    pub fn new(scene: &Scene, pupil_m: f32) -> DefocusModel {
        DefocusModel {
            distances: scene.image_distances(),
            pupil_m,
            background_px_per_m: px_per_m(
                scene.background.photo.width as f32,
                scene.background.size_m.x,
            ),
            // u runs once around the object: texels per metre of its circumference.
            surface_px_per_m: scene.object.surface_texture.as_ref().map_or(1.0, |t| {
                px_per_m(
                    t.width as f32,
                    std::f32::consts::PI * 2.0 * scene.object.radius_m,
                )
            }),
        }
    }

    /// The blur of both images for a gaze image (eq. 13-14); `None` while it is unknown.
    pub fn defocus(&self, image: GazeImage) -> Option<Defocus> {
        if image == GazeImage::Unknown {
            return None;
        }
        let blur = image_blur(
            image,
            &self.distances,
            self.pupil_m,
            self.surface_px_per_m,
            self.background_px_per_m,
        );
        Some(Defocus {
            refracted_k_g_px: blur.refracted_k_g_px,
            surface_k_g_px: blur.surface_k_g_px,
        })
    }
}

/// Decides each frame's look: the effect set's fixed part, and the defocus that the gaze
/// pipeline (vergence -> depth filter -> gaze image, METHOD.md section 5) asks for.
pub struct LookPlanner {
    /// The effect set's look without defocus amounts.
    base: Look,
    /// Gaze pipeline and defocus model, when defocus is on.
    defocus: Option<(GazePipeline, DefocusModel)>,
}

impl LookPlanner {
    /// A planner for `base` (see `views::look`); with `defocus`, the gaze pipeline runs with
    /// `gaze` as its configuration.
    pub fn new(base: Look, defocus: Option<(GazeConfig, DefocusModel)>) -> LookPlanner {
        LookPlanner {
            base,
            defocus: defocus.map(|(config, model)| (GazePipeline::new(config), model)),
        }
    }

    /// A planner with the same settings and no gaze history, for a replay that starts over.
    pub fn restarted(&self) -> LookPlanner {
        LookPlanner {
            base: self.base,
            defocus: self
                .defocus
                .as_ref()
                .map(|(pipeline, model)| (GazePipeline::new(*pipeline.config()), *model)),
        }
    }

    /// Forces the gaze image (or lets the tracker choose again) from now on; no effect
    /// without defocus. The gaze pipeline keeps its tracking state.
    pub fn set_gaze_override(&mut self, image: GazeOverride) {
        if let Some((pipeline, _)) = &mut self.defocus {
            pipeline.set_override(image);
        }
    }

    /// The forced gaze image; `None` without defocus.
    pub fn gaze_override(&self) -> Option<GazeOverride> {
        self.defocus
            .as_ref()
            .map(|(pipeline, _)| pipeline.config().override_image)
    }

    /// The look of a frame, and the gaze state behind its defocus (when defocus is on).
    pub fn plan(&mut self, input: &FrameInput) -> (Look, Option<GazeState>) {
        match &mut self.defocus {
            None => (self.base, None),
            Some((pipeline, model)) => {
                let state = pipeline.update(input.gaze.as_ref(), input.time_ns);
                let look = Look {
                    defocus: model.defocus(state.image),
                    ..self.base
                };
                (look, Some(state))
            }
        }
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
        Some(DefocusSetup::new(scene, pupil_m))
    } else {
        None
    };
    let planners = sets
        .iter()
        .map(|effects| {
            let base = views::look(effects, reflection);
            let defocus = match (&setup, effects.defocus) {
                (Some(setup), true) => {
                    let mut config = GazeConfig::new(setup.model.distances);
                    config.filter = gaze.filter.unwrap_or(scene.gaze.filter);
                    config.override_image = gaze.image.unwrap_or(scene.gaze.image);
                    Some((config, setup.model))
                }
                _ => None,
            };
            LookPlanner::new(base, defocus)
        })
        .collect();
    Ok((planners, setup))
}
