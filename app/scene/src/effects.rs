//! Which of the paper's perception-based effects are switched on.
//!
//! An [`EffectSet`] is parsed from a comma-separated list of effect names, of the paper's
//! study-condition names, or of both (case-insensitive). The scene file's `[effects] set` and
//! the command line use the same parser. Parsing never refuses an effect because this build
//! does not implement it yet, so scenes can be written ahead of the features; the CLI calls
//! [`EffectSet::ensure_implemented`] before rendering.

use std::fmt;
use std::str::FromStr;

/// A set of switches, one per perception-based effect. All off is the paper's baseline
/// ("conventional method": environment map + Fresnel).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct EffectSet {
    /// Per-eye refraction disparity (Sec. 5.1.1, eq. 7-8).
    pub disparity: bool,
    /// Gaze-dependent defocus of the image not looked at (Sec. 5.1.2, eq. 9-14).
    pub defocus: bool,
    /// Shadow inducer: brighten the floor around the shadow (Sec. 3.1.1, eq. 1-5).
    pub inducer: bool,
    /// Caustics overlay corrected for the real floor (Sec. 3.1.2, eq. 6).
    pub caustics: bool,
}

/// Why an effect list was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EffectError {
    /// A name that is neither an effect nor a study condition.
    #[error("unknown effect '{name}'; expected a comma-separated list of: {valid}")]
    Unknown {
        /// The name as written.
        name: String,
        /// The accepted names, comma-separated.
        valid: &'static str,
    },
    /// The list (or one of its comma-separated items) is empty.
    #[error("empty effect name in '{list}'; write 'none' for the baseline method")]
    Empty {
        /// The whole list as written.
        list: String,
    },
    /// A name meaning "no effect" (`none`, `O2`, `a`) was combined with other names.
    #[error("'{name}' means no effect and cannot be combined with other effects in '{list}'")]
    NoneCombined {
        /// The "no effect" name as written.
        name: String,
        /// The whole list as written.
        list: String,
    },
    /// Switches that this build cannot render yet.
    #[error("{}", not_implemented_message(.effects))]
    NotImplemented {
        /// Canonical names of the refused switches, in canonical order.
        effects: Vec<&'static str>,
    },
}

