//! Scripted input (`--script FILE`): events at given frames, so tests can drive the viewer.
//!
//! One event a line, `FRAME EVENT ARGS...`; `#` starts a comment. The events of frame N are
//! applied before frame N is drawn, in file order. Events (docs/view.md):
//!
//! - `key NAME`: press and release a key (`key 3`, `key f1`, `key space`);
//! - `down NAME` / `up NAME`: hold a key (movement) and let it go;
//! - `move X Y`: the cursor to fractions of the window's width and height from the top left;
//! - `press BUTTON` / `release BUTTON` / `click BUTTON`: `left`, `right` or `middle`;
//! - `wheel N`: turn the wheel N notches;
//! - `copy FROM TO`: copy a file over another (paths relative to the script's folder), e.g. to
//!   edit the scene and see it reload;
//! - `resize W H`: ask for a window of W x H pixels;
//! - `minimise` / `restore`: ask the window manager or compositor to minimise the window and
//!   to bring it back (a Wayland client cannot bring back a window itself).

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::input::InputEvent;

/// One scripted step.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// An input event.
    Input(InputEvent),
    /// Ask for a new window size, pixels.
    Resize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// Ask for the window to be minimised (true) or brought back (false).
    Minimise(bool),
    /// Copy a file over another.
    Copy {
        /// The file copied.
        from: PathBuf,
        /// The file replaced.
        to: PathBuf,
    },
}

/// A script: steps in frame order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    /// (frame, step), sorted by frame, file order kept within a frame.
    steps: Vec<(u64, Step)>,
    /// Index of the first step not yet handed out.
    next: usize,
}

/// Why a script was refused.
#[derive(Debug, Error)]
pub enum ScriptError {
    /// The file could not be read.
    #[error("reading script {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A line is not an event.
    #[error("{path}:{line}: {reason}")]
    Line {
        /// The file.
        path: String,
        /// Line number, from 1.
        line: usize,
        /// What was expected.
        reason: String,
    },
}

impl Script {
    /// Reads a script; relative paths of `copy` are taken from the script's folder.
    pub fn load(path: &Path) -> Result<Script, ScriptError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScriptError::Read {
            path: path.display().to_string(),
            source,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Script::parse(&text, base).map_err(|(line, reason)| ScriptError::Line {
            path: path.display().to_string(),
            line,
            reason,
        })
    }

