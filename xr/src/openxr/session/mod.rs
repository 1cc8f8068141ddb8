//! The live session: what it holds and reports, and the commands it takes. It is made in
//! [`create`], driven by the OpenXR state machine in [`state_machine`], hands out and submits
//! frames in [`frame`], and places the scene with [`placement`].
//!
//! The order of the fields of [`Session`] is its teardown order (Rust drops fields in
//! declaration order): frame stream, waiter, swapchains, actions, gaze, spaces, then the
//! session.

mod create;
mod depth;
mod display_time;
mod frame;
mod frame_end;
mod gaze_time;
mod images;
mod interruptions;
mod locate;
mod placement;
mod scope;
mod state_machine;
mod tracking;

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use glam::Vec3;
use openxr as xr;
use vitreous_trace::{Blend, Command, Pose};

use super::DepthOptions;
use super::SessionOptions;
use super::actions::Controls;
use super::choose::{GazeSource, SpaceChoice};
use super::gaze::{Gaze, GazeTally};
use super::gaze_order::GazeOrder;
use super::state::{EndReason, State};

pub(super) use create::start;
pub use interruptions::Interruptions;
use placement::re_register;

/// Set by the Ctrl-C handler; polled by every session.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
/// Whether the handler is installed (it can be only once per process).
static HANDLER: OnceLock<bool> = OnceLock::new();

/// Installs the Ctrl-C handler once; false when another handler was already set.
fn install_ctrl_c() -> bool {
    *HANDLER.get_or_init(|| {
        ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst))
            .map_err(|e| tracing::warn!("cannot handle Ctrl-C: {e}"))
            .is_ok()
    })
}

/// Whether Ctrl-C was pressed since a session installed its handler (the app stops waiting
/// for a runtime to come back then too).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// How long the session waits for the runtime to make it READY or walk it to EXITING.
const STATE_TIMEOUT: Duration = Duration::from_secs(20);

/// What a finished (or running) session did.
#[derive(Clone, Debug, Default)]
pub struct SessionReport {
    /// Every state the session reached, in order (repeats collapsed).
    pub states: Vec<State>,
    /// Frames handed to the app and submitted with a projection layer.
    pub frames_submitted: u64,
    /// Frames the runtime said not to render (submitted without layers).
    pub frames_skipped: u64,
    /// Why the session ended (None while running).
    pub end_reason: Option<EndReason>,
    /// The gaze source.
    pub gaze_source: Option<GazeSource>,
    /// The gaze source's samples: frames asked, samples received, frames with a fresh one
    /// (for XR_EXT_eye_gaze_interaction, the runtime's combined-ray samples).
    pub gaze_samples: GazeTally,
    /// The reference space.
    pub space: Option<SpaceChoice>,
    /// The blend mode.
    pub blend: Option<Blend>,
    /// Frames whose views the runtime could not locate fully (pose not valid).
    pub frames_untracked: u64,
    /// The controller action set was created and attached to the session.
    pub actions_attached: bool,
    /// Interaction profiles whose suggested bindings the runtime accepted.
    pub action_profiles: Vec<String>,
    /// Successful xrSyncActions calls (one per FOCUSED frame).
    pub action_syncs: u64,
    /// Commands the live actions gave.
    pub commands: u64,
    /// Frames submitted with depth (XR_KHR_composition_layer_depth).
    pub frames_with_depth: u64,
    /// The depth swapchain's format (VkFormat code) when depth is submitted.
    pub depth_format: Option<i32>,
    /// Frames begun but left without being shown (an error before xrEndFrame): each was
    /// ended with no layers and its images released.
    pub frames_abandoned: u64,
    /// XrEventDataReferenceSpaceChangePending events for the scene's space; each re-anchors
    /// the scene at the next located head pose.
    pub space_changes: u64,
    /// Frames submitted with `XrFrameEndInfoML` (XR_ML_frame_end_info: the focus distance).
    pub frames_with_focus_distance: u64,
    /// The focus distance of the last such frame, metres.
    pub last_focus_distance_m: Option<f32>,
    /// Frames submitted with `XrGlobalDimmerFrameEndInfoML` (XR_ML_global_dimmer).
    pub frames_with_global_dimmer: u64,
    /// Plane detections finished (XR_EXT_plane_detection).
    pub plane_detections: u64,
    /// Light estimates read (XR_ML_light_estimation).
    pub light_estimates: u64,
    /// What a misbehaving headset did to the session, and what the session did about it.
    pub interruptions: Interruptions,
}

