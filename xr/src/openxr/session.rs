//! The live session: state machine, frame loop calls, views, swapchain, gaze.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ash::vk;
use ash::vk::Handle;
use glam::{Quat, Vec3};
use openxr as xr;

use super::actions::{Command, Controls};
use super::choose::{self, Blend, GazeOffer, GazeSource, SpaceChoice};
use super::gaze::{ExtGaze, FbTracker, Gaze, TraceGaze};
use super::state::{self, Action, EndReason, State};
use super::{
    DepthOptions, OpenXrError, Result, Runtime, SessionOptions, SwapchainImages, VulkanHandles,
    XrContext,
};
use crate::frame::{Backend, EyeView, Fov, FrameInput, FrameTarget, Pose};

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
}

impl SessionReport {
    /// Whether the session reached `state`.
    pub fn reached(&self, state: State) -> bool {
        self.states.contains(&state)
    }
}

/// A frame handed out and not yet ended.
struct Pending {
    /// Its predicted display time.
    display: xr::Time,
    /// The located views, in the runtime's space (for the projection layer).
    views: Vec<xr::View>,
    /// Its index.
    index: u64,
    /// The depth swapchain image acquired for it, when depth is submitted.
    depth_image: Option<u32>,
}

/// A live OpenXR session; the [`Backend`] of `vitreous run`.
pub struct Session {
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
    /// The gaze source (holds spaces/trackers of the session).
    gaze: Gaze,
    /// The app space the scene is placed in (STAGE or LOCAL).
    space: xr::Space,
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
    /// Whether the real world is drawn behind the glass.
    world_behind: bool,
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
    /// Scene frame from app space; fixed at the first located head pose.
    world_from_space: Option<Pose>,
    /// Display time of the first frame.
    first_display: Option<xr::Time>,
    /// Next frame index.
    next_index: u64,
    /// The frame in flight and the swapchain image acquired for it.
    pending: Option<(Pending, u32)>,
    /// Options.
    options: SessionOptions,
    /// What happened.
    report: SessionReport,
}

