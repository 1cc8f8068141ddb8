//! Simulated controller buttons (`VITREOUS_SIM_BUTTONS`): a script of presses and releases
//! on the inputs of one interaction profile, answered through `xrGetActionStateBoolean` for
//! the actions the app bound to those inputs, on the session's display clock. A runtime
//! without controllers (Monado's simulated HMD) then drives an app's controller path.
//!
//! The script, one event a line (`#` starts a comment):
//!
//! ```text
//! profile /interaction_profiles/htc/vive_controller
//! # seconds after the first frame's predicted display time, input path, down or up
//! 1.0  /user/hand/left/input/squeeze/click  down
//! 1.5  /user/hand/left/input/trigger/click  down
//! 1.8  /user/hand/left/input/trigger/click  up
//! ```
//!
//! The `profile` line comes first; times do not go back; every input path starts with a
//! `/user/hand/left` or `/user/hand/right` path and names one of the profile's inputs as the
//! app binds it (only the inputs the app binds in that profile are answered).

use std::fmt;

use openxr::sys;

/// The user paths a scripted input may belong to.
pub const HANDS: [&str; 2] = ["/user/hand/left", "/user/hand/right"];

/// A button script with its paths resolved in an instance.
#[derive(Clone, Debug)]
pub struct Buttons {
    /// The script.
    pub script: ButtonScript,
    /// Its profile's path.
    pub profile: sys::Path,
    /// Its inputs' paths, in [`ButtonScript::inputs`] order.
    pub inputs: Vec<sys::Path>,
    /// The paths of [`HANDS`].
    pub hands: [sys::Path; 2],
}

impl Buttons {
    /// The scripted inputs among suggested `bindings` of `profile`: (action, input index)
    /// for each binding of the script's profile to one of its inputs.
    pub fn bound(
        &self,
        profile: sys::Path,
        bindings: &[sys::ActionSuggestedBinding],
    ) -> Vec<(sys::Action, usize)> {
        if profile != self.profile {
            return Vec::new();
        }
        bindings
            .iter()
            .filter_map(|b| {
                let input = self.inputs.iter().position(|&p| p == b.binding)?;
                Some((b.action, input))
            })
            .collect()
    }

    /// The input among `inputs` (bound to one action) that a state request for
    /// `subaction` reads: the one of that hand, or for no hand (NULL path) the first.
    pub fn input_for(&self, inputs: &[usize], subaction: sys::Path) -> Option<usize> {
        inputs.iter().copied().find(|&k| {
            subaction == sys::Path::NULL || self.hands[self.script.hand_of(k)] == subaction
        })
    }
}

/// A parsed button script.
#[derive(Clone, Debug, PartialEq)]
pub struct ButtonScript {
    /// The interaction profile the inputs belong to.
    pub profile: String,
    /// The distinct input paths, in order of first use.
    pub inputs: Vec<String>,
    /// Per input: (seconds, down) in time order.
    pub events: Vec<Vec<(f64, bool)>>,
}

/// What is wrong with a script line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScriptError {
    /// 1-based line number.
    pub line: usize,
    /// What was expected.
    pub message: String,
}

impl fmt::Display for ScriptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

impl ButtonScript {
    /// Parses a script (see the module docs).
    pub fn parse(text: &str) -> Result<ButtonScript, ScriptError> {
        let mut script = ButtonScript {
            profile: String::new(),
            inputs: Vec::new(),
            events: Vec::new(),
        };
        let mut last_time = f64::NEG_INFINITY;
        for (i, raw) in text.lines().enumerate() {
            let fail = |message: String| ScriptError {
                line: i + 1,
                message,
            };
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let words: Vec<&str> = line.split_whitespace().collect();
            if script.profile.is_empty() {
                match words.as_slice() {
                    ["profile", path] if path.starts_with("/interaction_profiles/") => {
                        script.profile = (*path).to_owned();
                        continue;
                    }
                    _ => {
                        return Err(fail(
                            "expected `profile /interaction_profiles/...` first".into(),
                        ));
                    }
                }
            }
            let [time, path, state] = words.as_slice() else {
                return Err(fail(format!(
                    "expected `SECONDS INPUT_PATH down|up`, got `{line}`"
                )));
            };
            let time: f64 = time
                .parse()
                .ok()
                .filter(|t: &f64| t.is_finite() && *t >= 0.0)
                .ok_or_else(|| fail(format!("expected seconds >= 0, got `{time}`")))?;
            if time < last_time {
                return Err(fail(format!(
                    "time {time} s goes back (the line before: {last_time} s)"
                )));
            }
            last_time = time;
            if !HANDS.iter().any(|h| {
                path.strip_prefix(h)
                    .is_some_and(|r| r.starts_with("/input/"))
            }) {
                return Err(fail(format!(
                    "expected an input of /user/hand/left or /user/hand/right, got `{path}`"
                )));
            }
            let down = match *state {
                "down" => true,
                "up" => false,
                other => return Err(fail(format!("expected down or up, got `{other}`"))),
            };
            let index = match script.inputs.iter().position(|p| p == path) {
                Some(k) => k,
                None => {
                    script.inputs.push((*path).to_owned());
                    script.events.push(Vec::new());
                    script.inputs.len() - 1
                }
            };
            script.events[index].push((time, down));
        }
        if script.profile.is_empty() {
            return Err(ScriptError {
                line: text.lines().count().max(1),
                message: "no `profile` line".into(),
            });
        }
        Ok(script)
    }

