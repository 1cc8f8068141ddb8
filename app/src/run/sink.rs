//! What `vitreous run` does with each frame: the sink the frame loop hands every frame to
//! (the scene's pose and edits, the look and the readback asked for, the display's frame-end
//! hints, the recording and the per-frame log, the readback check).

use anyhow::{Context, Result};
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_trace::format::TraceWriter;
use vitreous_trace::light::LightEstimate;
use vitreous_trace::{Blend, Command, FrameInput};
use vitreous_xr::FrameEndHints;

use super::recording::{trace_sample, views_due};
use super::room_light;
use vitreous_frames::conditions::LiveConditions;
use vitreous_frames::director::Director;
use vitreous_frames::focus::FocusFollower;
use vitreous_frames::frame_log::FrameLog;
use vitreous_frames::frame_loop::{FramePlan, FrameSink};
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::readback_check::{self, ReadbackCheck, check_readback};
use vitreous_frames::resident::ResidentSampler;
use vitreous_frames::scene_edit::SceneEdit;

/// Records frames and checks a readback.
pub(super) struct RunSink<'d> {
    /// Decides each frame's look (effect condition, gaze-dependent defocus).
    pub(super) looks: LiveConditions,
    /// Live commands from the session.
    pub(super) commands: Option<std::sync::mpsc::Receiver<Command>>,
    /// Frame to read back, if any.
    pub(super) readback_frame: Option<u64>,
    /// The scene's object, for the region check.
    pub(super) object_center_m: glam::Vec3,
    /// The object's radius.
    pub(super) object_radius_m: f32,
    /// The blend mode the images are composed for.
    pub(super) blend: Blend,
    /// With a segmented dimmer: its panel, where the light is and where the floor lies (a
    /// point and its normal), so the readback check knows where the shadow falls.
    pub(super) dimmer_shadow: Option<(
        vitreous_optics::display::dimmer::DimmerDesc,
        glam::Vec3,
        glam::Vec3,
        glam::Vec3,
    )>,
    /// The readback result.
    pub(super) readback: Option<ReadbackCheck>,
    /// Where head pose and gaze are recorded, if asked.
    pub(super) writer: Option<TraceWriter<vitreous_trace::format::AtomicFile>>,
    /// Every frame's input while recording, for the replay check (nothing is kept per frame
    /// otherwise).
    pub(super) recorded: Vec<FrameInput>,
    /// The per-frame log (`frames.csv` with `--out`).
    pub(super) log: FrameLog,
    /// What decides each frame's condition and gaze image instead of the live controls (a
    /// study's trials, `vitreous study run`).
    pub(super) director: Option<&'d mut dyn Director>,
    /// The first error writing the log, reported when the next frame finishes.
    pub(super) log_error: Option<anyhow::Error>,
    /// The scene's motion (`[motion]`), from the session's first frame, with the edits.
    pub(super) motion: MotionClock,
    /// The keyboard's live controls, when read.
    pub(super) edits: Option<std::sync::mpsc::Receiver<SceneEdit>>,
    /// The upward planes the runtime detects (XR_EXT_plane_detection), as they come.
    pub(super) planes_rx:
        Option<std::sync::mpsc::Receiver<Vec<vitreous_trace::planes::DetectedPlane>>>,
    /// The latest detection's planes, in the scene frame: where a place puts the object.
    pub(super) planes: Vec<vitreous_trace::planes::DetectedPlane>,
    /// Where re-registrations go: the session, which moves the scene's placement (the
    /// current session's, [`RunSink::attach`]).
    pub(super) registrar: Option<std::sync::mpsc::Sender<Command>>,
    /// The wearer's filtered fixation depth, which the display's focus plane follows.
    pub(super) focus: FocusFollower,
    /// This frame's filtered fixation depth, metres.
    pub(super) focus_m: Option<f32>,
    /// The scene's global dimmer level (`[display] global_dimmer`).
    pub(super) global_dimmer: Option<f32>,
    /// The room's light as the runtime estimates it (XR_ML_light_estimation), as it comes.
    pub(super) light_rx: Option<std::sync::mpsc::Receiver<vitreous_trace::light::LightEstimate>>,
    /// What the estimates did (`None`: none came).
    pub(super) room_light: Option<room_light::RoomLight>,
    /// The eye tracker's dropouts.
    pub(super) gaze_watch: vitreous_frames::gaze_watch::GazeWatch,
    /// Every session event, with the display time of the frame it came with.
    pub(super) events: Vec<(i64, vitreous_trace::SessionEvent)>,
    /// Display time of the newest frame, nanoseconds.
    pub(super) last_time_ns: Option<i64>,
    /// Resident memory over the session's frames.
    pub(super) resident: ResidentSampler,
    /// The headset's eye views, against the scene's.
    pub(super) views: super::views::ViewWatch,
    /// The eyes of the last views line recorded.
    pub(super) recorded_views: Option<[vitreous_trace::format::HeadView; 2]>,
    /// The newest gaze time recorded (a frame without gaze is stamped with it).
    pub(super) recorded_gaze_ns: Option<i64>,
}

