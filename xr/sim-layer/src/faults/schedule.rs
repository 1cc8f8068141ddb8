//! The fault schedule (`VITREOUS_SIM_FAULTS`): which misbehaviour of a real headset the layer
//! injects, and when. One fault a line, `WHEN FAULT [ARGUMENTS]`, `#` starts a comment:
//!
//! ```text
//! frame 40  headset-off 3          # the wearer takes the headset off for 3 s
//! frame 120 menu 30                # a system menu takes the input focus for 30 frames
//! at 9.5    session-loss 2         # the session is lost; the headset is gone for 2 s
//! frame 400 instance-loss 2        # the runtime goes away for 2 s
//! frame 470 recentre               # the wearer recentres (reference space change)
//! frame 500 no-render 20           # shouldRender = false for 20 frames
//! frame 540 late 4                 # the app's next frame comes 4 display periods late
//! frame 560 image-timeout 2        # 2 swapchain image waits time out
//! frame 580 runtime-failure xrLocateViews   # one call fails with XR_ERROR_RUNTIME_FAILURE
//! frame 600 tracking-lost 20 10    # head position lost for 20 frames, then orientation for 10
//! frame 650 unusable-pose 5        # 5 frames of head poses marked valid holding NaN and zeros
//! frame 670 zero-fov 2             # 2 frames whose views' fields of view are four zeros
//! frame 700 gaze-dropout 2 invalid # the eye tracker drops out for 2 s (none, invalid or low)
//! frame 715 gaze-clock 1 20        # for 1 s the eye tracker stamps its samples 20 ms ahead
//! frame 730 bad-time 3 negative    # 3 frames at a negative display time (or repeat, or ahead)
//! frame 760 eyes 58 2              # the eyes from now on 58 mm apart, each turned 2 degrees out
//! chaos 7 2000                     # a random schedule of every fault over 2000 frames (seed 7)
//! ```
//!
//! `frame N` is the app's `N`-th `xrWaitFrame` in the process (from 0, across sessions and
//! instances); `at S` is `S` seconds of display time after the first frame's. `chaos SEED FRAMES`
//! stands for the schedule [`chaos`] draws from the seed: every fault family at least once,
//! spaced so the session recovers between them.

use std::fmt;

use vitreous_trace::synth::SplitMix64;

use crate::config::SimViews;

/// When a fault starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Trigger {
    /// At the app's `N`-th `xrWaitFrame` of the process (from 0).
    Frame(u64),
    /// This many seconds of display time after the process's first frame.
    At(f64),
}

/// How the eye tracker drops out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dropout {
    /// No new sample: the trackers keep answering with the last sample before the dropout
    /// (its time stamp stays).
    None,
    /// Samples with no valid eye, combined ray, fixation or pupil.
    Invalid,
    /// Samples as usual, but with LOW confidence (XR_ML_eye_tracker's fixation; gaze
    /// confidence 0.1 for XR_FB_eye_tracking_social).
    Low,
}

impl Dropout {
    /// The word the schedule uses.
    pub fn name(self) -> &'static str {
        match self {
            Dropout::None => "none",
            Dropout::Invalid => "invalid",
            Dropout::Low => "low",
        }
    }
}

/// What a runtime's clock does wrong in a bad-time fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BadTime {
    /// `xrWaitFrame` succeeds with a negative predicted display time, and `xrEndFrame` with it
    /// fails with `XR_ERROR_TIME_INVALID` (as a SteamVR release did).
    Negative,
    /// `xrWaitFrame` predicts the same display time as the frame before.
    Repeat,
    /// `xrWaitFrame` predicts a display time 27.6 days ahead of the true one (as a streaming
    /// runtime's pacer did after a refocus); `xrEndFrame` at it succeeds.
    Ahead,
}

impl BadTime {
    /// How far ahead an `Ahead` time is, nanoseconds: 27.6 days.
    pub const AHEAD_NS: i64 = 2_384_640_000_000_000;
}

impl BadTime {
    /// The word the schedule uses.
    pub fn name(self) -> &'static str {
        match self {
            BadTime::Negative => "negative",
            BadTime::Repeat => "repeat",
            BadTime::Ahead => "ahead",
        }
    }
}