    /// The hand (index into [`HANDS`]) of input `input`.
    pub fn hand_of(&self, input: usize) -> usize {
        usize::from(self.inputs[input].starts_with(HANDS[1]))
    }

    /// Input `input` at `t_s` seconds: down or not, and when it last changed (seconds; None
    /// before its first event).
    pub fn state_at(&self, input: usize, t_s: f64) -> (bool, Option<f64>) {
        self.events[input]
            .iter()
            .take_while(|(t, _)| *t <= t_s)
            .fold((false, None), |(down, since), &(t, d)| {
                if d == down {
                    (down, since)
                } else {
                    (d, Some(t))
                }
            })
    }

    /// What `xrGetActionStateBoolean` reports for input `input` after the sync at `now_s`,
    /// the one before it having been at `previous_s` (None: this is the first): down now,
    /// changed since the previous sync, and when it last changed.
    pub fn boolean_state(
        &self,
        input: usize,
        now_s: f64,
        previous_s: Option<f64>,
    ) -> (bool, bool, Option<f64>) {
        let (down, since) = self.state_at(input, now_s);
        let before = previous_s.is_some_and(|p| self.state_at(input, p).0);
        (down, down != before, since)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const SCRIPT: &str = "# a chord\nprofile /interaction_profiles/htc/vive_controller\n\
                          1.0 /user/hand/left/input/squeeze/click down\n\
                          1.5 /user/hand/left/input/trigger/click down # press\n\
                          1.8 /user/hand/left/input/trigger/click up\n\
                          3.0 /user/hand/left/input/squeeze/click up\n";

    #[test]
    fn a_script_gives_each_input_its_presses_on_the_clock() {
        let s = ButtonScript::parse(SCRIPT).unwrap();
        assert_eq!(s.profile, "/interaction_profiles/htc/vive_controller");
        assert_eq!(s.inputs.len(), 2);
        assert_eq!(s.hand_of(0), 0);
        assert_eq!(s.state_at(0, 0.5), (false, None));
        assert_eq!(s.state_at(0, 2.0), (true, Some(1.0)));
        assert_eq!(s.state_at(0, 3.5), (false, Some(3.0)));
        // A press between two syncs: down and changed at the first sync after it, then held.
        assert_eq!(
            s.boolean_state(1, 1.55, Some(1.45)),
            (true, true, Some(1.5))
        );
        assert_eq!(
            s.boolean_state(1, 1.65, Some(1.55)),
            (true, false, Some(1.5))
        );
        assert_eq!(
            s.boolean_state(1, 1.85, Some(1.75)),
            (false, true, Some(1.8))
        );
        // The first sync compares with up.
        assert_eq!(s.boolean_state(0, 2.0, None), (true, true, Some(1.0)));
    }

    #[test]
    fn bad_lines_are_refused_with_their_number() {
        let profile = "profile /interaction_profiles/htc/vive_controller\n";
        for (text, line, says) in [
            ("1.0 /user/hand/left/input/a/click down\n", 1, "profile"),
            ("profile vive\n", 1, "profile"),
            ("", 1, "no `profile` line"),
        ] {
            let e = ButtonScript::parse(text).unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e}");
            assert!(e.message.contains(says), "{text:?}: {e}");
        }
        for (body, says) in [
            ("1.0 /user/hand/left/input/a/click\n", "SECONDS INPUT_PATH"),
            ("x /user/hand/left/input/a/click down\n", "seconds"),
            ("-1 /user/hand/left/input/a/click down\n", "seconds"),
            ("NaN /user/hand/left/input/a/click down\n", "seconds"),
            ("1 /user/head/input/a/click down\n", "/user/hand/left"),
            ("1 /user/hand/left/input/a/click pressed\n", "down or up"),
            (
                "2 /user/hand/left/input/a/click down\n1 /user/hand/left/input/a/click up\n",
                "goes back",
            ),
        ] {
            let e = ButtonScript::parse(&format!("{profile}{body}")).unwrap_err();
            assert!(e.line >= 2 && e.message.contains(says), "{body:?}: {e}");
        }
    }

    proptest! {
        /// Any text is parsed or refused with a line in it, never a panic; what is parsed
        /// keeps each input's events in time order and answers any time.
        #[test]
        fn any_text_is_parsed_or_refused_with_a_line(
            lines in proptest::collection::vec(
                prop_oneof![
                    Just("profile /interaction_profiles/htc/vive_controller".to_string()),
                    (0.0f64..10.0, 0usize..3, any::<bool>()).prop_map(|(t, k, d)| format!(
                        "{t} /user/hand/{}/input/b{k}/click {}",
                        if k == 0 { "left" } else { "right" },
                        if d { "down" } else { "up" }
                    )),
                    "[ -~]{0,40}",
                ],
                0..12,
            ),
            at in 0.0f64..12.0,
        ) {
            let text = lines.join("\n");
            match ButtonScript::parse(&text) {
                Ok(s) => {
                    for (k, events) in s.events.iter().enumerate() {
                        prop_assert!(events.windows(2).all(|w| w[0].0 <= w[1].0));
                        let (_, since) = s.state_at(k, at);
                        prop_assert!(since.is_none_or(|t| t <= at));
                    }
                }
                Err(e) => prop_assert!(e.line >= 1 && e.line <= lines.len().max(1)),
            }
        }
    }
}