impl SessionReport {
    /// Whether the session reached `state`.
    pub fn reached(&self, state: State) -> bool {
        self.states.contains(&state)
    }

    /// The report of a run whose session was followed by `later` (a new one after a loss):
    /// the states one after the other, the counts added, what only one session has (the end,
    /// the sources, the newest values) the later's.
    pub fn then(&mut self, later: &SessionReport) {
        self.states.extend(later.states.iter().copied());
        self.states.dedup();
        self.frames_submitted += later.frames_submitted;
        self.frames_skipped += later.frames_skipped;
        self.end_reason = later.end_reason;
        self.gaze_source = later.gaze_source;
        self.gaze_samples.add(&later.gaze_samples);
        self.space = later.space;
        self.blend = later.blend;
        self.frames_untracked += later.frames_untracked;
        self.actions_attached &= later.actions_attached;
        self.action_syncs += later.action_syncs;
        self.commands += later.commands;
        self.frames_with_depth += later.frames_with_depth;
        self.depth_format = later.depth_format;
        self.frames_abandoned += later.frames_abandoned;
        self.space_changes += later.space_changes;
        self.frames_with_focus_distance += later.frames_with_focus_distance;
        self.last_focus_distance_m = later.last_focus_distance_m.or(self.last_focus_distance_m);
        self.frames_with_global_dimmer += later.frames_with_global_dimmer;
        self.plane_detections += later.plane_detections;
        self.light_estimates += later.light_estimates;
        self.interruptions.then(&later.interruptions);
    }
}

