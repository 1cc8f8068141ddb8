//! The effect conditions the viewer switches between, and their look planners (every planner
//! sees every frame, so a switch finds its gaze filter warm).

use anyhow::Result;
use vitreous_render::{Look, Reflection};
use vitreous_trace::FrameInput;

use crate::effects::EffectSet;
use crate::gaze::{FilterKind, GazeConfig, GazeOverride, GazeState};
use crate::look::{DefocusModel, LookPlanner};

/// The conditions keys 1-7 choose: none (O2, a), O3, O4, O5, b, c, and the inducer alone
/// (disparity, defocus and caustics alone are O4, O3 and b).
pub const CONDITION_KEYS: [&str; 7] = ["none", "O3", "O4", "O5", "b", "c", "inducer"];

/// The gaze filters G steps through.
pub const FILTERS: [&str; 5] = ["evidence", "fixation", "mean20", "median20", "one-euro"];

/// The viewer's conditions and planners.
pub struct ViewConditions {
    /// Each condition (None where this build or scene cannot show it), by key.
    conditions: Vec<Option<EffectSet>>,
    /// The planner of each available condition.
    planners: Vec<Option<LookPlanner>>,
    /// Index of the condition shown.
    current: usize,
    /// The scene's numbers for eq. 13-14, when any condition has defocus.
    model: Option<DefocusModel>,
    /// How the reflected image is drawn.
    reflection: Reflection,
    /// The gaze filter.
    filter: FilterKind,
    /// The forced gaze image.
    gaze: GazeOverride,
    /// The newest gaze state of the condition shown.
    state: Option<GazeState>,
}

impl ViewConditions {
    /// The conditions of [`CONDITION_KEYS`] (with `start` first when it is not among them),
    /// leaving out those whose effects this build does not implement and, without a loaded
    /// caustic bake, those with caustics.
    pub fn new(
        start: EffectSet,
        caustics_loaded: bool,
        model: Option<DefocusModel>,
        reflection: Reflection,
        filter: FilterKind,
        gaze: GazeOverride,
    ) -> ViewConditions {
        let mut sets: Vec<EffectSet> = CONDITION_KEYS
            .iter()
            .map(|n| EffectSet::parse(n).expect("condition names parse"))
            .collect();
        let current = match sets.iter().position(|s| *s == start) {
            Some(i) => i,
            None => {
                sets.push(start);
                sets.len() - 1
            }
        };
        let conditions = sets
            .into_iter()
            .map(|s| {
                (s.ensure_implemented().is_ok() && (!s.caustics || caustics_loaded)).then_some(s)
            })
            .collect();
        let mut looks = ViewConditions {
            conditions,
            planners: Vec::new(),
            current,
            model,
            reflection,
            filter,
            gaze,
            state: None,
        };
        looks.rebuild();
        looks
    }

    /// New planners for the current settings (gaze history starts over).
    fn rebuild(&mut self) {
        self.planners = self
            .conditions
            .iter()
            .map(|c| {
                c.map(|set| {
                    let defocus = match (set.defocus, &self.model) {
                        (true, Some(model)) => {
                            let mut config = GazeConfig::new(model.distances);
                            config.filter = self.filter;
                            config.override_image = self.gaze;
                            Some((config, model.clone()))
                        }
                        _ => None,
                    };
                    LookPlanner::new(crate::look::base_look(&set, self.reflection), defocus)
                })
            })
            .collect();
    }

    /// The condition shown.
    pub fn condition(&self) -> EffectSet {
        self.conditions[self.current].expect("the current condition is available")
    }

    /// The planner of the condition shown.
    pub fn planner(&self) -> &LookPlanner {
        self.planners[self.current]
            .as_ref()
            .expect("the current condition has a planner")
    }

    /// Moves the object the image distances are measured to (its centre and model-to-world
    /// transform), for every condition.
    pub fn set_object_pose(&mut self, center_m: glam::Vec3, world_from_model: glam::Mat4) {
        for planner in self.planners.iter_mut().flatten() {
            planner.set_object_pose(center_m, world_from_model);
        }
    }

    /// The gaze filter, reflection and forced gaze image, for the overlay.
    pub fn settings(&self) -> (FilterKind, Reflection, GazeOverride) {
        (self.filter, self.reflection, self.gaze)
    }

    /// The newest gaze state of the condition shown (None without defocus).
    pub fn gaze_state(&self) -> Option<GazeState> {
        self.state
    }

