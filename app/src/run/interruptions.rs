//! What a misbehaving headset did to the run, and what the run did about it: each session
//! event ([`SessionEvent`]: the headset taken off, a menu, frames not rendered, a loss, lost
//! tracking, the eye tracker dropping out) logged, written into the recording as an event line
//! (trace v1.4, so `vitreous replay` of it reports the same), handed to the director (a study
//! shows an interrupted trial again), and counted in `summary.json`'s `interruptions`.

use std::collections::BTreeMap;

use serde::Serialize;
use vitreous_trace::format::EventRecord;
use vitreous_trace::session_event::{Loss, TrackingLoss};
use vitreous_trace::{FrameInput, SessionEvent};
use vitreous_xr::openxr::Interruptions;

use super::sink::RunSink;
use vitreous_frames::gaze_watch::GazeWatch;

impl RunSink<'_> {
    /// Takes the session's events that came before `frame` (`None`: after the last one).
    pub(super) fn note_events(&mut self, frame: Option<&FrameInput>, events: &[SessionEvent]) {
        let time_ns = frame.map(|f| f.time_ns).or(self.last_time_ns).unwrap_or(0);
        for event in events {
            self.note_event(time_ns, *event);
        }
        if let Some(director) = &mut self.director {
            director.session_events(events);
        }
    }

    /// Looks at the frame's gaze for the eye tracker's dropouts (before the frame is recorded).
    pub(super) fn watch_gaze(&mut self, frame: &FrameInput) {
        if let Some(event) = self.gaze_watch.observe(frame) {
            tracing::warn!("frame {}: {event}", frame.index);
            self.note_event(frame.time_ns, event);
        }
    }

    /// Records one event at `time_ns` (the frame it came with).
    fn note_event(&mut self, time_ns: i64, event: SessionEvent) {
        self.events.push((time_ns, event));
        if let Some(w) = &mut self.writer
            && let Err(e) = w.write_event(&EventRecord { time_ns, event })
        {
            self.log_error
                .get_or_insert(anyhow::Error::new(e).context("recording a session event"));
        }
    }
}

/// A new session after a loss.
#[derive(Clone, Debug, Serialize)]
pub struct Reconnect {
    /// What was lost: `session` or `instance`.
    pub lost: String,
    /// How long the run waited for the runtime to come back, seconds.
    pub waited_s: f64,
}

/// Frames the runtime handed out that were not rendered, by why.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct NotRenderedFrames {
    /// The runtime said not to render (`shouldRender` false).
    pub runtime: u64,
    /// The head's orientation was not tracked.
    pub tracking: u64,
    /// A runtime call failed while the frame was prepared or submitted.
    pub failed: u64,
    /// The session was walking to its end after the app asked to exit.
    pub exiting: u64,
}

/// `summary.json`'s `interruptions`: every frame the runtime handed out is either shown or
/// counted once under `not_rendered` (`frames_waited = frames_shown + not_rendered.*`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct InterruptionSummary {
    /// Frames the runtime handed out (xrWaitFrame), over every session of the run.
    pub frames_waited: u64,
    /// Frames submitted with their projection layer.
    pub frames_shown: u64,
    /// Frames not rendered, by why.
    pub not_rendered: NotRenderedFrames,
    /// Display periods the runtime moved past with no frame of the run's (late frames).
    pub late_periods: u64,
    /// Times the runtime stopped the session (the headset taken off), and began it again.
    pub pauses: u64,
    /// Times the session was begun again after a pause.
    pub resumes: u64,
    /// Times the session lost the input focus (a system menu).
    pub unfocused: u64,
    /// Lost sessions and lost runtimes, and the new sessions after them.
    pub reconnects: Vec<Reconnect>,
    /// How the run ended, when it ended lost (`session` or `instance`) and did not reconnect.
    pub lost_at_end: Option<String>,
    /// Times head tracking lost the position, and the orientation.
    pub tracking_lost_position: u64,
    /// Times head tracking lost the orientation.
    pub tracking_lost_orientation: u64,
    /// Frames drawn at the last tracked head position.
    pub frames_position_held: u64,
    /// Frames whose head or eye pose the runtime marked valid but was not usable (not finite,
    /// not a unit quaternion): taken as lost tracking.
    pub frames_unusable_pose: u64,
    /// Frames whose views' field of view the runtime marked valid but was none (four zero
    /// angles, not finite, not left of right and below up): not drawn.
    pub frames_unusable_field: u64,
    /// Times the reference space changed (recentred).
    pub recentres: u64,
    /// Swapchain image waits that timed out and were waited for again.
    pub image_wait_timeouts: u64,
    /// Calls that failed with XR_ERROR_RUNTIME_FAILURE, by name (each cost its frame).
    pub failed_calls: BTreeMap<String, u64>,
    /// Times the eye tracker gave no usable sample for longer than a blink.
    pub gaze_dropouts: u64,
    /// The longest such dropout, seconds.
    pub longest_gaze_dropout_s: f64,
    /// Frames drawn with the gaze decision held through a dropout.
    pub frames_gaze_held: u64,
    /// Event lines written into the recording (0 without `--record`).
    pub events_recorded: u64,
}