/// Creates the session; see [`Runtime::start`].
///
/// # Safety
/// As [`Runtime::start`].
pub(super) unsafe fn start(
    rt: &Runtime,
    vulkan: VulkanHandles,
    options: &SessionOptions,
) -> Result<(Session, SwapchainImages)> {
    let info = xr::vulkan::SessionCreateInfo {
        instance: vulkan.instance.as_raw() as _,
        physical_device: vulkan.physical.as_raw() as _,
        device: vulkan.device.as_raw() as _,
        queue_family_index: vulkan.queue_family,
        queue_index: vulkan.queue_index,
    };
    let (session, waiter, stream) =
        unsafe { rt.instance.create_session::<xr::Vulkan>(rt.system, &info) }
            .xr("xrCreateSession")?;

    let spaces = session
        .enumerate_reference_spaces()
        .xr("xrEnumerateReferenceSpaces")?;
    let space_choice = choose::choose_space(spaces.contains(&xr::ReferenceSpaceType::STAGE));
    let space_type = match space_choice {
        SpaceChoice::Stage => xr::ReferenceSpaceType::STAGE,
        SpaceChoice::Local => xr::ReferenceSpaceType::LOCAL,
    };
    let space = session
        .create_reference_space(space_type, xr::Posef::IDENTITY)
        .xr("xrCreateReferenceSpace")?;
    let view_space = session
        .create_reference_space(xr::ReferenceSpaceType::VIEW, xr::Posef::IDENTITY)
        .xr("xrCreateReferenceSpace(VIEW)")?;
    tracing::info!("scene placed in the {space_choice:?} reference space");

    let formats: Vec<i64> = session
        .enumerate_swapchain_formats()
        .xr("xrEnumerateSwapchainFormats")?
        .into_iter()
        .map(i64::from)
        .collect();
    let format = choose::choose_format(&formats).ok_or_else(|| {
        OpenXrError::Unsupported(format!(
            "the runtime offers no 8-bit RGBA/BGRA swapchain format (VkFormat codes offered: {formats:?})"
        ))
    })?;
    tracing::info!(
        "swapchain format VkFormat {} ({})",
        format.vk_format,
        if format.srgb {
            "sRGB: the image encodes"
        } else {
            "UNORM: linear values stored as is"
        }
    );
    let (w, h) = rt.info.size;
    let swapchain = session
        .create_swapchain(&xr::SwapchainCreateInfo {
            create_flags: xr::SwapchainCreateFlags::EMPTY,
            usage_flags: xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                | xr::SwapchainUsageFlags::TRANSFER_SRC,
            format: format.vk_format as u32,
            sample_count: 1,
            width: w,
            height: h,
            face_count: 1,
            array_size: 2,
            mip_count: 1,
        })
        .xr("xrCreateSwapchain")?;
    let images = swapchain
        .enumerate_images()
        .xr("xrEnumerateSwapchainImages")?
        .into_iter()
        .map(vk::Image::from_raw)
        .collect();
    let depth = match (rt.depth_layer, options.depth) {
        (true, Some(d)) => depth_swapchain(&session, &formats, d, (w, h)),
        (false, Some(_)) => {
            tracing::info!(
                "depth not submitted: the runtime does not offer XR_KHR_composition_layer_depth"
            );
            None
        }
        (_, None) => None,
    };
    let depth_images = match &depth {
        Some((chain, _)) => match chain.enumerate_images() {
            Ok(raw) => raw.into_iter().map(vk::Image::from_raw).collect(),
            Err(e) => {
                return Err(OpenXrError::Call {
                    call: "xrEnumerateSwapchainImages(depth)",
                    result: e,
                });
            }
        },
        None => Vec::new(),
    };

    let offer = GazeOffer {
        fb_social: rt.fb_gaze && rt.info.fb_eye_tracking_supported,
        ext_gaze_extension: rt.ext_gaze,
        ext_gaze_supported: rt.info.eye_gaze_supported,
        trace: options.gaze_trace.is_some(),
    };
    let mut source = choose::choose_gaze(offer);
    if rt.ext_gaze && !rt.info.eye_gaze_supported {
        tracing::info!(
            "XR_EXT_eye_gaze_interaction is offered but the system has no eye tracker \
             (supportsEyeGazeInteraction = false)"
        );
    }
    let gaze = loop {
        let made = match source {
            GazeSource::FbSocial => FbTracker::new(&session).map(Gaze::FbSocial),
            GazeSource::ExtGaze => ExtGaze::new(&session).map(Gaze::ExtGaze),
            GazeSource::Trace => {
                let path = options
                    .gaze_trace
                    .as_deref()
                    .expect("chosen only with a trace");
                TraceGaze::open(path).map(Gaze::Trace)
            }
            GazeSource::Manual => Ok(Gaze::Manual),
        };
        match made {
            Ok(g) => break g,
            // A bad trace is the user's error: say so.
            Err(e) if source == GazeSource::Trace => return Err(e),
            Err(e) => {
                tracing::warn!("gaze source {source} failed ({e}); trying the next one");
                source = match source {
                    GazeSource::FbSocial if offer.ext_gaze_supported => GazeSource::ExtGaze,
                    GazeSource::FbSocial | GazeSource::ExtGaze if offer.trace => GazeSource::Trace,
                    _ => GazeSource::Manual,
                };
            }
        }
    };
    // Controller actions: a failure here costs the live actions only, never the session.
    let controls = match Controls::new(&rt.instance) {
        Ok(c) => Some(c),
        Err(e) => {
            tracing::warn!("no live controller actions: {e}");
            None
        }
    };
    // xrAttachSessionActionSets may be called once per session: every set goes in together.
    let mut action_sets: Vec<xr::ActionSet> = Vec::new();
    if let Gaze::ExtGaze(g) = &gaze {
        action_sets.push(g.set.clone());
    }
    if let Some(c) = &controls {
        action_sets.push(c.set.clone());
    }
    if !action_sets.is_empty() {
        let refs: Vec<&xr::ActionSet> = action_sets.iter().collect();
        session
            .attach_action_sets(&refs)
            .xr("xrAttachSessionActionSets")?;
    }
    let action_profiles: Vec<String> = controls
        .as_ref()
        .map(|c| c.profiles.iter().map(|p| (*p).to_owned()).collect())
        .unwrap_or_default();
    if controls.is_some() {
        tracing::info!(
            "controller actions attached (select, menu on each hand; profiles: {})",
            action_profiles.join(", ")
        );
    }
    tracing::info!("gaze source: {}", gaze.source());
    if gaze.source() == GazeSource::Manual {
        tracing::warn!("no eye tracker and no --gaze-trace: the gaze image must be chosen by hand");
    }

    if options.handle_ctrl_c {
        install_ctrl_c();
    }
    let blend = match rt.info.blend {
        Blend::Additive => xr::EnvironmentBlendMode::ADDITIVE,
        Blend::AlphaBlend => xr::EnvironmentBlendMode::ALPHA_BLEND,
        Blend::Opaque => xr::EnvironmentBlendMode::OPAQUE,
    };
    let report = SessionReport {
        states: vec![State::Idle],
        gaze_source: Some(gaze.source()),
        space: Some(space_choice),
        blend: Some(rt.info.blend),
        actions_attached: controls.is_some(),
        action_profiles,
        depth_format: depth.as_ref().map(|(_, d)| d.format.as_raw()),
        ..SessionReport::default()
    };
    let out = SwapchainImages {
        images,
        format: vk::Format::from_raw(format.vk_format as i32),
        srgb: format.srgb,
        size: (w, h),
        depth_images,
    };
    let (commands_tx, commands_rx) = mpsc::channel();
    Ok((
        Session {
            stream,
            waiter,
            swapchain,
            depth,
            controls,
            action_sets,
            commands_tx,
            commands_rx: Some(commands_rx),
            gaze,
            space,
            view_space,
            session,
            instance: rt.instance.clone(),
            events: xr::EventDataBuffer::new(),
            blend,
            world_behind: rt.info.blend.needs_world_behind(),
            size: (w, h),
            state: State::Idle,
            running: false,
            exit_requested: false,
            quit: false,
            world_from_space: None,
            first_display: None,
            next_index: 0,
            pending: None,
            options: options.clone(),
            report,
        },
        out,
    ))
}