    /// Shows condition `index` of [`CONDITION_KEYS`]; says what happened.
    pub fn choose(&mut self, index: usize) -> String {
        match self.conditions.get(index) {
            Some(Some(set)) => {
                self.current = index;
                format!("effects now {set}")
            }
            Some(None) => format!(
                "condition {} is not available here (not implemented, or no caustic bake for \
                 the scene)",
                CONDITION_KEYS[index]
            ),
            None => "no such condition".into(),
        }
    }

    /// The next available condition.
    pub fn next(&mut self) -> String {
        let n = self.conditions.len();
        for step in 1..=n {
            let i = (self.current + step) % n;
            if self.conditions[i].is_some() {
                return self.choose(i);
            }
        }
        self.choose(self.current)
    }

    /// Switches the reflected image between Phong and environment + Fresnel.
    pub fn toggle_reflection(&mut self) -> String {
        self.reflection = match self.reflection {
            Reflection::Phong => Reflection::EnvironmentFresnel,
            Reflection::EnvironmentFresnel => Reflection::Phong,
        };
        self.rebuild();
        format!("reflection now {:?}", self.reflection)
    }

    /// The next gaze filter of [`FILTERS`].
    pub fn next_filter(&mut self) -> Result<String> {
        let now = self.filter.to_string();
        let i = FILTERS.iter().position(|f| *f == now).map_or(0, |i| i + 1);
        self.filter = FILTERS[i % FILTERS.len()].parse()?;
        self.rebuild();
        Ok(format!("gaze filter now {}", self.filter))
    }

    /// Shows the condition with effects `set`; false when the viewer has no such condition
    /// available.
    pub fn show_set(&mut self, set: EffectSet) -> bool {
        match self.conditions.iter().position(|c| *c == Some(set)) {
            Some(i) => {
                self.current = i;
                true
            }
            None => false,
        }
    }

    /// Forces the gaze image (auto: the gaze pipeline decides).
    pub fn set_gaze(&mut self, gaze: GazeOverride) {
        if gaze != self.gaze {
            self.gaze = gaze;
            for p in self.planners.iter_mut().flatten() {
                p.set_gaze_override(gaze);
            }
        }
    }

    /// The next forced gaze image (auto, surface, refracted).
    pub fn next_gaze(&mut self) -> String {
        self.gaze = match self.gaze {
            GazeOverride::Auto => GazeOverride::Surface,
            GazeOverride::Surface => GazeOverride::Refracted,
            GazeOverride::Refracted => GazeOverride::Auto,
        };
        for p in self.planners.iter_mut().flatten() {
            p.set_gaze_override(self.gaze);
        }
        format!("gaze image forced: {}", self.gaze)
    }

    /// This frame's look: every planner sees the frame, the current one's look is used.
    pub fn plan(&mut self, input: &FrameInput) -> Look {
        let mut look = Look::default();
        for (i, planner) in self.planners.iter_mut().enumerate() {
            if let Some(p) = planner {
                let (l, state) = p.plan(input);
                if i == self.current {
                    look = l;
                    self.state = state;
                }
            }
        }
        look
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn looks(start: &str, caustics: bool) -> ViewConditions {
        ViewConditions::new(
            EffectSet::parse(start).unwrap(),
            caustics,
            None,
            Reflection::Phong,
            FilterKind::default(),
            GazeOverride::Auto,
        )
    }

    #[test]
    fn keys_choose_conditions_and_caustics_need_a_bake() {
        let mut l = looks("O5", false);
        assert_eq!(l.condition(), EffectSet::parse("O5").unwrap());
        assert!(l.choose(0).contains("none"));
        assert_eq!(l.condition(), EffectSet::NONE);
        assert!(l.choose(4).contains("not available"), "b needs the bake");
        assert_eq!(l.condition(), EffectSet::NONE);
        let mut with = looks("none", true);
        if EffectSet::parse("b").unwrap().ensure_implemented().is_ok() {
            with.choose(4);
            assert!(with.condition().caustics);
        }
    }

    #[test]
    fn an_unlisted_start_set_is_kept_and_filters_cycle() {
        let mut l = looks("disparity,inducer", false);
        assert_eq!(
            l.condition(),
            EffectSet::parse("disparity,inducer").unwrap()
        );
        let mut seen = Vec::new();
        for _ in 0..FILTERS.len() {
            l.next_filter().unwrap();
            seen.push(l.settings().0.to_string());
        }
        assert_eq!(seen.last().map(String::as_str), Some("evidence"));
        assert!(seen.contains(&"mean20".to_string()));
    }
}