/// A live OpenXR session; the [`crate::Backend`] of `vitreous run`.
pub struct Session {
    /// The plane detector, when the runtime has XR_EXT_plane_detection; dropped before the
    /// session.
    planes: Option<super::planes::PlaneDetector>,
    /// Where each finished detection's planes (in the scene frame) go for the app.
    planes_tx: mpsc::Sender<Vec<vitreous_trace::planes::DetectedPlane>>,
    /// The app's end, until taken (see [`Session::take_planes`]).
    planes_rx: Option<mpsc::Receiver<Vec<vitreous_trace::planes::DetectedPlane>>>,
    /// The light estimation, when the runtime has XR_ML_light_estimation; dropped before the
    /// session.
    light: Option<super::light_estimator::LightEstimator>,
    /// Where each new light estimate (in the scene frame) goes for the app.
    light_tx: mpsc::Sender<vitreous_trace::light::LightEstimate>,
    /// The app's end, until taken (see [`Session::take_light_estimates`]).
    light_rx: Option<mpsc::Receiver<vitreous_trace::light::LightEstimate>>,
    /// Frame submission; dropped before the session.
    stream: xr::FrameStream<xr::Vulkan>,
    /// Frame pacing.
    waiter: xr::FrameWaiter,
    /// The one 2-layer swapchain.
    swapchain: xr::Swapchain<xr::Vulkan>,
    /// The 2-layer depth swapchain, when depth is submitted, and its near/far planes.
    depth: Option<(xr::Swapchain<xr::Vulkan>, DepthOptions)>,
    /// The controller actions, when their set could be made.
    controls: Option<Controls>,
    /// Every action set attached to the session (synced together each FOCUSED frame).
    action_sets: Vec<xr::ActionSet>,
    /// Where commands go for the app (see [`Session::take_commands`]).
    commands_tx: mpsc::Sender<Command>,
    /// The app's end, until taken.
    commands_rx: Option<mpsc::Receiver<Command>>,
    /// Commands the app sends in (keyboard controls), applied at the next frame.
    injected_tx: mpsc::Sender<Command>,
    /// Their receiving end, drained each frame.
    injected_rx: mpsc::Receiver<Command>,
    /// The gaze source (holds spaces/trackers of the session).
    gaze: Gaze,
    /// The frames' gaze kept in time order.
    gaze_order: GazeOrder,
    /// The app space the scene is placed in (STAGE or LOCAL).
    space: xr::Space,
    /// Its type, to match reference-space change events.
    space_type: xr::ReferenceSpaceType,
    /// The VIEW space (the head).
    view_space: xr::Space,
    /// The session.
    session: xr::Session<xr::Vulkan>,
    /// The instance, for events.
    instance: xr::Instance,
    /// Event storage.
    events: xr::EventDataBuffer,
    /// Blend mode submitted with every frame.
    blend: xr::EnvironmentBlendMode,
    /// Flags of the projection layer (source alpha for ALPHA_BLEND).
    layer_flags: xr::CompositionLayerFlags,
    /// The blend mode, as the renderer composes for it.
    display_blend: Blend,
    /// Eye image size, pixels.
    size: (u32, u32),
    /// Current state.
    state: State,
    /// Between xrBeginSession and xrEndSession.
    running: bool,
    /// xrRequestExitSession was called.
    exit_requested: bool,
    /// Set to quit on the next wait.
    quit: bool,
    /// Scene frame from app space; fixed at the first located head pose (and again at the
    /// first one after the space changed).
    world_from_space: Option<Pose>,
    /// Display time of the first frame.
    first_display: Option<xr::Time>,
    /// Next frame index.
    next_index: u64,
    /// The frame between xrBeginFrame and xrEndFrame, and what it holds.
    open: Option<scope::OpenFrame>,
    /// Options.
    options: SessionOptions,
    /// What happened.
    report: SessionReport,
    /// XR_ML_frame_end_info is enabled.
    ml_frame_end: bool,
    /// XR_ML_global_dimmer is enabled.
    ml_dimmer: bool,
    /// What the app asked of the display for the frame in flight.
    hints: crate::FrameEndHints,
    /// Events for the app since the last frame handed out.
    pending: interruptions::Pending,
    /// The predicted display time of the frame waited for last (`None` after a stop).
    last_waited_ns: Option<i64>,
    /// The newest display time a frame was predicted at that was usable
    /// ([`display_time::bad_display_time`]), in this session or the one it continues, and when
    /// it was predicted.
    last_display: Option<(i64, std::time::Instant)>,
    /// The last tracked head pose, and what tracking lacks now.
    tracking: tracking::HeadTracking,
    /// Since when the runtime has had the session stopped (the headset taken off), and when
    /// that was last logged.
    paused: Option<(std::time::Instant, std::time::Instant)>,
    /// Frames that failed in a row (a runtime failure each).
    failed_in_a_row: u32,
    /// The running session lost the input focus (and has not got it back).
    unfocused: bool,
}

impl Session {
    /// What the session did so far.
    pub fn report(&self) -> &SessionReport {
        &self.report
    }

    /// Eye image size, pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The commands of the live actions, as they come (each is also logged, and Nudge and
    /// Rotate are applied to the scene's placement by the session itself). `None` after the
    /// first call.
    pub fn take_commands(&mut self) -> Option<mpsc::Receiver<Command>> {
        self.commands_rx.take()
    }

    /// The receiving end of the planes the runtime detects (XR_EXT_plane_detection), each
    /// finished detection's upward planes in the scene frame; taken once (`None` after).
    pub fn take_planes(
        &mut self,
    ) -> Option<mpsc::Receiver<Vec<vitreous_trace::planes::DetectedPlane>>> {
        self.planes_rx.take()
    }