impl RunSink<'_> {
    /// Takes the channels of a (new) session: its live commands, detected planes, light
    /// estimates and where re-registrations go.
    pub(super) fn attach(&mut self, session: &mut vitreous_xr::openxr::Session) {
        self.commands = session.take_commands();
        self.planes_rx = session.take_planes();
        self.light_rx = session.take_light_estimates();
        self.registrar = Some(session.command_sender());
    }

    /// With a segmented dimmer, what it must darken: the object's centre and the centre of
    /// its shadow (where the ray from the light through the centre meets the floor).
    pub(super) fn dimmed(&self) -> Option<readback_check::Dimmed> {
        let (panel, light, floor, normal) = self.dimmer_shadow?;
        let to_center = self.object_center_m - light;
        let t = (floor - light).dot(normal) / to_center.dot(normal);
        Some(readback_check::Dimmed {
            points: vec![self.object_center_m, light + to_center * t],
            panel,
        })
    }
}

impl FrameSink for RunSink<'_> {
    fn pose(&mut self, input: &FrameInput) -> Option<vitreous_render::ScenePose> {
        self.take_planes();
        self.follow_room_light(input);
        self.apply_typed_controls(input);
        let placement = self.motion.placement(input.time_ns)?;
        let (center, pose) = (placement.object_position_m, self.motion.pose_of(&placement));
        self.looks.set_object_pose(center, pose.world_from_model);
        self.object_center_m = center;
        if let Some(shadow) = &mut self.dimmer_shadow {
            shadow.1 = placement.light_position_m;
        }
        Some(pose)
    }

    fn light_share(&mut self) -> Option<f32> {
        Some(self.motion.light_share())
    }

    fn started(&mut self, input: &FrameInput) -> Result<()> {
        self.watch_gaze(input);
        self.views.watch(input);
        self.last_time_ns = Some(input.time_ns);
        if let Some(w) = &mut self.writer {
            if let Some(views) = views_due(input, self.recorded_views.as_ref()) {
                w.write_views(&views).context("recording the views")?;
                self.recorded_views = Some(views.eyes);
            }
            let sample = trace_sample(input, self.recorded_gaze_ns);
            w.write(&sample).context("recording the trace")?;
            self.recorded_gaze_ns = Some(sample.gaze.sample_time_ns);
            self.recorded.push(input.clone());
        }
        Ok(())
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let read = self.readback_frame == Some(input.index);
        let commands: Vec<Command> = match &self.commands {
            Some(rx) => rx.try_iter().collect(),
            None => Vec::new(),
        };
        for command in commands {
            self.record_command(command, input);
            if let Some(director) = &mut self.director {
                director.command(command);
            } else if let Some(change) = self.looks.apply(command) {
                tracing::info!("frame {}: {change}", input.index);
            }
        }
        let mut look = match &mut self.director {
            Some(director) => self.looks.plan_directed(*director, input),
            None => self.looks.plan(input),
        };
        look.caustics &= self.motion.caustics_valid();
        self.focus_m = self.focus.update(input);
        let condition = self.looks.condition().to_string();
        if let Err(e) = self
            .log
            .record(input, &condition, self.looks.planner().last_defocus())
        {
            self.log_error.get_or_insert(e);
        }
        FramePlan {
            look,
            want: Want {
                eyes: read,
                world: read,
            },
        }
    }

    fn session_events(
        &mut self,
        frame: Option<&FrameInput>,
        events: &[vitreous_trace::SessionEvent],
    ) -> Result<()> {
        self.note_events(frame, events);
        Ok(())
    }

    fn frame_end_hints(&mut self, _input: &FrameInput) -> FrameEndHints {
        FrameEndHints {
            focus_distance_m: self.focus_m,
            global_dimmer: self.global_dimmer,
        }
    }

    fn finished(&mut self, input: &FrameInput, result: &FrameResult) -> Result<()> {
        self.resident.frame(input.index);
        if let Some(e) = self.log_error.take() {
            return Err(e);
        }
        if let Some(e) = self.director.as_mut().and_then(|d| d.take_error()) {
            return Err(e);
        }
        if let Some(rb) = &result.readback {
            self.readback = Some(check_readback(
                input,
                rb,
                self.object_center_m,
                self.object_radius_m,
                self.blend,
                self.dimmed().as_ref(),
            ));
        }
        Ok(())
    }
}

impl RunSink<'_> {
    /// Takes the newest light estimate since the last frame and turns the scene's light to
    /// it (recorded) when it points elsewhere.
    pub(super) fn follow_room_light(&mut self, input: &FrameInput) {
        let Some(rx) = &self.light_rx else {
            return;
        };
        let Some(estimate): Option<LightEstimate> = rx.try_iter().last() else {
            return;
        };
        let room = self
            .room_light
            .get_or_insert_with(room_light::RoomLight::default);
        room.estimates += 1;
        room.direction = Some(estimate.direction.to_array());
        let (_, floor_normal) = self.motion.floor();
        room.floor_share = estimate.share_on(floor_normal);
        if let Some(record) = self
            .motion
            .follow_light(estimate.direction, room.floor_share, input)
        {
            room.light_moves += 1;
            self.record(&record);
        }
        if let Some(room) = &mut self.room_light {
            room.light_share = Some(self.motion.light_share());
        }
    }
}