fn not_implemented_message(effects: &[&'static str]) -> String {
    let quoted: Vec<String> = effects.iter().map(|e| format!("'{e}'")).collect();
    if quoted.len() == 1 {
        format!("effect {} is not implemented yet in this build", quoted[0])
    } else {
        format!(
            "effects {} are not implemented yet in this build",
            quoted.join(", ")
        )
    }
}

/// Every accepted name, as listed in error messages.
const VALID_NAMES: &str = "none, disparity, defocus, inducer, caustics, all, \
     O2 (none), O3 (defocus), O4 (disparity), O5 (disparity+defocus), \
     a (none), b (caustics), c (inducer+caustics)";

impl EffectSet {
    /// The baseline: no perception-based effect.
    pub const NONE: EffectSet = EffectSet {
        disparity: false,
        defocus: false,
        inducer: false,
        caustics: false,
    };

    /// Every effect.
    pub const ALL: EffectSet = EffectSet {
        disparity: true,
        defocus: true,
        inducer: true,
        caustics: true,
    };

    /// The switches this build can render. Grows as effects land.
    pub const IMPLEMENTED: EffectSet = EffectSet {
        disparity: true,
        defocus: true,
        inducer: true,
        caustics: true,
    };

    /// Parses a comma-separated, case-insensitive list of names: `none`, `disparity`,
    /// `defocus`, `inducer`, `caustics`, `all`, and the paper's conditions `O2` (none),
    /// `O3` (defocus), `O4` (disparity), `O5` (disparity + defocus), `a` (none),
    /// `b` (caustics), `c` (inducer + caustics). Items are combined by union; a "no effect"
    /// name cannot be combined with others.
    pub fn parse(list: &str) -> Result<EffectSet, EffectError> {
        let mut set = EffectSet::NONE;
        let mut none_name: Option<&str> = None;
        let mut count = 0usize;
        for raw in list.split(',') {
            let name = raw.trim();
            if name.is_empty() {
                return Err(EffectError::Empty {
                    list: list.to_owned(),
                });
            }
            count += 1;
            let item = Self::parse_one(name).ok_or_else(|| EffectError::Unknown {
                name: name.to_owned(),
                valid: VALID_NAMES,
            })?;
            if item == EffectSet::NONE {
                none_name = Some(name);
            }
            set = set.union(item);
        }
        if let Some(name) = none_name
            && count > 1
        {
            return Err(EffectError::NoneCombined {
                name: name.to_owned(),
                list: list.to_owned(),
            });
        }
        Ok(set)
    }

    fn parse_one(name: &str) -> Option<EffectSet> {
        let on = |disparity, defocus, inducer, caustics| EffectSet {
            disparity,
            defocus,
            inducer,
            caustics,
        };
        Some(match name.to_ascii_lowercase().as_str() {
            "none" | "o2" | "a" => EffectSet::NONE,
            "all" => EffectSet::ALL,
            "disparity" | "o4" => on(true, false, false, false),
            "defocus" | "o3" => on(false, true, false, false),
            "o5" => on(true, true, false, false),
            "inducer" => on(false, false, true, false),
            "caustics" | "b" => on(false, false, false, true),
            "c" => on(false, false, true, true),
            _ => return None,
        })
    }

    /// The switches on in either set.
    pub fn union(self, other: EffectSet) -> EffectSet {
        EffectSet {
            disparity: self.disparity || other.disparity,
            defocus: self.defocus || other.defocus,
            inducer: self.inducer || other.inducer,
            caustics: self.caustics || other.caustics,
        }
    }

    /// True when no effect is on (the baseline method).
    pub fn is_none(self) -> bool {
        self == EffectSet::NONE
    }

    /// Canonical names of the switches that are on, in canonical order
    /// (disparity, defocus, inducer, caustics).
    pub fn names(self) -> Vec<&'static str> {
        [
            (self.disparity, "disparity"),
            (self.defocus, "defocus"),
            (self.inducer, "inducer"),
            (self.caustics, "caustics"),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .collect()
    }

    /// Refuses any switch that this build does not implement yet (see
    /// [`EffectSet::IMPLEMENTED`]), naming each one.
    pub fn ensure_implemented(&self) -> Result<(), EffectError> {
        let missing = EffectSet {
            disparity: self.disparity && !Self::IMPLEMENTED.disparity,
            defocus: self.defocus && !Self::IMPLEMENTED.defocus,
            inducer: self.inducer && !Self::IMPLEMENTED.inducer,
            caustics: self.caustics && !Self::IMPLEMENTED.caustics,
        };
        if missing.is_none() {
            Ok(())
        } else {
            Err(EffectError::NotImplemented {
                effects: missing.names(),
            })
        }
    }
}

/// The canonical name: `none`, `all`, or the switches that are on joined by commas in
/// canonical order (`disparity,defocus`). [`EffectSet::parse`] reads it back.
impl fmt::Display for EffectSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_none() {
            f.write_str("none")
        } else if *self == EffectSet::ALL {
            f.write_str("all")
        } else {
            f.write_str(&self.names().join(","))
        }
    }
}

