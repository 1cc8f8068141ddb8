//! The effect conditions a live session switches between, each with a warm look planner, and
//! the forced gaze image ([`LiveConditions`]: `vitreous run`'s controller cycle, a study's
//! trials, and under `vitreous view`'s keys); the conditions `vitreous run` cycles through
//! ([`live_conditions`]) and the mapping of the backend's generic cycle buttons to the effect
//! condition and the forced gaze image ([`GAZE_IMAGE_CYCLE`], [`CONDITION_CYCLE`]).

use vitreous_trace::{Command, Cycle, FrameInput};

use crate::director::Director;
use crate::look::LookPlanner;
use vitreous_gaze::{GazeOverride, GazeState};
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

/// The effect conditions a live session switches between, each with its look planner (all fed
/// every frame, so a switch finds its gaze filter warm), and the forced gaze image: what
/// `vitreous run`'s controller cycles, a study's trials (through [`Director`]) and `vitreous
/// view`'s keys choose among.
pub struct LiveConditions {
    /// Each condition and its planner; `None` where the session cannot show the condition (kept
    /// so that the others keep the index the session knows them by).
    conditions: Vec<Option<(EffectSet, LookPlanner)>>,
    /// Index of the condition shown.
    current: usize,
    /// The forced gaze image.
    gaze: GazeOverride,
    /// The newest gaze state of the condition shown.
    state: Option<GazeState>,
}

impl LiveConditions {
    /// Starts at the first condition with gaze image `gaze`, applied to every planner.
    pub fn new(conditions: Vec<(EffectSet, LookPlanner)>, gaze: GazeOverride) -> LiveConditions {
        assert!(!conditions.is_empty(), "at least one condition");
        LiveConditions::with_gaps(conditions.into_iter().map(Some).collect(), 0, gaze)
    }

    /// Conditions of which some cannot be shown (`None`), starting at index `current`, with
    /// gaze image `gaze` applied to every planner.
    pub fn with_gaps(
        conditions: Vec<Option<(EffectSet, LookPlanner)>>,
        current: usize,
        gaze: GazeOverride,
    ) -> LiveConditions {
        let mut looks = LiveConditions {
            conditions,
            current,
            gaze,
            state: None,
        };
        looks.set_gaze(gaze);
        looks
    }

    /// New planners for every condition that can be shown (their gaze history starts over),
    /// with the forced gaze image applied.
    pub fn replan(&mut self, mut planner: impl FnMut(EffectSet) -> LookPlanner) {
        for (set, p) in self.conditions.iter_mut().flatten() {
            *p = planner(*set);
        }
        self.set_gaze(self.gaze);
    }

    /// The condition shown.
    pub fn condition(&self) -> EffectSet {
        self.shown().0
    }

    /// The condition shown and its planner.
    fn shown(&self) -> &(EffectSet, LookPlanner) {
        self.conditions[self.current]
            .as_ref()
            .expect("the current condition can be shown")
    }

    /// Index of the condition shown.
    pub fn current(&self) -> usize {
        self.current
    }

    /// How many conditions there are, those that cannot be shown included.
    pub fn len(&self) -> usize {
        self.conditions.len()
    }

    /// Whether there are no conditions at all.
    pub fn is_empty(&self) -> bool {
        self.conditions.is_empty()
    }

    /// Condition `index`, when it exists and can be shown.
    pub fn get(&self, index: usize) -> Option<EffectSet> {
        self.conditions.get(index)?.as_ref().map(|(set, _)| *set)
    }

    /// Moves the object the image distances are measured to (its centre and model-to-world
    /// transform), for every condition.
    pub fn set_object_pose(&mut self, center_m: glam::Vec3, world_from_model: glam::Mat4) {
        for (_, planner) in self.conditions.iter_mut().flatten() {
            planner.set_object_pose(center_m, world_from_model);
        }
    }

    /// The planner of the condition shown (its newest defocus decision, its pupil source).
    pub fn planner(&self) -> &LookPlanner {
        &self.shown().1
    }

    /// The newest gaze state of the condition shown (None without defocus).
    pub fn gaze_state(&self) -> Option<GazeState> {
        self.state
    }