/// A call the layer can make fail once with `XR_ERROR_RUNTIME_FAILURE`: the calls an app makes
/// between `xrBeginFrame` and `xrEndFrame` (and `xrEndFrame` itself).
pub const FAILING_CALLS: [&str; 7] = [
    "xrLocateViews",
    "xrLocateSpace",
    "xrAcquireSwapchainImage",
    "xrWaitSwapchainImage",
    "xrReleaseSwapchainImage",
    "xrSyncActions",
    "xrEndFrame",
];

/// One misbehaviour of a real headset.
#[derive(Clone, Debug, PartialEq)]
pub enum Fault {
    /// The wearer takes the headset off: FOCUSED, VISIBLE, SYNCHRONIZED, STOPPING on three
    /// frames; once the app ends the session, IDLE, and READY again after this many seconds.
    HeadsetOff(f64),
    /// A system menu: VISIBLE (no input) for this many frames, then FOCUSED.
    Menu(u64),
    /// `XR_SESSION_STATE_LOSS_PENDING`; every call on the session then fails with
    /// `XR_ERROR_SESSION_LOST` and `xrGetSystem` with `XR_ERROR_FORM_FACTOR_UNAVAILABLE` for this
    /// many seconds.
    SessionLoss(f64),
    /// `XrEventDataInstanceLossPending`; every call on the instance then fails with
    /// `XR_ERROR_INSTANCE_LOST`, and `xrCreateInstance` with `XR_ERROR_RUNTIME_UNAVAILABLE`, then
    /// `XR_ERROR_INITIALIZATION_FAILED`, for this many seconds.
    InstanceLoss(f64),
    /// `XrEventDataReferenceSpaceChangePending` for every LOCAL and STAGE space type the
    /// session made.
    Recentre,
    /// `shouldRender` false for this many frames.
    NoRender(u64),
    /// The app's next frame comes this many display periods late (the layer waits, begins and
    /// ends that many frames with no layers first).
    Late(u64),
    /// This many `xrWaitSwapchainImage` calls time out (`XR_TIMEOUT_EXPIRED`).
    ImageTimeout(u64),
    /// The next call of this name fails with `XR_ERROR_RUNTIME_FAILURE` (one of
    /// [`FAILING_CALLS`]).
    RuntimeFailure(&'static str),
    /// Head tracking lost: the position for this many frames, then the orientation too for
    /// that many.
    TrackingLost(u64, u64),
    /// For this many frames the head's located poses are marked valid but hold nothing
    /// usable: positions not a number, all-zero quaternions.
    UnusablePose(u64),
    /// For this many frames `xrLocateViews` answers every view's field of view as four zero
    /// angles, its poses and flags as they are (a runtime asked before it knows its views).
    ZeroFov(u64),
    /// The eye tracker drops out for this many seconds of display time.
    GazeDropout(f64, Dropout),
    /// For this many seconds of display time the eye tracker's clock runs this many
    /// milliseconds ahead of the runtime's (behind, when negative): every sample is stamped
    /// that much after the time it holds (after the frame's display time, when asked at it;
    /// behind, before samples already handed out).
    GazeClock(f64, i64),
    /// For this many frames `xrWaitFrame` predicts a display time no frame can have.
    BadTime(u64, BadTime),
    /// From now on `xrLocateViews` answers eyes this many millimetres apart, each view turned
    /// this many degrees outwards (a wearer turning the headset's eye distance, or handing the
    /// headset to someone else): as `VITREOUS_SIM_VIEWS`, whose eyes it replaces.
    Eyes(f32, f32),
}

impl Fault {
    /// The fault's family, as the schedule names it.
    pub fn name(&self) -> &'static str {
        match self {
            Fault::HeadsetOff(_) => "headset-off",
            Fault::Menu(_) => "menu",
            Fault::SessionLoss(_) => "session-loss",
            Fault::InstanceLoss(_) => "instance-loss",
            Fault::Recentre => "recentre",
            Fault::NoRender(_) => "no-render",
            Fault::Late(_) => "late",
            Fault::ImageTimeout(_) => "image-timeout",
            Fault::RuntimeFailure(_) => "runtime-failure",
            Fault::TrackingLost(..) => "tracking-lost",
            Fault::UnusablePose(_) => "unusable-pose",
            Fault::ZeroFov(_) => "zero-fov",
            Fault::GazeDropout(..) => "gaze-dropout",
            Fault::GazeClock(..) => "gaze-clock",
            Fault::BadTime(..) => "bad-time",
            Fault::Eyes(..) => "eyes",
        }
    }

