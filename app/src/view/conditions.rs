//! The viewer's side of the effect conditions: which condition each of keys 1-7 shows, and the
//! gaze filters and reflections it cycles, on top of the conditions and warm planners every
//! live session switches between ([`LiveConditions`]).

use std::ops::{Deref, DerefMut};

use anyhow::Result;
use vitreous_render::Reflection;

use vitreous_frames::conditions::LiveConditions;
use vitreous_frames::look::{DefocusModel, LookPlanner};
use vitreous_gaze::{FilterKind, GazeConfig, GazeOverride};
use vitreous_scene::effects::EffectSet;

/// The conditions keys 1-7 choose: none (O2, a), O3, O4, O5, b, c, and the inducer alone
/// (disparity, defocus and caustics alone are O4, O3 and b).
pub const CONDITION_KEYS: [&str; 7] = ["none", "O3", "O4", "O5", "b", "c", "inducer"];

/// The gaze filters G steps through.
pub const FILTERS: [&str; 5] = ["evidence", "fixation", "mean20", "median20", "one-euro"];

/// The viewer's conditions: those of the keys, by index of [`CONDITION_KEYS`] (the ones this
/// build or scene cannot show held as gaps), and the settings their planners are made with.
/// Derefs to the [`LiveConditions`] they are.
pub struct ViewConditions {
    /// The conditions and their planners.
    looks: LiveConditions,
    /// The scene's numbers for eq. 13-14, when any condition has defocus.
    model: Option<DefocusModel>,
    /// How the reflected image is drawn.
    reflection: Reflection,
    /// The gaze filter.
    filter: FilterKind,
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
                (s.ensure_implemented().is_ok() && (!s.caustics || caustics_loaded)).then(|| {
                    let planner = planner(s, model.as_ref(), reflection, filter, gaze);
                    (s, planner)
                })
            })
            .collect();
        ViewConditions {
            looks: LiveConditions::with_gaps(conditions, current, gaze),
            model,
            reflection,
            filter,
        }
    }

    /// New planners for the current settings (gaze history starts over).
    fn rebuild(&mut self) {
        let (model, reflection, filter) = (self.model.as_ref(), self.reflection, self.filter);
        let gaze = self.looks.gaze();
        self.looks
            .replan(|set| planner(set, model, reflection, filter, gaze));
    }

    /// The gaze filter, reflection and forced gaze image, for the overlay.
    pub fn settings(&self) -> (FilterKind, Reflection, GazeOverride) {
        (self.filter, self.reflection, self.looks.gaze())
    }

    /// Shows condition `index` of [`CONDITION_KEYS`]; says what happened.
    pub fn choose(&mut self, index: usize) -> String {
        if index >= self.looks.len() {
            return "no such condition".into();
        }
        match self.looks.get(index) {
            Some(set) => {
                self.looks.select(index);
                format!("effects now {set}")
            }
            None => format!(
                "condition {} is not available here (not implemented, or no caustic bake for \
                 the scene)",
                CONDITION_KEYS[index]
            ),
        }
    }

    /// The next available condition.
    pub fn next(&mut self) -> String {
        match self.looks.step() {
            Some(set) => format!("effects now {set}"),
            None => self.choose(self.looks.current()),
        }
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

    /// The next forced gaze image (auto, surface, refracted).
    pub fn next_gaze(&mut self) -> String {
        format!("gaze image forced: {}", self.looks.cycle_gaze())
    }
}

impl Deref for ViewConditions {
    type Target = LiveConditions;

    fn deref(&self) -> &LiveConditions {
        &self.looks
    }
}

impl DerefMut for ViewConditions {
    fn deref_mut(&mut self) -> &mut LiveConditions {
        &mut self.looks
    }
}

/// The planner of condition `set` with the viewer's settings.
fn planner(
    set: EffectSet,
    model: Option<&DefocusModel>,
    reflection: Reflection,
    filter: FilterKind,
    gaze: GazeOverride,
) -> LookPlanner {
    let defocus = match (set.defocus, model) {
        (true, Some(model)) => {
            let mut config = GazeConfig::new(model.distances);
            config.filter = filter;
            config.override_image = gaze;
            Some((config, model.clone()))
        }
        _ => None,
    };
    LookPlanner::new(vitreous_frames::look::base_look(&set, reflection), defocus)
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