/// Makes the 2-layer depth swapchain, or says why not and returns `None` (no depth is then
/// submitted; nothing else changes).
fn depth_swapchain(
    session: &xr::Session<xr::Vulkan>,
    formats: &[i64],
    depth: DepthOptions,
    (w, h): (u32, u32),
) -> Option<(xr::Swapchain<xr::Vulkan>, DepthOptions)> {
    let code = i64::from(depth.format.as_raw());
    if !formats.contains(&code) {
        tracing::warn!(
            "depth not submitted: the runtime offers no {:?} swapchain (VkFormat codes \
             offered: {formats:?})",
            depth.format
        );
        return None;
    }
    let made = session.create_swapchain(&xr::SwapchainCreateInfo {
        create_flags: xr::SwapchainCreateFlags::EMPTY,
        usage_flags: xr::SwapchainUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        format: code as u32,
        sample_count: 1,
        width: w,
        height: h,
        face_count: 1,
        array_size: 2,
        mip_count: 1,
    });
    match made {
        Ok(chain) => {
            tracing::info!(
                "depth submitted with XR_KHR_composition_layer_depth: {:?} swapchain, depth 0..1 \
                 = {} m..{} m",
                depth.format,
                depth.near_m,
                depth.far_m
            );
            Some((chain, depth))
        }
        Err(e) => {
            tracing::warn!("depth not submitted: xrCreateSwapchain(depth) failed: {e}");
            None
        }
    }
}

