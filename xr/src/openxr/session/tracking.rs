//! Head tracking as the session uses it: each frame's located head and eye poses, and what is
//! done when the runtime cannot locate them fully. A lost position (orientation still tracked,
//! as a headset's inertial sensors give it) is held at the last tracked one, each eye put where
//! it sat in the head then, so the wearer can still look around a scene that stays put; a lost
//! orientation leaves nothing to draw a world-locked object with, and the frame is not drawn
//! (on an optical see-through display, glass in the wrong place is worse than none).

use vitreous_trace::Pose;
use vitreous_trace::session_event::{SessionEvent, TrackingLoss};

use super::placement::{compose, inverse};

/// What a frame's located poses are good for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Located {
    /// Draw the frame with these poses (app space): the head and each eye.
    Draw {
        /// The head.
        head: Pose,
        /// The left and right eyes.
        eyes: [Pose; 2],
        /// Whether the position is the last tracked one, held.
        held: bool,
    },
    /// Do not draw it: the orientation is not tracked (or nothing was tracked yet).
    NotDrawn,
}

/// What the runtime said of one frame's poses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Poses {
    /// The head (VIEW space in the app's space).
    pub(super) head: Pose,
    /// The eyes' views.
    pub(super) eyes: [Pose; 2],
    /// Whether the positions are valid (head and views).
    pub(super) position_valid: bool,
    /// Whether the orientations are valid (head and views).
    pub(super) orientation_valid: bool,
}

/// The last tracked poses and what is lost now.
#[derive(Clone, Debug, Default)]
pub(super) struct HeadTracking {
    /// The last fully tracked head, and each eye in the head frame then.
    last: Option<(Pose, [Pose; 2])>,
    /// What is lost now, if anything.
    lost: Option<TrackingLoss>,
}

impl HeadTracking {
    /// What to do with a frame's poses; `events` gets a loss when it starts or deepens and
    /// the return of tracking when it ends.
    pub(super) fn locate(&mut self, poses: Poses, events: &mut Vec<SessionEvent>) -> Located {
        let now = match (poses.position_valid, poses.orientation_valid) {
            (true, true) => None,
            (false, true) => Some(TrackingLoss::Position),
            (_, false) => Some(TrackingLoss::Orientation),
        };
        if now != self.lost {
            events.push(match now {
                Some(loss) => SessionEvent::TrackingLost(loss),
                None => SessionEvent::TrackingBack,
            });
            self.lost = now;
        }
        match now {
            None => {
                let to_head = inverse(&poses.head);
                self.last = Some((poses.head, poses.eyes.map(|e| compose(&to_head, &e))));
                Located::Draw {
                    head: poses.head,
                    eyes: poses.eyes,
                    held: false,
                }
            }
            Some(TrackingLoss::Position) => match self.last {
                Some((last, eyes_in_head)) => {
                    let head = Pose {
                        position: last.position,
                        orientation: poses.head.orientation,
                    };
                    Located::Draw {
                        head,
                        eyes: eyes_in_head.map(|e| compose(&head, &e)),
                        held: true,
                    }
                }
                None => Located::NotDrawn,
            },
            Some(TrackingLoss::Orientation) => Located::NotDrawn,
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;

    fn poses(position: Vec3, yaw: f32, position_valid: bool, orientation_valid: bool) -> Poses {
        let head = Pose {
            position,
            orientation: Quat::from_rotation_y(yaw),
        };
        let eye = |x: f32| Pose {
            position: head.transform_point(Vec3::new(x, 0.0, 0.0)),
            orientation: head.orientation,
        };
        Poses {
            head,
            eyes: [eye(-0.032), eye(0.032)],
            position_valid,
            orientation_valid,
        }
    }

    #[test]
    fn a_lost_position_is_held_and_the_eyes_turn_with_the_tracked_orientation() {
        let mut t = HeadTracking::default();
        let mut events = Vec::new();
        let home = Vec3::new(0.1, 1.6, 0.2);
        assert!(matches!(
            t.locate(poses(home, 0.0, true, true), &mut events),
            Located::Draw { held: false, .. }
        ));
        // The runtime reports a nonsense position with the position lost: it is not used.
        let Located::Draw { head, eyes, held } =
            t.locate(poses(Vec3::ZERO, 0.5, false, true), &mut events)
        else {
            panic!("a lost position is still drawn");
        };
        assert!(held);
        assert!((head.position - home).length() < 1e-6);
        // Each eye 32 mm from the head along the turned head's x.
        let x = Quat::from_rotation_y(0.5) * Vec3::X;
        assert!((eyes[1].position - (home + x * 0.032)).length() < 1e-6);
        assert!((eyes[0].orientation.dot(Quat::from_rotation_y(0.5))).abs() > 0.999_999);
        assert_eq!(events, [SessionEvent::TrackingLost(TrackingLoss::Position)]);
    }

    #[test]
    fn a_lost_orientation_is_not_drawn_and_the_return_is_said_once() {
        let mut t = HeadTracking::default();
        let mut events = Vec::new();
        // Nothing tracked yet: nothing to hold.
        assert_eq!(
            t.locate(poses(Vec3::ZERO, 0.0, false, true), &mut events),
            Located::NotDrawn
        );
        t.locate(poses(Vec3::Y, 0.0, true, true), &mut events);
        assert_eq!(
            t.locate(poses(Vec3::Y, 0.0, false, false), &mut events),
            Located::NotDrawn
        );
        t.locate(poses(Vec3::Y, 0.0, false, false), &mut events);
        t.locate(poses(Vec3::Y, 0.0, true, true), &mut events);
        t.locate(poses(Vec3::Y, 0.0, true, true), &mut events);
        assert_eq!(
            events,
            [
                SessionEvent::TrackingLost(TrackingLoss::Position),
                SessionEvent::TrackingBack,
                SessionEvent::TrackingLost(TrackingLoss::Orientation),
                SessionEvent::TrackingBack,
            ]
        );
    }
}
