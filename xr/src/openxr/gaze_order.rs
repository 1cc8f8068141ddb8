//! The frames' gaze samples in time order, none stamped after its frame ([`GazeOrder`]).

use vitreous_trace::GazeSample;

/// The frames' gaze in time order, never stamped after its frame.
///
/// A runtime may hand out a sample stamped before one the app already used: a tracker that
/// stamped a blink with the display time and then stalls on an older sample, a clock that went
/// back. Such a sample is not new; the frame gets the newest sample used so far again instead,
/// as a tracker with no new sample answers, so the gaze filters and the recording (whose gaze
/// times must not decrease) only see time go forward.
///
/// A runtime may also stamp a new sample after the display time the frame asked it for: an eye
/// tracker whose clock runs ahead of the runtime's. It is the newest the tracker has, so the
/// frame uses it, stamped at the frame's display time (a frame's gaze is what was known when it
/// was shown; a recording's line pairs a pose with the gaze at or before it); the same sample
/// handed out again keeps that stamp, and later samples are ordered by the runtime's stamps.
///
/// It carries over to the next session after a loss ([`super::Continued`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GazeOrder {
    /// The newest sample handed to a frame, as handed.
    newest: Option<GazeSample>,
    /// The runtime's stamp of that sample (later than `newest`'s when it was stamped ahead).
    newest_runtime_ns: Option<i64>,
}

/// The gaze a frame gets ([`GazeOrder::order`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ordered {
    /// The sample, stamped no later than the frame's display time.
    pub gaze: Option<GazeSample>,
    /// Stamped before one already used: the newest was given again instead.
    pub out_of_order: bool,
    /// A new sample stamped this long after the frame's display time, nanoseconds (restamped).
    pub ahead_ns: Option<i64>,
}

impl GazeOrder {
    /// The newest sample handed to a frame so far.
    pub fn newest(&self) -> Option<GazeSample> {
        self.newest
    }

    /// The gaze a frame displayed at `display_ns` gets for the runtime's `gaze`.
    pub fn order(&mut self, gaze: Option<GazeSample>, display_ns: i64) -> Ordered {
        let ordered = |gaze, out_of_order, ahead_ns| Ordered {
            gaze,
            out_of_order,
            ahead_ns,
        };
        let Some(mut g) = gaze else {
            return ordered(None, false, None);
        };
        let stamped = g.sample_time_ns;
        match (self.newest, self.newest_runtime_ns) {
            (Some(n), Some(runtime_ns)) if stamped < runtime_ns => {
                return ordered(Some(n), true, None);
            }
            (Some(n), Some(runtime_ns)) if stamped == runtime_ns => {
                g.sample_time_ns = n.sample_time_ns;
                self.newest = Some(g);
                return ordered(Some(g), false, None);
            }
            _ => {}
        }
        let ahead_ns = (stamped > display_ns).then(|| stamped - display_ns);
        if ahead_ns.is_some() {
            let floor = self.newest.map_or(i64::MIN, |n| n.sample_time_ns);
            g.sample_time_ns = display_ns.max(floor);
        }
        self.newest = Some(g);
        self.newest_runtime_ns = Some(stamped);
        ordered(Some(g), false, ahead_ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_trace::GazeRay;

    /// A sample stamped `ns` whose rays start at `x`.
    fn at(ns: i64, x: f32) -> GazeSample {
        let ray = GazeRay {
            origin: glam::Vec3::new(x, 0.0, 0.0),
            direction: glam::Vec3::NEG_Z,
            valid: true,
        };
        GazeSample::binocular(ns, ray, ray)
    }

    /// Orders `gaze` for a frame at `display_ns`: (the frame's gaze, out of order, ahead).
    fn order_at(
        order: &mut GazeOrder,
        gaze: Option<GazeSample>,
        display_ns: i64,
    ) -> (Option<GazeSample>, bool, Option<i64>) {
        let o = order.order(gaze, display_ns);
        (o.gaze, o.out_of_order, o.ahead_ns)
    }

    #[test]
    fn a_sample_older_than_one_used_gives_the_newest_again() {
        let mut order = GazeOrder::default();
        assert_eq!(
            order_at(&mut order, Some(at(40, 0.1)), 45),
            (Some(at(40, 0.1)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(50, 0.2)), 60),
            (Some(at(50, 0.2)), false, None)
        );
        // A blink stamped with the display time (100), then a stalled tracker's older sample.
        assert_eq!(
            order_at(&mut order, Some(at(100, 0.0)), 100),
            (Some(at(100, 0.0)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(53, 0.3)), 110),
            (Some(at(100, 0.0)), true, None)
        );
        // The same time again is not out of order; no sample stays none.
        assert_eq!(
            order_at(&mut order, Some(at(100, 0.4)), 120),
            (Some(at(100, 0.4)), false, None)
        );
        assert_eq!(order_at(&mut order, None, 130), (None, false, None));
        assert_eq!(order.newest(), Some(at(100, 0.4)));
        // Carried over a loss: the next session's first sample is held against it.
        let mut next = order;
        assert_eq!(
            order_at(&mut next, Some(at(90, 0.5)), 140),
            (Some(at(100, 0.4)), true, None)
        );
    }

    #[test]
    fn a_sample_stamped_after_its_frame_is_used_at_the_frame_time() {
        let mut order = GazeOrder::default();
        assert_eq!(
            order_at(&mut order, Some(at(90, 0.1)), 100),
            (Some(at(90, 0.1)), false, None)
        );
        // A tracker's clock 30 ahead: the new sample is the frame's, stamped at its time.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 110),
            (Some(at(110, 0.2)), false, Some(30))
        );
        // The same sample again keeps that stamp, ahead of the next frame or not.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 120),
            (Some(at(110, 0.2)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.2)), 150),
            (Some(at(110, 0.2)), false, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(160, 0.3)), 130),
            (Some(at(130, 0.3)), false, Some(30))
        );
        // The clock back in step: samples stamped before the runtime's newest stamp are old.
        assert_eq!(
            order_at(&mut order, Some(at(140, 0.4)), 140),
            (Some(at(130, 0.3)), true, None)
        );
        assert_eq!(
            order_at(&mut order, Some(at(170, 0.5)), 170),
            (Some(at(170, 0.5)), false, None)
        );
        // A restamp never goes back before a sample handed out earlier.
        let mut order = GazeOrder::default();
        order.order(Some(at(100, 0.1)), 100);
        assert_eq!(
            order_at(&mut order, Some(at(200, 0.2)), 100),
            (Some(at(100, 0.2)), false, Some(100))
        );
        // Every frame's gaze is stamped at or before its display time.
        let mut order = GazeOrder::default();
        let mut newest = i64::MIN;
        for (display, stamp) in [
            (10, 5),
            (20, 45),
            (30, 45),
            (40, 35),
            (50, 75),
            (60, 55),
            (70, 70),
        ] {
            let g = order.order(Some(at(stamp, 0.0)), display).gaze.unwrap();
            assert!(
                g.sample_time_ns <= display && g.sample_time_ns >= newest,
                "{display} {stamp}"
            );
            newest = g.sample_time_ns;
        }
    }
}