    /// Moves plane detection on for the frame shown at `time` (head at `head_space` in app
    /// space), and hands a finished detection's planes to the app in the scene frame
    /// (`world_from_space`).
    pub(super) fn poll_planes(
        &mut self,
        time: xr::Time,
        head_space: &Pose,
        world_from_space: &Pose,
    ) {
        let Some(detector) = &mut self.planes else {
            return;
        };
        if let Some(found) = detector.poll(&self.space, time, *head_space) {
            self.report.plane_detections += 1;
            let scene: Vec<_> = found
                .into_iter()
                .map(|p| vitreous_trace::planes::DetectedPlane {
                    pose: placement::compose(world_from_space, &p.pose),
                    ..p
                })
                .collect();
            if self.report.plane_detections == 1 {
                tracing::info!("XR_EXT_plane_detection: {} upward planes", scene.len());
            }
            let _ = self.planes_tx.send(scene);
        }
    }

    /// The receiving end of the room's light as the runtime estimates it
    /// (XR_ML_light_estimation): each new estimate, in the scene frame; taken once (`None`
    /// after).
    pub fn take_light_estimates(
        &mut self,
    ) -> Option<mpsc::Receiver<vitreous_trace::light::LightEstimate>> {
        self.light_rx.take()
    }

    /// Moves light estimation on for the frame shown at `time`, and hands a new estimate to
    /// the app in the scene frame (`world_from_space`).
    pub(super) fn poll_light(&mut self, time: xr::Time, world_from_space: &Pose) {
        let Some(estimator) = &mut self.light else {
            return;
        };
        if let Some(estimate) = estimator.poll(&self.session, &self.space, time) {
            self.report.light_estimates = estimator.estimates;
            let scene = estimate.rotated(world_from_space.orientation);
            if estimator.estimates == 1 {
                tracing::info!(
                    "XR_ML_light_estimation: the main light travels along ({:.3}, {:.3}, {:.3}) \
                     in the scene",
                    scene.direction.x,
                    scene.direction.y,
                    scene.direction.z
                );
            }
            let _ = self.light_tx.send(scene);
        }
    }

    /// The scene frame from app space, once placed (a new session after a loss may take it
    /// over, [`SessionOptions::world_from_space`]).
    pub fn world_from_space(&self) -> Option<Pose> {
        self.world_from_space
    }

    /// The next frame's index.
    pub fn next_index(&self) -> u64 {
        self.next_index
    }

    /// The predicted display time of the session's first frame, nanoseconds.
    pub fn first_display_ns(&self) -> Option<i64> {
        self.first_display.map(|t| t.as_nanos())
    }

    /// The newest usable display time a frame was predicted at (nanoseconds), and when.
    pub fn last_display(&self) -> Option<(i64, std::time::Instant)> {
        self.last_display
    }

    /// The frames' gaze order so far (the newest sample a frame got).
    pub fn gaze_order(&self) -> GazeOrder {
        self.gaze_order
    }

    /// Where the application sends commands to be applied as if a live action gave them, at
    /// the next frame before its views are located (e.g. a keyboard's re-registration).
    pub fn command_sender(&self) -> mpsc::Sender<Command> {
        self.injected_tx.clone()
    }

    /// Applies the commands sent through [`Session::command_sender`] since the last frame.
    /// `head_m` is the head's position in the scene frame.
    pub(super) fn apply_injected(&mut self, head_m: Vec3) {
        while let Ok(command) = self.injected_rx.try_recv() {
            self.command(command, head_m);
        }
    }

    /// Applies a command as if a live action gave it (Nudge and Rotate re-register the scene;
    /// every command is passed on to [`Session::take_commands`]'s receiver). `head_m` is the
    /// head's position in the scene frame.
    pub fn command(&mut self, command: Command, head_m: Vec3) {
        tracing::info!("live action: {command}");
        self.report.commands += 1;
        if let Some(w) = &mut self.world_from_space {
            *w = re_register(w, command, head_m);
        }
        // The app may have dropped its receiver: then nobody wants the rest.
        let _ = self.commands_tx.send(command);
    }
}