impl InterruptionSummary {
    /// The summary of a run from its sessions' merged report, its new sessions after losses
    /// and the sink's gaze watch and events.
    pub fn new(
        report: &vitreous_xr::openxr::SessionReport,
        reconnects: Vec<Reconnect>,
        gaze: &GazeWatch,
        events: &[(i64, SessionEvent)],
        recorded: bool,
    ) -> InterruptionSummary {
        let i: &Interruptions = &report.interruptions;
        let lost_name = |l: Loss| match l {
            Loss::Session => "session".to_owned(),
            Loss::Instance => "instance".to_owned(),
        };
        let count = |wanted: fn(&SessionEvent) -> bool| {
            events.iter().filter(|(_, e)| wanted(e)).count() as u64
        };
        InterruptionSummary {
            frames_waited: i.frames_waited,
            frames_shown: report.frames_submitted,
            not_rendered: NotRenderedFrames {
                runtime: report.frames_skipped,
                tracking: i.not_rendered_tracking,
                failed: report.frames_abandoned,
                exiting: i.not_rendered_exiting,
            },
            late_periods: i.late_periods,
            pauses: i.pauses,
            resumes: i.resumes,
            unfocused: i.unfocused,
            reconnects,
            lost_at_end: i.lost.map(lost_name),
            tracking_lost_position: i.tracking_losses[TrackingLoss::Position as usize],
            tracking_lost_orientation: i.tracking_losses[TrackingLoss::Orientation as usize],
            frames_position_held: i.frames_position_held,
            frames_unusable_pose: i.frames_unusable_pose,
            frames_unusable_field: i.frames_unusable_field,
            recentres: report.space_changes,
            image_wait_timeouts: i.image_wait_timeouts,
            failed_calls: i
                .failed_calls
                .iter()
                .map(|(c, n)| ((*c).to_owned(), *n))
                .collect(),
            gaze_dropouts: gaze.dropouts,
            longest_gaze_dropout_s: gaze.longest_ms as f64 / 1000.0,
            frames_gaze_held: gaze.frames_held,
            events_recorded: if recorded { count(|_| true) } else { 0 },
        }
    }

    /// Whether the frames add up: every frame handed out shown or counted as not rendered.
    pub fn frames_add_up(&self) -> bool {
        let n = &self.not_rendered;
        self.frames_waited == self.frames_shown + n.runtime + n.tracking + n.failed + n.exiting
    }

    /// One line for the run's report, when anything happened.
    pub fn line(&self) -> Option<String> {
        let n = &self.not_rendered;
        let quiet = n.runtime
            + n.tracking
            + n.failed
            + self.late_periods
            + self.pauses
            + self.unfocused
            + self.reconnects.len() as u64
            + self.tracking_lost_position
            + self.tracking_lost_orientation
            + self.recentres
            + self.image_wait_timeouts
            + self.gaze_dropouts
            == 0
            && self.lost_at_end.is_none();
        (!quiet).then(|| {
            format!(
                "interruptions: {} of {} frames shown (not rendered: {} by the runtime, {} for \
                 tracking, {} after a failed call); {} late periods; {} pauses, {} resumed; {} \
                 menus; {} reconnects{}; tracking lost {} (position) + {} (orientation); {} \
                 recentres; {} image timeouts; {} gaze dropouts (longest {:.1} s)",
                self.frames_shown,
                self.frames_waited,
                n.runtime,
                n.tracking,
                n.failed,
                self.late_periods,
                self.pauses,
                self.resumes,
                self.unfocused,
                self.reconnects.len(),
                self.lost_at_end
                    .as_ref()
                    .map_or(String::new(), |l| format!(", ended lost ({l})")),
                self.tracking_lost_position,
                self.tracking_lost_orientation,
                self.recentres,
                self.image_wait_timeouts,
                self.gaze_dropouts,
                self.longest_gaze_dropout_s
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitreous_trace::session_event::NotRendered;
    use vitreous_xr::openxr::SessionReport;

    #[test]
    fn every_frame_handed_out_is_shown_or_counted_once() {
        let mut report = SessionReport {
            frames_submitted: 90,
            frames_skipped: 6,
            frames_abandoned: 1,
            ..SessionReport::default()
        };
        report.interruptions.frames_waited = 100;
        report.interruptions.not_rendered_tracking = 2;
        report.interruptions.not_rendered_exiting = 1;
        let events = [(
            10,
            SessionEvent::NotRendered {
                reason: NotRendered::Runtime,
                frames: 6,
            },
        )];
        let s = InterruptionSummary::new(&report, Vec::new(), &GazeWatch::default(), &events, true);
        assert!(s.frames_add_up());
        assert_eq!(s.events_recorded, 1);
        assert!(s.line().unwrap().contains("90 of 100 frames shown"));
        report.interruptions.frames_waited = 101;
        let s = InterruptionSummary::new(&report, Vec::new(), &GazeWatch::default(), &[], false);
        assert!(!s.frames_add_up());
        // A quiet run says nothing.
        let quiet = InterruptionSummary::default();
        assert_eq!(quiet.line(), None);
    }
}