    /// Whether the fault walks the session through states the app sees (so it waits until the
    /// session is FOCUSED again after the one before).
    pub fn changes_state(&self) -> bool {
        matches!(
            self,
            Fault::HeadsetOff(_) | Fault::Menu(_) | Fault::SessionLoss(_) | Fault::InstanceLoss(_)
        )
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())?;
        match self {
            Fault::HeadsetOff(s) | Fault::SessionLoss(s) | Fault::InstanceLoss(s) => {
                write!(f, " {s}")
            }
            Fault::Menu(n)
            | Fault::NoRender(n)
            | Fault::Late(n)
            | Fault::ImageTimeout(n)
            | Fault::UnusablePose(n)
            | Fault::ZeroFov(n) => write!(f, " {n}"),
            Fault::RuntimeFailure(call) => write!(f, " {call}"),
            Fault::TrackingLost(p, o) => write!(f, " {p} {o}"),
            Fault::GazeDropout(s, kind) => write!(f, " {s} {}", kind.name()),
            Fault::GazeClock(s, ms) => write!(f, " {s} {ms}"),
            Fault::BadTime(n, kind) => write!(f, " {n} {}", kind.name()),
            Fault::Eyes(ipd, toe) => write!(f, " {ipd} {toe}"),
            Fault::Recentre => Ok(()),
        }
    }
}

/// A fault and when it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Scheduled {
    /// When.
    pub trigger: Trigger,
    /// What.
    pub fault: Fault,
}

impl fmt::Display for Scheduled {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.trigger {
            Trigger::Frame(n) => write!(f, "frame {n} {}", self.fault),
            Trigger::At(s) => write!(f, "at {s} {}", self.fault),
        }
    }
}

/// The longest a fault may keep the headset away, seconds: long enough for any test, short
/// enough that a typo does not hang one.
pub const MAX_SECONDS: f64 = 600.0;
/// The most frames a fault may last.
pub const MAX_FRAMES: u64 = 100_000;

/// A schedule line that does not parse: its number (from 1) and what was expected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScheduleError {
    /// The line, from 1.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ScheduleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Parses a schedule; `chaos` lines are expanded. The faults come out in the order they start
/// (frame triggers by frame, time triggers by time, each kind in file order among equals).
pub fn parse(text: &str) -> Result<Vec<Scheduled>, ScheduleError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let err = |message: String| ScheduleError {
            line: i + 1,
            message,
        };
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["chaos", seed, frames] => {
                let seed = seed
                    .parse::<u64>()
                    .map_err(|_| err(format!("chaos: seed `{seed}` is not a whole number")))?;
                let frames = whole(frames, "chaos: frames", 1, MAX_FRAMES).map_err(err)?;
                out.extend(chaos(seed, frames));
            }
            [when, at, fault @ ..] => {
                let trigger = match *when {
                    "frame" => Trigger::Frame(whole(at, "frame", 0, u64::MAX).map_err(err)?),
                    "at" => Trigger::At(seconds(at, "at", 0.0, 86_400.0).map_err(err)?),
                    other => {
                        return Err(err(format!(
                            "`{other}`: expected `frame N`, `at SECONDS` or `chaos SEED FRAMES`"
                        )));
                    }
                };
                out.push(Scheduled {
                    trigger,
                    fault: fault_of(fault).map_err(err)?,
                });
            }
            _ => {
                return Err(err(
                    "expected `frame N FAULT ...`, `at SECONDS FAULT ...` or `chaos SEED FRAMES`"
                        .into(),
                ));
            }
        }
    }
    out.sort_by(|a, b| match (a.trigger, b.trigger) {
        (Trigger::Frame(x), Trigger::Frame(y)) => x.cmp(&y),
        (Trigger::At(x), Trigger::At(y)) => x.total_cmp(&y),
        (Trigger::Frame(_), Trigger::At(_)) => std::cmp::Ordering::Less,
        (Trigger::At(_), Trigger::Frame(_)) => std::cmp::Ordering::Greater,
    });
    Ok(out)
}

/// A whole number from `low` to `high`.
fn whole(word: &str, what: &str, low: u64, high: u64) -> Result<u64, String> {
    word.parse::<u64>()
        .ok()
        .filter(|n| (low..=high).contains(n))
        .ok_or_else(|| format!("{what}: `{word}` is not a whole number from {low} to {high}"))
}