/// The depth info of one eye's layer: image `layer` of `swapchain` over `rect`, depth 0..1
/// from `near_m` to `far_m` (a standard, not reversed, projection).
pub(crate) fn depth_info(
    swapchain: xr::sys::Swapchain,
    layer: u32,
    rect: xr::Rect2Di,
    depth: &DepthOptions,
) -> xr::sys::CompositionLayerDepthInfoKHR {
    xr::sys::CompositionLayerDepthInfoKHR {
        ty: xr::sys::CompositionLayerDepthInfoKHR::TYPE,
        next: std::ptr::null(),
        sub_image: xr::sys::SwapchainSubImage {
            swapchain,
            image_rect: rect,
            image_array_index: layer,
        },
        min_depth: 0.0,
        max_depth: 1.0,
        near_z: depth.near_m,
        far_z: depth.far_m,
    }
}

/// Chains each view's depth info into its `next` (keeping whatever was chained before behind
/// it).
///
/// # Safety
/// `infos` must outlive every use of `views` (xrEndFrame), and must not move.
pub(crate) unsafe fn chain_depth(
    views: &mut [xr::sys::CompositionLayerProjectionView],
    infos: &mut [xr::sys::CompositionLayerDepthInfoKHR],
) {
    for (view, info) in views.iter_mut().zip(infos.iter_mut()) {
        info.next = view.next;
        view.next = info as *const xr::sys::CompositionLayerDepthInfoKHR as *const _;
    }
}

/// The scene frame from app space after a re-registration command: the scene moves by `d`
/// (Nudge), or turns by `a` about the vertical axis through the head at `head_m` (Rotate),
/// both in the scene frame. Other commands leave it as is.
pub(crate) fn re_register(world_from_space: &Pose, command: Command, head_m: Vec3) -> Pose {
    let change = match command {
        // The scene moving by d is everything else moving by -d in scene coordinates.
        Command::Nudge(d) => Pose {
            position: -d,
            orientation: Quat::IDENTITY,
        },
        // p' = R(-a) (p - h) + h.
        Command::Rotate(a) => {
            let r = Quat::from_rotation_y(-a);
            Pose {
                position: head_m - r * head_m,
                orientation: r,
            }
        }
        Command::Cycle(_) => return *world_from_space,
    };
    compose(&change, world_from_space)
}

/// vitreous' state for an OpenXR one.
fn state_of(s: xr::SessionState) -> State {
    match s {
        xr::SessionState::IDLE => State::Idle,
        xr::SessionState::READY => State::Ready,
        xr::SessionState::SYNCHRONIZED => State::Synchronized,
        xr::SessionState::VISIBLE => State::Visible,
        xr::SessionState::FOCUSED => State::Focused,
        xr::SessionState::STOPPING => State::Stopping,
        xr::SessionState::LOSS_PENDING => State::LossPending,
        xr::SessionState::EXITING => State::Exiting,
        _ => State::Unknown,
    }
}

/// A pose from OpenXR's.
fn pose_of(p: &xr::Posef) -> Pose {
    Pose {
        position: Vec3::new(p.position.x, p.position.y, p.position.z),
        orientation: Quat::from_xyzw(
            p.orientation.x,
            p.orientation.y,
            p.orientation.z,
            p.orientation.w,
        )
        .normalize(),
    }
}

/// `a` after `b`: maps `b`'s frame into `a`'s parent.
pub(crate) fn compose(a: &Pose, b: &Pose) -> Pose {
    Pose {
        position: a.transform_point(b.position),
        orientation: (a.orientation * b.orientation).normalize(),
    }
}

/// The inverse transform.
pub(crate) fn inverse(p: &Pose) -> Pose {
    let q = p.orientation.conjugate();
    Pose {
        position: -(q * p.position),
        orientation: q,
    }
}

/// The rotation about +y that faces where `orientation` faces (level, no roll).
pub(crate) fn yaw_only(orientation: Quat) -> Quat {
    let f = orientation * Vec3::NEG_Z;
    if f.x.abs() < 1e-6 && f.z.abs() < 1e-6 {
        return Quat::IDENTITY;
    }
    Quat::from_rotation_y((-f.x).atan2(-f.z))
}