    /// Where A_p comes from and the tracker samples with a measurement, of the conditions with
    /// defocus (all share the scene's pupil source; the counts of the first one).
    pub fn pupil_source(&self) -> Option<(vitreous_gaze::PupilSource, u64)> {
        self.conditions
            .iter()
            .flatten()
            .find_map(|(_, p)| p.pupil_source())
    }

    /// The forced gaze image.
    pub fn gaze(&self) -> GazeOverride {
        self.gaze
    }

    /// Shows condition `index` (of those given to [`LiveConditions::new`]).
    pub fn select(&mut self, index: usize) {
        assert!(self.get(index).is_some(), "condition {index} exists");
        self.current = index;
    }

    /// Shows the condition with effects `set`; false when there is none that can be shown.
    pub fn show_set(&mut self, set: EffectSet) -> bool {
        match (0..self.len()).find(|&i| self.get(i) == Some(set)) {
            Some(i) => {
                self.current = i;
                true
            }
            None => false,
        }
    }

    /// Shows the next condition that can be shown (after the last, the first; the one shown
    /// when it is the only one) and returns it; None when none can be shown.
    pub fn step(&mut self) -> Option<EffectSet> {
        let n = self.len();
        let next = (1..=n)
            .map(|step| (self.current + step) % n)
            .find(|&i| self.get(i).is_some())?;
        self.current = next;
        self.get(next)
    }

    /// Forces the gaze image of every condition.
    pub fn set_gaze(&mut self, gaze: GazeOverride) {
        self.gaze = gaze;
        for (_, planner) in self.conditions.iter_mut().flatten() {
            planner.set_gaze_override(gaze);
        }
    }

    /// Forces the next gaze image (auto, surface, refracted, auto) and returns it.
    pub fn cycle_gaze(&mut self) -> GazeOverride {
        let next = match self.gaze {
            GazeOverride::Auto => GazeOverride::Surface,
            GazeOverride::Surface => GazeOverride::Refracted,
            GazeOverride::Refracted => GazeOverride::Auto,
        };
        self.set_gaze(next);
        next
    }

    /// Applies a live command; says what changed (None for commands handled elsewhere: the
    /// session's Nudge and Rotate, the scene edits). [`GAZE_IMAGE_CYCLE`] steps the forced gaze image,
    /// [`CONDITION_CYCLE`] the effect condition.
    pub fn apply(&mut self, command: Command) -> Option<String> {
        match command {
            Command::Cycle(CONDITION_CYCLE) => {
                self.step();
                Some(format!(
                    "effect condition now {} ({} of {})",
                    self.condition(),
                    self.current + 1,
                    self.conditions.len()
                ))
            }
            Command::Cycle(GAZE_IMAGE_CYCLE) => {
                let next = self.cycle_gaze();
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

    /// This frame's look: every planner sees the frame, the current one's look is used (a
    /// default look when it cannot be shown).
    pub fn plan(&mut self, input: &FrameInput) -> vitreous_render::Look {
        let mut look = vitreous_render::Look::default();
        for (i, (_, planner)) in self
            .conditions
            .iter_mut()
            .enumerate()
            .filter_map(|(i, c)| Some((i, c.as_mut()?)))
        {
            let (l, state) = planner.plan(input);
            if i == self.current {
                look = l;
                self.state = state;
            }
        }
        look
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

    #[test]
    fn conditions_that_cannot_be_shown_keep_their_index_and_are_stepped_over() {
        let sets = [
            EffectSet::NONE,
            EffectSet::parse("disparity").unwrap(),
            EffectSet::parse("O5").unwrap(),
        ];
        let planner = |e: &EffectSet| {
            LookPlanner::new(crate::look::base_look(e, Reflection::default()), None)
        };
        let mut looks = LiveConditions::with_gaps(
            vec![
                Some((sets[0], planner(&sets[0]))),
                None,
                Some((sets[2], planner(&sets[2]))),
            ],
            2,
            GazeOverride::Auto,
        );
        assert_eq!(looks.condition(), sets[2]);
        assert_eq!(looks.get(1), None);
        assert!(!looks.show_set(sets[1]));
        assert_eq!(looks.step(), Some(sets[0]), "wraps round");
        assert_eq!(looks.step(), Some(sets[2]), "skips the gap");
        assert_eq!(looks.current(), 2);
        assert!(looks.show_set(sets[0]));
        assert!(!looks.plan(&frame()).disparity);
    }
}