/// Seconds from `low` to `high`.
fn seconds(word: &str, what: &str, low: f64, high: f64) -> Result<f64, String> {
    word.parse::<f64>()
        .ok()
        .filter(|s| s.is_finite() && (low..=high).contains(s))
        .ok_or_else(|| format!("{what}: `{word}` is not a number of seconds from {low} to {high}"))
}

/// The fault a line's words after its trigger name.
fn fault_of(words: &[&str]) -> Result<Fault, String> {
    let frames = |w: &str, what: &str| whole(w, what, 1, MAX_FRAMES);
    let secs = |w: &str, what: &str| seconds(w, what, 0.0, MAX_SECONDS);
    Ok(match words {
        ["headset-off", s] => Fault::HeadsetOff(secs(s, "headset-off")?),
        ["menu", n] => Fault::Menu(frames(n, "menu")?),
        ["session-loss", s] => Fault::SessionLoss(secs(s, "session-loss")?),
        ["instance-loss", s] => Fault::InstanceLoss(secs(s, "instance-loss")?),
        ["recentre"] => Fault::Recentre,
        ["no-render", n] => Fault::NoRender(frames(n, "no-render")?),
        ["unusable-pose", n] => Fault::UnusablePose(frames(n, "unusable-pose")?),
        ["zero-fov", n] => Fault::ZeroFov(frames(n, "zero-fov")?),
        ["late", n] => Fault::Late(whole(n, "late", 1, 100)?),
        ["image-timeout", n] => Fault::ImageTimeout(whole(n, "image-timeout", 1, 100)?),
        ["runtime-failure", call] => Fault::RuntimeFailure(
            FAILING_CALLS
                .iter()
                .find(|c| *c == call)
                .copied()
                .ok_or_else(|| {
                    format!(
                        "runtime-failure: `{call}` is not one of {}",
                        FAILING_CALLS.join(", ")
                    )
                })?,
        ),
        ["tracking-lost", p, o] => {
            let p = whole(p, "tracking-lost: position frames", 0, MAX_FRAMES)?;
            let o = whole(o, "tracking-lost: orientation frames", 0, MAX_FRAMES)?;
            if p + o == 0 {
                return Err("tracking-lost: no frame lost (both counts 0)".into());
            }
            Fault::TrackingLost(p, o)
        }
        ["gaze-dropout", s, kind] => Fault::GazeDropout(
            seconds(s, "gaze-dropout", 0.001, MAX_SECONDS)?,
            match *kind {
                "none" => Dropout::None,
                "invalid" => Dropout::Invalid,
                "low" => Dropout::Low,
                other => {
                    return Err(format!(
                        "gaze-dropout: `{other}` is not none, invalid or low"
                    ));
                }
            },
        ),
        ["gaze-clock", s, ms] => Fault::GazeClock(
            seconds(s, "gaze-clock", 0.001, MAX_SECONDS)?,
            ms.parse::<i64>()
                .ok()
                .filter(|n| *n != 0 && n.abs() <= 1000)
                .ok_or_else(|| {
                    format!(
                        "gaze-clock: `{ms}` is not a whole number of milliseconds ahead, -1000 \
                         to 1000 and not 0"
                    )
                })?,
        ),
        ["bad-time", n, kind] => Fault::BadTime(
            whole(n, "bad-time", 1, 1000)?,
            match *kind {
                "negative" => BadTime::Negative,
                "repeat" => BadTime::Repeat,
                "ahead" => BadTime::Ahead,
                other => {
                    return Err(format!(
                        "bad-time: `{other}` is not negative, repeat or ahead"
                    ));
                }
            },
        ),
        ["eyes", ipd, toe @ ..] if toe.len() <= 1 => {
            let number = |w: &str| w.parse::<f32>().ok().filter(|v| v.is_finite());
            let (ipd_mm, toe_deg) = (number(ipd), toe.first().map_or(Some(0.0), |t| number(t)));
            match (ipd_mm, toe_deg) {
                (Some(i), Some(t)) if SimViews::new(i, t).is_some() => Fault::Eyes(i, t),
                _ => {
                    return Err(format!(
                        "eyes: `{}` is not a distance of 40 to 90 millimetres, then optionally \
                         a turn outwards of -10 to 10 degrees",
                        words[1..].join(" ")
                    ));
                }
            }
        }
        [name, ..] => {
            return Err(format!(
                "`{name}`: not a fault with those arguments (headset-off S, menu N, session-loss S, \
                 instance-loss S, recentre, no-render N, late N, image-timeout N, \
                 runtime-failure CALL, tracking-lost N N, unusable-pose N, zero-fov N, \
                 gaze-dropout S none|invalid|low, gaze-clock S MS, \
                 bad-time N negative|repeat|ahead, eyes MM [DEG])"
            ));
        }
        [] => return Err("a trigger with no fault after it".into()),
    })
}