/// The scene frame from app space such that the first head pose `head0` (app space) sits at
/// the viewer's position, facing the scene's -z.
pub(crate) fn place_scene(head0: &Pose, viewer_m: Vec3, origin: Option<Pose>) -> Pose {
    let level = Pose {
        position: head0.position,
        orientation: yaw_only(head0.orientation),
    };
    let viewer = Pose {
        position: viewer_m,
        orientation: Quat::IDENTITY,
    };
    let placed = compose(&viewer, &inverse(&level));
    match origin {
        Some(o) => compose(&o, &placed),
        None => placed,
    }
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

    /// xrSyncActions with every attached set, then the controller commands; only while
    /// FOCUSED (input goes to the focused session only).
    fn sync_actions(&mut self, head_m: Vec3) -> Result<()> {
        if self.state != State::Focused || self.action_sets.is_empty() {
            return Ok(());
        }
        let active: Vec<xr::ActiveActionSet<'_>> = self
            .action_sets
            .iter()
            .map(xr::ActiveActionSet::new)
            .collect();
        self.session.sync_actions(&active).xr("xrSyncActions")?;
        self.report.action_syncs += 1;
        let commands = match &self.controls {
            Some(c) => c.commands(&self.session)?,
            None => Vec::new(),
        };
        for command in commands {
            self.command(command, head_m);
        }
        Ok(())
    }

    fn set_state(&mut self, s: State) {
        self.state = s;
        if self.report.states.last() != Some(&s) {
            self.report.states.push(s);
        }
        tracing::info!("session state {s}");
    }

    fn end_with(&mut self, reason: EndReason) {
        if self.report.end_reason.is_none() {
            self.report.end_reason = Some(reason);
        }
    }

    /// Handles pending events; applies the state machine.
    fn poll_events(&mut self) -> Result<()> {
        loop {
            let event = self
                .instance
                .poll_event(&mut self.events)
                .xr("xrPollEvent")?;
            let Some(event) = event else { break };
            match event {
                xr::Event::SessionStateChanged(e) => {
                    let s = state_of(e.state());
                    // Copy out before `self` is borrowed mutably again.
                    self.set_state(s);
                    match state::on_state(s, self.running) {
                        Action::Begin => {
                            self.session
                                .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
                                .xr("xrBeginSession")?;
                            self.running = true;
                        }
                        Action::End => {
                            self.session.end().xr("xrEndSession")?;
                            self.running = false;
                            if !self.exit_requested {
                                self.end_with(EndReason::RuntimeExit);
                            }
                        }
                        Action::EndAndQuit => {
                            let _ = self.session.end();
                            self.running = false;
                            self.end_with(EndReason::SessionLost);
                            self.quit = true;
                        }
                        Action::Quit => {
                            if s == State::LossPending {
                                self.end_with(EndReason::SessionLost);
                            } else {
                                self.end_with(EndReason::RuntimeExit);
                            }
                            self.quit = true;
                        }
                        Action::Continue => {}
                    }
                }
                xr::Event::InstanceLossPending(_) => {
                    tracing::warn!("the OpenXR runtime is going away (instance loss pending)");
                    if self.running {
                        let _ = self.session.end();
                        self.running = false;
                    }
                    self.end_with(EndReason::InstanceLost);
                    self.quit = true;
                }
                xr::Event::EventsLost(e) => {
                    tracing::warn!("the runtime dropped {} events", e.lost_event_count());
                }
                _ => {}
            }
            if self.quit {
                break;
            }
        }
        Ok(())
    }

    /// Asks the runtime to end the session (or quits at once if it never ran).
    fn stop(&mut self, reason: EndReason) -> Result<()> {
        self.end_with(reason);
        if self.exit_requested {
            return Ok(());
        }
        self.exit_requested = true;
        if self.running {
            tracing::info!("ending the session: {reason}");
            self.session.request_exit().xr("xrRequestExitSession")?;
        } else {
            self.quit = true;
        }
        Ok(())
    }

    /// Waits and begins a frame; `None` when the runtime says not to render it (it is then
    /// ended here with no layers).
    fn begin_frame(&mut self) -> Result<Option<xr::FrameState>> {
        let frame = self.waiter.wait().xr("xrWaitFrame")?;
        self.stream.begin().xr("xrBeginFrame")?;
        if !frame.should_render || self.exit_requested {
            self.stream
                .end(frame.predicted_display_time, self.blend, &[])
                .xr("xrEndFrame")?;
            if !self.exit_requested {
                self.report.frames_skipped += 1;
            }
            return Ok(None);
        }
        Ok(Some(frame))
    }

    /// Locates the head and eyes for a frame displayed at `display`.
    fn locate(&mut self, display: xr::Time) -> Result<(Pose, Vec<xr::View>, bool)> {
        let head = self
            .view_space
            .locate(&self.space, display)
            .xr("xrLocateSpace")?;
        let (flags, views) = self
            .session
            .locate_views(
                xr::ViewConfigurationType::PRIMARY_STEREO,
                display,
                &self.space,
            )
            .xr("xrLocateViews")?;
        let tracked = head.location_flags.contains(
            xr::SpaceLocationFlags::POSITION_VALID | xr::SpaceLocationFlags::ORIENTATION_VALID,
        ) && flags
            .contains(xr::ViewStateFlags::POSITION_VALID | xr::ViewStateFlags::ORIENTATION_VALID);
        Ok((pose_of(&head.pose), views, tracked))
    }
}