    /// Parses script text; errors give the line number and the reason.
    pub fn parse(text: &str, base: &Path) -> Result<Script, (usize, String)> {
        let mut steps = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let words: Vec<&str> = line.split_whitespace().collect();
            let frame: u64 = words[0].parse().map_err(|_| {
                (
                    i + 1,
                    format!("expected a frame number first, got '{}'", words[0]),
                )
            })?;
            let args = &words[2.min(words.len())..];
            let want = |n: usize, usage: &str| {
                if args.len() == n {
                    Ok(())
                } else {
                    Err((i + 1, format!("expected '{usage}'")))
                }
            };
            let fraction = |s: &str| {
                s.parse::<f32>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or_else(|| (i + 1, format!("expected a fraction 0..1, got '{s}'")))
            };
            let button = |s: &str| match s {
                "left" | "right" | "middle" => Ok(s.to_string()),
                _ => Err((i + 1, format!("expected left, right or middle, got '{s}'"))),
            };
            let key = |name: &str, pressed| {
                Step::Input(InputEvent::Key {
                    name: name.to_lowercase(),
                    pressed,
                })
            };
            let click = |name: String, pressed| Step::Input(InputEvent::Button { name, pressed });
            let event = words.get(1).copied().unwrap_or("");
            match event {
                "key" => {
                    want(1, "FRAME key NAME")?;
                    steps.push((frame, key(args[0], true)));
                    steps.push((frame, key(args[0], false)));
                }
                "down" | "up" => {
                    want(1, "FRAME down|up NAME")?;
                    steps.push((frame, key(args[0], event == "down")));
                }
                "move" => {
                    want(2, "FRAME move X Y")?;
                    let (x, y) = (fraction(args[0])?, fraction(args[1])?);
                    steps.push((frame, Step::Input(InputEvent::Cursor { x, y })));
                }
                "press" | "release" => {
                    want(1, "FRAME press|release BUTTON")?;
                    steps.push((frame, click(button(args[0])?, event == "press")));
                }
                "click" => {
                    want(1, "FRAME click BUTTON")?;
                    steps.push((frame, click(button(args[0])?, true)));
                    steps.push((frame, click(button(args[0])?, false)));
                }
                "wheel" => {
                    want(1, "FRAME wheel N")?;
                    let n = args[0]
                        .parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| (i + 1, format!("expected notches, got '{}'", args[0])))?;
                    steps.push((frame, Step::Input(InputEvent::Wheel(n))));
                }
                "resize" => {
                    want(2, "FRAME resize W H")?;
                    let px = |s: &str| {
                        s.parse::<u32>()
                            .ok()
                            .filter(|v| (64..=8192).contains(v))
                            .ok_or_else(|| (i + 1, format!("expected 64..8192 pixels, got '{s}'")))
                    };
                    let (width, height) = (px(args[0])?, px(args[1])?);
                    steps.push((frame, Step::Resize { width, height }));
                }
                "minimise" | "restore" => {
                    want(0, "FRAME minimise (or restore)")?;
                    steps.push((frame, Step::Minimise(event == "minimise")));
                }
                "copy" => {
                    want(2, "FRAME copy FROM TO")?;
                    steps.push((
                        frame,
                        Step::Copy {
                            from: base.join(args[0]),
                            to: base.join(args[1]),
                        },
                    ));
                }
                other => {
                    return Err((
                        i + 1,
                        format!(
                            "unknown event '{other}'; expected key, down, up, move, press, \
                             release, click, wheel, resize, minimise, restore or copy"
                        ),
                    ));
                }
            }
        }
        steps.sort_by_key(|(frame, _)| *frame);
        Ok(Script { steps, next: 0 })
    }

    /// The steps of frames up to and including `frame` not yet handed out.
    pub fn due(&mut self, frame: u64) -> Vec<Step> {
        let mut out = Vec::new();
        while let Some((f, step)) = self.steps.get(self.next) {
            if *f > frame {
                break;
            }
            out.push(step.clone());
            self.next += 1;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_come_out_at_their_frame_in_file_order() {
        let text = "# a comment\n5 key 3\n2 move 0.5 0.25\n5 wheel -1 # back\n\
                    9 copy a.toml b.toml\n12 resize 400 300\n13 minimise\n14 restore\n";
        let mut s = Script::parse(text, Path::new("/s")).unwrap();
        assert!(s.due(1).is_empty());
        assert_eq!(
            s.due(2),
            [Step::Input(InputEvent::Cursor { x: 0.5, y: 0.25 })]
        );
        let at5 = s.due(5);
        assert_eq!(at5.len(), 3, "press, release, wheel: {at5:?}");
        assert_eq!(at5[2], Step::Input(InputEvent::Wheel(-1.0)));
        assert_eq!(
            s.due(100),
            [
                Step::Copy {
                    from: PathBuf::from("/s/a.toml"),
                    to: PathBuf::from("/s/b.toml"),
                },
                Step::Resize {
                    width: 400,
                    height: 300
                },
                Step::Minimise(true),
                Step::Minimise(false),
            ]
        );
    }

    #[test]
    fn bad_lines_are_refused_with_their_number() {
        for (text, line, says) in [
            ("1 key\n", 1, "FRAME key NAME"),
            ("\nx key a\n", 2, "frame number"),
            ("1 move 2 0\n", 1, "fraction"),
            ("1 click thumb\n", 1, "left, right or middle"),
            ("1 jump\n", 1, "unknown event 'jump'"),
            ("1 minimise now\n", 1, "FRAME minimise"),
            ("1 resize 10 300\n", 1, "64..8192"),
        ] {
            let (l, reason) = Script::parse(text, Path::new(".")).unwrap_err();
            assert_eq!(l, line, "{text}");
            assert!(reason.contains(says), "{text}: {reason}");
        }
    }
}