/// A random schedule from `seed` over the app's first `frames` frames: every fault family at
/// least once, in a shuffled order, then more drawn at random, each starting 50 to 130 frames
/// after the one before ended (the app has time to recover and show frames in between).
/// Outages last 0.5 to 3 s, a menu 10 to 60 frames, a dropout 0.3 to 3 s, unusable poses 1 to
/// 10 frames, zero fields of view 1 to 5, bad display times 1 to 5, an eye tracker's clock 5
/// to 100 ms ahead (or, one time in four, 50 to 500 ms behind) for 0.3 to 3 s; new eyes are 54 to 72 mm apart and turned 0 to 3 degrees outwards.
pub fn chaos(seed: u64, frames: u64) -> Vec<Scheduled> {
    let mut rng = SplitMix64(seed ^ 0x6368_616f_735f_7673);
    let families = 16u64;
    let mut order: Vec<u64> = (0..families).collect();
    rng.shuffle(&mut order);
    let mut out = Vec::new();
    let mut at = 40 + rng.below(40);
    let mut k = 0;
    while at < frames.saturating_sub(40) {
        let family = if k < order.len() {
            order[k]
        } else {
            rng.below(families)
        };
        k += 1;
        let secs = |rng: &mut SplitMix64, low: f64, high: f64| {
            ((low + (high - low) * rng.unit()) * 10.0).round() / 10.0
        };
        let (fault, length) = match family {
            0 => (Fault::HeadsetOff(secs(&mut rng, 0.5, 3.0)), 3),
            1 => {
                let n = 10 + rng.below(51);
                (Fault::Menu(n), n)
            }
            2 => (Fault::SessionLoss(secs(&mut rng, 0.5, 3.0)), 1),
            3 => (Fault::InstanceLoss(secs(&mut rng, 0.5, 3.0)), 1),
            4 => (Fault::Recentre, 1),
            5 => {
                let n = 1 + rng.below(30);
                (Fault::NoRender(n), n)
            }
            6 => (Fault::Late(1 + rng.below(6)), 1),
            7 => (Fault::ImageTimeout(1 + rng.below(3)), 1),
            8 => (
                Fault::RuntimeFailure(
                    FAILING_CALLS[rng.below(FAILING_CALLS.len() as u64) as usize],
                ),
                1,
            ),
            9 => {
                let p = rng.below(30);
                let o = rng.below(20) + u64::from(p == 0);
                (Fault::TrackingLost(p, o), p + o)
            }
            10 => {
                let kind = [Dropout::None, Dropout::Invalid, Dropout::Low][rng.below(3) as usize];
                let s = secs(&mut rng, 0.3, 3.0);
                (Fault::GazeDropout(s, kind), (s * 20.0) as u64)
            }
            11 => {
                let n = 1 + rng.below(10);
                (Fault::UnusablePose(n), n)
            }
            12 => {
                let n = 1 + rng.below(5);
                let kind =
                    [BadTime::Negative, BadTime::Repeat, BadTime::Ahead][rng.below(3) as usize];
                (Fault::BadTime(n, kind), n)
            }
            14 => {
                let n = 1 + rng.below(5);
                (Fault::ZeroFov(n), n)
            }
            13 => {
                let s = secs(&mut rng, 0.3, 3.0);
                let ms = match rng.below(4) {
                    0 => -50 - rng.below(451) as i64,
                    _ => 5 + rng.below(96) as i64,
                };
                (Fault::GazeClock(s, ms), (s * 20.0) as u64)
            }
            _ => {
                let ipd = 54.0 + 0.5 * rng.below(37) as f32;
                let toe = 0.5 * rng.below(7) as f32;
                (Fault::Eyes(ipd, toe), 1)
            }
        };
        out.push(Scheduled {
            trigger: Trigger::Frame(at),
            fault,
        });
        at += length + 50 + rng.below(81);
    }
    out
}

#[cfg(test)]
mod tests;