impl Backend for Session {
    type Error = OpenXrError;

    fn wait_frame(&mut self) -> Result<Option<FrameInput>> {
        if self.pending.is_some() {
            return Err(OpenXrError::FrameOrder(
                "wait_frame called twice without end_frame".into(),
            ));
        }
        let mut since_change = Instant::now();
        let mut last_state = self.state;
        loop {
            if INTERRUPTED.load(Ordering::SeqCst) {
                self.stop(EndReason::Interrupted)?;
            }
            if self
                .options
                .max_frames
                .is_some_and(|max| self.report.frames_submitted >= max)
            {
                self.stop(EndReason::FrameLimit)?;
            }
            self.poll_events()?;
            if self.quit {
                tracing::info!(
                    "session over: {}",
                    self.report.end_reason.unwrap_or(EndReason::RuntimeExit)
                );
                return Ok(None);
            }
            if self.state != last_state {
                last_state = self.state;
                since_change = Instant::now();
            }
            if !(self.running && state::runs_frames(self.state)) {
                if since_change.elapsed() > STATE_TIMEOUT {
                    return Err(OpenXrError::Unsupported(format!(
                        "the session stayed {} for {} s (running: {}); is the runtime's \
                         compositor working?",
                        self.state,
                        STATE_TIMEOUT.as_secs(),
                        self.running
                    )));
                }
                std::thread::sleep(Duration::from_millis(5));
                continue;
            }
            let Some(frame) = self.begin_frame()? else {
                continue;
            };
            let display = frame.predicted_display_time;
            let image = self
                .swapchain
                .acquire_image()
                .xr("xrAcquireSwapchainImage")?;
            self.swapchain
                .wait_image(xr::Duration::INFINITE)
                .xr("xrWaitSwapchainImage")?;
            let depth_image = match &mut self.depth {
                Some((chain, _)) => {
                    let i = chain.acquire_image().xr("xrAcquireSwapchainImage(depth)")?;
                    chain
                        .wait_image(xr::Duration::INFINITE)
                        .xr("xrWaitSwapchainImage(depth)")?;
                    Some(i)
                }
                None => None,
            };
            // Views are located after the wait for the image, as late as this loop allows.
            let (head_space, views, tracked) = self.locate(display)?;
            if !tracked {
                self.report.frames_untracked += 1;
            }
            let first_display = *self.first_display.get_or_insert(display);
            let placed = *self.world_from_space.get_or_insert_with(|| {
                place_scene(
                    &head_space,
                    self.options.viewer_position_m,
                    self.options.scene_origin,
                )
            });
            // Live actions (and the eye-gaze action) are synced before the gaze is sampled and
            // before the placement is used, so a nudge shows in this very frame.
            self.sync_actions(compose(&placed, &head_space).position)?;
            let world_from_space = self.world_from_space.unwrap_or(placed);
            let gaze = self
                .gaze
                .sample(&self.session, &self.view_space, display, first_display);
            let eye = |v: &xr::View| EyeView {
                pose: compose(&world_from_space, &pose_of(&v.pose)),
                fov: Fov {
                    angle_left_rad: v.fov.angle_left,
                    angle_right_rad: v.fov.angle_right,
                    angle_up_rad: v.fov.angle_up,
                    angle_down_rad: v.fov.angle_down,
                },
            };
            let input = FrameInput {
                index: self.next_index,
                time_ns: display.as_nanos(),
                head: compose(&world_from_space, &head_space),
                views: [eye(&views[0]), eye(&views[1])],
                gaze,
            };
            self.pending = Some((
                Pending {
                    display,
                    views,
                    index: self.next_index,
                    depth_image,
                },
                image,
            ));
            self.next_index += 1;
            return Ok(Some(input));
        }
    }