impl FromStr for EffectSet {
    type Err = EffectError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        EffectSet::parse(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(disparity: bool, defocus: bool, inducer: bool, caustics: bool) -> EffectSet {
        EffectSet {
            disparity,
            defocus,
            inducer,
            caustics,
        }
    }

    #[test]
    fn plain_names_parse_to_single_switches() {
        assert_eq!(EffectSet::parse("none").unwrap(), EffectSet::NONE);
        assert_eq!(
            EffectSet::parse("disparity").unwrap(),
            set(true, false, false, false)
        );
        assert_eq!(
            EffectSet::parse("defocus").unwrap(),
            set(false, true, false, false)
        );
        assert_eq!(
            EffectSet::parse("inducer").unwrap(),
            set(false, false, true, false)
        );
        assert_eq!(
            EffectSet::parse("caustics").unwrap(),
            set(false, false, false, true)
        );
        assert_eq!(EffectSet::parse("all").unwrap(), EffectSet::ALL);
    }

    #[test]
    fn study_conditions_are_aliases() {
        assert_eq!(EffectSet::parse("O2").unwrap(), EffectSet::NONE);
        assert_eq!(
            EffectSet::parse("O3").unwrap(),
            set(false, true, false, false)
        );
        assert_eq!(
            EffectSet::parse("O4").unwrap(),
            set(true, false, false, false)
        );
        assert_eq!(
            EffectSet::parse("o5").unwrap(),
            set(true, true, false, false)
        );
        assert_eq!(EffectSet::parse("a").unwrap(), EffectSet::NONE);
        assert_eq!(
            EffectSet::parse("B").unwrap(),
            set(false, false, false, true)
        );
        assert_eq!(
            EffectSet::parse("c").unwrap(),
            set(false, false, true, true)
        );
    }

    #[test]
    fn lists_are_unions_case_insensitive_and_trimmed() {
        assert_eq!(
            EffectSet::parse(" Disparity , DEFOCUS ").unwrap(),
            EffectSet::parse("O5").unwrap()
        );
        assert_eq!(
            EffectSet::parse("c,disparity,defocus").unwrap(),
            EffectSet::ALL
        );
        assert_eq!(
            EffectSet::parse("caustics,caustics").unwrap(),
            set(false, false, false, true)
        );
    }

    #[test]
    fn unknown_name_lists_valid_names() {
        let err = EffectSet::parse("disparity,blur").unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("'blur'"), "{msg}");
        for name in [
            "none",
            "disparity",
            "defocus",
            "inducer",
            "caustics",
            "all",
            "O5",
        ] {
            assert!(msg.contains(name), "{msg} lacks {name}");
        }
    }

    #[test]
    fn empty_items_and_combined_none_are_refused() {
        assert!(matches!(
            EffectSet::parse(""),
            Err(EffectError::Empty { .. })
        ));
        assert!(matches!(
            EffectSet::parse("disparity,,defocus"),
            Err(EffectError::Empty { .. })
        ));
        assert!(matches!(
            EffectSet::parse("none,disparity"),
            Err(EffectError::NoneCombined { .. })
        ));
        assert!(matches!(
            EffectSet::parse("O3,a"),
            Err(EffectError::NoneCombined { .. })
        ));
    }

    #[test]
    fn display_is_canonical_and_round_trips() {
        assert_eq!(EffectSet::NONE.to_string(), "none");
        assert_eq!(EffectSet::ALL.to_string(), "all");
        assert_eq!(
            EffectSet::parse("defocus,disparity").unwrap().to_string(),
            "disparity,defocus"
        );
        for bits in 0u8..16 {
            let s = set(bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0);
            assert_eq!(EffectSet::parse(&s.to_string()).unwrap(), s, "{s}");
            assert_eq!(s.to_string().parse::<EffectSet>().unwrap(), s);
        }
    }

    #[test]
    fn unimplemented_switches_are_named() {
        assert!(EffectSet::NONE.ensure_implemented().is_ok());
        assert!(EffectSet::IMPLEMENTED.ensure_implemented().is_ok());
        if !EffectSet::IMPLEMENTED.disparity {
            let err = set(true, false, false, false)
                .ensure_implemented()
                .unwrap_err();
            assert_eq!(
                err.to_string(),
                "effect 'disparity' is not implemented yet in this build"
            );
        }
        let missing = EffectSet::ALL.names().len() - EffectSet::IMPLEMENTED.names().len();
        match EffectSet::ALL.ensure_implemented() {
            Ok(()) => assert_eq!(missing, 0),
            Err(EffectError::NotImplemented { effects }) => assert_eq!(effects.len(), missing),
            Err(other) => panic!("unexpected error {other}"),
        }
    }
}
