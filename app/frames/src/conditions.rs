//! Live actions' side in the app: the effect conditions `vitreous run` cycles through and the
//! mapping of the backend's generic cycle buttons to the effect condition and the forced gaze
//! image ([`GAZE_IMAGE_CYCLE`], [`CONDITION_CYCLE`]).

use vitreous_trace::{Command, Cycle, FrameInput};

use crate::director::Director;
use crate::look::LookPlanner;
use vitreous_gaze::GazeOverride;
use vitreous_scene::effects::EffectSet;

/// The paper's study conditions, in the order the live action cycles through them (after the
/// run's own effect set): O2 (none), O3 (defocus), O4 (disparity), O5 (disparity + defocus),
/// b (caustics), c (inducer + caustics).
pub const STUDY_CONDITIONS: [&str; 6] = ["O2", "O3", "O4", "O5", "b", "c"];

/// The effect conditions `vitreous run` cycles through: `start` first, then the study
/// conditions, each once, keeping only those this build implements and (for caustics) those
/// whose bake is loaded.
pub fn live_conditions(start: EffectSet, caustics_loaded: bool) -> Vec<EffectSet> {
    let mut out = vec![start];
    for name in STUDY_CONDITIONS {
        let set = EffectSet::parse(name).expect("study condition names parse");
        if !out.contains(&set)
            && set.ensure_implemented().is_ok()
            && (!set.caustics || caustics_loaded)
        {
            out.push(set);
        }
    }
    out
}

/// The looks the live actions switch between: a look planner per effect condition (all fed
/// every frame, so switching keeps the gaze filters warm) and the forced gaze image.
pub struct LiveConditions {
    /// Each condition and its planner.
    conditions: Vec<(EffectSet, LookPlanner)>,
    /// Index of the condition shown.
    current: usize,
    /// The forced gaze image.
    gaze: GazeOverride,
}

impl LiveConditions {
    /// Starts at the first condition with gaze image `gaze`, applied to every planner.
    pub fn new(conditions: Vec<(EffectSet, LookPlanner)>, gaze: GazeOverride) -> LiveConditions {
        assert!(!conditions.is_empty(), "at least one condition");
        let mut looks = LiveConditions {
            conditions,
            current: 0,
            gaze,
        };
        looks.set_gaze(gaze);
        looks
    }

    /// The condition shown.
    pub fn condition(&self) -> EffectSet {
        self.conditions[self.current].0
    }

    /// Moves the object the image distances are measured to (its centre and model-to-world
    /// transform), for every condition.
    pub fn set_object_pose(&mut self, center_m: glam::Vec3, world_from_model: glam::Mat4) {
        for (_, planner) in &mut self.conditions {
            planner.set_object_pose(center_m, world_from_model);
        }
    }

    /// The planner of the condition shown (its newest defocus decision, its pupil source).
    pub fn planner(&self) -> &LookPlanner {
        &self.conditions[self.current].1
    }

    /// Where A_p comes from and the tracker samples with a measurement, of the conditions with
    /// defocus (all share the scene's pupil source; the counts of the first one).
    pub fn pupil_source(&self) -> Option<(vitreous_gaze::PupilSource, u64)> {
        self.conditions.iter().find_map(|(_, p)| p.pupil_source())
    }

    /// The forced gaze image.
    pub fn gaze(&self) -> GazeOverride {
        self.gaze
    }

    /// Shows condition `index` (of those given to [`LiveConditions::new`]).
    pub fn select(&mut self, index: usize) {
        assert!(index < self.conditions.len(), "condition {index} exists");
        self.current = index;
    }

    /// Forces the gaze image of every condition.
    pub fn set_gaze(&mut self, gaze: GazeOverride) {
        self.gaze = gaze;
        for (_, planner) in &mut self.conditions {
            planner.set_gaze_override(gaze);
        }
    }