    fn frame_target(&self) -> FrameTarget {
        match &self.pending {
            Some((pending, image)) => FrameTarget::Swapchain {
                index: *image,
                depth_index: pending.depth_image,
                world_behind: self.world_behind,
            },
            None => FrameTarget::Own,
        }
    }

    fn end_frame(&mut self, frame: &FrameInput) -> Result<()> {
        let Some((pending, _)) = self.pending.take() else {
            return Err(OpenXrError::FrameOrder(
                "end_frame without wait_frame".into(),
            ));
        };
        if pending.index != frame.index {
            return Err(OpenXrError::FrameOrder(format!(
                "end_frame for frame {} but frame {} is in flight",
                frame.index, pending.index
            )));
        }
        self.swapchain
            .release_image()
            .xr("xrReleaseSwapchainImage")?;
        if let (Some((chain, _)), Some(_)) = (&mut self.depth, pending.depth_image) {
            chain.release_image().xr("xrReleaseSwapchainImage(depth)")?;
        }
        let (w, h) = self.size;
        let rect = xr::Rect2Di {
            offset: xr::Offset2Di { x: 0, y: 0 },
            extent: xr::Extent2Di {
                width: w as i32,
                height: h as i32,
            },
        };
        let mut views: Vec<_> = pending
            .views
            .iter()
            .enumerate()
            .map(|(eye, v)| {
                xr::CompositionLayerProjectionView::new()
                    .pose(v.pose)
                    .fov(v.fov)
                    .sub_image(
                        xr::SwapchainSubImage::new()
                            .swapchain(&self.swapchain)
                            .image_array_index(eye as u32)
                            .image_rect(rect),
                    )
            })
            .collect();
        // Depth: the safe API cannot chain XrCompositionLayerDepthInfoKHR, so each view is
        // rebuilt from its raw struct with the depth info behind `next`. `depth_infos` lives
        // (unmoved) until xrEndFrame has returned.
        let mut depth_infos: Vec<xr::sys::CompositionLayerDepthInfoKHR> = Vec::new();
        if let (Some((chain, options)), Some(_)) = (&self.depth, pending.depth_image) {
            depth_infos = (0..views.len() as u32)
                .map(|eye| depth_info(chain.as_raw(), eye, rect, options))
                .collect();
            let mut raw: Vec<xr::sys::CompositionLayerProjectionView> =
                views.iter().map(|v| *v.as_raw()).collect();
            // SAFETY: `depth_infos` is not touched again before xrEndFrame returns; the
            // rebuilt views keep the colour swapchain they referenced (still alive in self).
            unsafe {
                chain_depth(&mut raw, &mut depth_infos);
                views = raw
                    .into_iter()
                    .map(|r| xr::CompositionLayerProjectionView::from_raw(r))
                    .collect();
            }
        }
        let layer = xr::CompositionLayerProjection::new()
            .space(&self.space)
            .views(&views);
        self.stream
            .end(pending.display, self.blend, &[&layer])
            .xr("xrEndFrame")?;
        drop(depth_infos);
        self.report.frames_submitted += 1;
        if pending.depth_image.is_some() {
            self.report.frames_with_depth += 1;
        }
        Ok(())
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        // A session dropped mid-frame (an error in the app) still ends its frame, so the
        // runtime is not left waiting.
        if let Some((pending, _)) = self.pending.take() {
            let _ = self.swapchain.release_image();
            if let (Some((chain, _)), Some(_)) = (&mut self.depth, pending.depth_image) {
                let _ = chain.release_image();
            }
            let _ = self.stream.end(pending.display, self.blend, &[]);
        }
        if self.running {
            let _ = self.session.request_exit();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_is_placed_at_the_first_head_pose_facing_forward() {
        let head0 = Pose {
            position: Vec3::new(0.5, 1.6, -1.0),
            orientation: Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.2),
        };
        let w = place_scene(&head0, Vec3::ZERO, None);
        let head_world = compose(&w, &head0);
        assert!(head_world.position.length() < 1e-5, "{head_world:?}");
        // Looking forward (-z) in the scene, pitch kept.
        let f = head_world.orientation * Vec3::NEG_Z;
        assert!(f.x.abs() < 1e-5 && f.z < 0.0, "{f}");
        // Round trip of the helpers.
        let back = compose(&inverse(&w), &head_world);
        assert!((back.position - head0.position).length() < 1e-5);
    }
    #[test]
    fn a_nudge_moves_the_scene_and_a_turn_keeps_the_head_in_place() {
        let head0 = Pose {
            position: Vec3::new(0.3, 1.6, 0.2),
            orientation: Quat::from_rotation_y(0.4),
        };
        let w = place_scene(&head0, Vec3::ZERO, None);
        let head_m = compose(&w, &head0).position;
        // The scene moves 1 cm away (-z): the head's scene coordinates move 1 cm the other way.
        let d = Vec3::new(0.0, 0.0, -0.01);
        let nudged = re_register(&w, Command::Nudge(d), head_m);
        let moved = compose(&nudged, &head0).position - head_m;
        assert!((moved + d).length() < 1e-6, "{moved}");
        // A turn about the head: the head stays, its view turns the other way in the scene,
        // so the scene appears turned by +a (to the left).
        let a = 0.1;
        let turned = re_register(&w, Command::Rotate(a), head_m);
        let head = compose(&turned, &head0);
        assert!((head.position - head_m).length() < 1e-5);
        let f = head.orientation * Vec3::NEG_Z;
        let f0 = compose(&w, &head0).orientation * Vec3::NEG_Z;
        let yaw = |v: Vec3| (-v.x).atan2(-v.z);
        assert!((yaw(f) - yaw(f0) + a).abs() < 1e-5, "{f} {f0}");
        // Other commands leave the placement alone.
        assert_eq!(
            re_register(&w, Command::Cycle(crate::openxr::Cycle::Secondary), head_m),
            w
        );
    }

    #[test]
    fn each_view_chains_its_depth_info() {
        let rect = xr::Rect2Di {
            offset: xr::Offset2Di { x: 0, y: 0 },
            extent: xr::Extent2Di {
                width: 320,
                height: 240,
            },
        };
        let options = DepthOptions {
            format: vk::Format::D32_SFLOAT,
            near_m: 0.02,
            far_m: 100.0,
        };
        let chain = <xr::sys::Swapchain as xr::sys::Handle>::from_raw(7);
        let mut infos: Vec<_> = (0..2)
            .map(|l| depth_info(chain, l, rect, &options))
            .collect();
        let view = *xr::CompositionLayerProjectionView::<xr::Vulkan>::new().as_raw();
        let mut views = [view, view];
        unsafe { chain_depth(&mut views, &mut infos) };
        for (eye, v) in views.iter().enumerate() {
            let info = unsafe { &*(v.next as *const xr::sys::CompositionLayerDepthInfoKHR) };
            assert_eq!(
                info.ty,
                xr::sys::StructureType::COMPOSITION_LAYER_DEPTH_INFO_KHR
            );
            assert!(info.next.is_null());
            assert_eq!(info.sub_image.swapchain, chain);
            assert_eq!(info.sub_image.image_array_index, eye as u32);
            assert_eq!(info.sub_image.image_rect.extent.width, 320);
            assert_eq!((info.min_depth, info.max_depth), (0.0, 1.0));
            assert_eq!((info.near_z, info.far_z), (0.02, 100.0));
        }
    }
}