    /// Applies a live command; says what changed (None for commands handled elsewhere: the
    /// session's Nudge and Rotate, the scene edits). [`GAZE_IMAGE_CYCLE`] steps the forced gaze image,
    /// [`CONDITION_CYCLE`] the effect condition.
    pub fn apply(&mut self, command: Command) -> Option<String> {
        match command {
            Command::Cycle(CONDITION_CYCLE) => {
                self.current = (self.current + 1) % self.conditions.len();
                Some(format!(
                    "effect condition now {} ({} of {})",
                    self.condition(),
                    self.current + 1,
                    self.conditions.len()
                ))
            }
            Command::Cycle(GAZE_IMAGE_CYCLE) => {
                let next = match self.gaze {
                    GazeOverride::Auto => GazeOverride::Surface,
                    GazeOverride::Surface => GazeOverride::Refracted,
                    GazeOverride::Refracted => GazeOverride::Auto,
                };
                self.set_gaze(next);
                Some(format!(
                    "gaze image now {next}{}",
                    if self.condition().defocus {
                        ""
                    } else {
                        " (shown once a condition with defocus is on)"
                    }
                ))
            }
            Command::Nudge(_)
            | Command::Rotate(_)
            | Command::MoveObject(_)
            | Command::TurnObject(_)
            | Command::PlaceObject => None,
        }
    }

    /// This frame's look as `director` decides it: its effect set (one of
    /// [`Director::sets`], the order these looks were built in; nothing shown, a blank look,
    /// for `None`) and its gaze image.
    pub fn plan_directed(
        &mut self,
        director: &mut dyn Director,
        input: &FrameInput,
    ) -> vitreous_render::Look {
        let (set, gaze) = director.next_shown(input);
        if let Some(g) = gaze
            && g != self.gaze()
        {
            self.set_gaze(g);
        }
        if let Some(i) = set.and_then(|s| director.sets().iter().position(|x| *x == s)) {
            self.select(i);
        }
        let mut look = self.plan(input);
        look.blank = set.is_none();
        look
    }

    /// This frame's look: every planner sees the frame, the current one's look is used.
    pub fn plan(&mut self, input: &FrameInput) -> vitreous_render::Look {
        let mut look = None;
        for (i, (_, planner)) in self.conditions.iter_mut().enumerate() {
            let l = planner.plan(input).0;
            if i == self.current {
                look = Some(l);
            }
        }
        look.expect("current condition exists")
    }
}

/// The live cycle (right-hand select) that forces the gaze image: surface, refracted, auto.
pub const GAZE_IMAGE_CYCLE: Cycle = Cycle::Primary;

/// The live cycle (right-hand menu) that steps through the effect conditions.
pub const CONDITION_CYCLE: Cycle = Cycle::Secondary;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_frame::test_frame as frame;
    use vitreous_render::Reflection;

    #[test]
    fn live_conditions_start_with_the_runs_own_and_skip_unloaded_caustics() {
        let defocus = EffectSet::parse("defocus").unwrap();
        let c = live_conditions(defocus, false);
        assert_eq!(c[0], defocus);
        assert_eq!(c.iter().filter(|&&e| e == defocus).count(), 1);
        assert!(
            c.iter()
                .all(|e| !e.caustics && e.ensure_implemented().is_ok())
        );
        assert!(c.contains(&EffectSet::NONE));
        assert!(c.contains(&EffectSet::parse("O5").unwrap()));
        let with = live_conditions(EffectSet::NONE, true);
        assert!(with.contains(&EffectSet::parse("c").unwrap()));
    }

    #[test]
    fn live_commands_cycle_the_condition_and_the_gaze_image() {
        let sets = [EffectSet::NONE, EffectSet::parse("disparity").unwrap()];
        let planners = sets
            .iter()
            .map(|e| LookPlanner::new(crate::look::base_look(e, Reflection::default()), None))
            .collect::<Vec<_>>();
        let mut looks = LiveConditions::new(
            sets.iter().copied().zip(planners).collect(),
            GazeOverride::Auto,
        );
        assert!(!looks.plan(&frame()).disparity);
        assert!(looks.apply(Command::Cycle(CONDITION_CYCLE)).is_some());
        assert_eq!(looks.condition(), sets[1]);
        assert!(looks.plan(&frame()).disparity);
        looks.apply(Command::Cycle(CONDITION_CYCLE));
        assert_eq!(looks.condition(), sets[0], "wraps round");
        let mut seen = Vec::new();
        for _ in 0..3 {
            looks.apply(Command::Cycle(GAZE_IMAGE_CYCLE));
            seen.push(looks.gaze());
        }
        assert_eq!(
            seen,
            [
                GazeOverride::Surface,
                GazeOverride::Refracted,
                GazeOverride::Auto
            ]
        );
        // Re-registration is the session's: nothing changes here.
        assert!(looks.apply(Command::Rotate(0.1)).is_none());
        assert_eq!(looks.condition(), sets[0]);
    }
}
