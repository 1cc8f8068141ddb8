//! The frame scope: waiting for and beginning a frame, acquiring the swapchain images,
//! locating the views, and ending the frame with its projection (and depth) layer.
//!
//! From xrBeginFrame to xrEndFrame the session holds an [`OpenFrame`] that records what the
//! frame has taken from the runtime. Every way out of it ends the frame: [`Backend::end_frame`]
//! with the layer; an error while the frame is being prepared, [`Backend::abandon_frame`] (the
//! app's error after the frame was handed out), a frame the head's orientation was not tracked
//! for, and a session dropped mid-frame all unwind it ([`Session::leave_open_frame`]):
//! acquired images waited for and released, xrEndFrame with no layers.
//!
//! What a real headset does on the way ([`super::interruptions`]): a frame the runtime says
//! not to render is ended with no layers; a call that fails with `XR_ERROR_RUNTIME_FAILURE`
//! costs its frame and the session goes on; a lost session or runtime ends the session (the
//! app may start a new one); a runtime that stops the session (the headset taken off) is waited
//! for, without a time limit, until it makes the session ready again.
//!
//! Every step of the scope (wait, begin, acquire, submit, leave) reads and writes the same open
//! frame and the session's counts of what a misbehaving headset did; what can stand apart does
//! (`scope.rs`, `locate.rs`, `tracking.rs`, `interruptions.rs`, `images.rs`, `depth.rs`,
//! `gaze_time.rs`, `display_time.rs`).

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use openxr as xr;
use vitreous_trace::session_event::{NotRendered, SessionEvent};
use vitreous_trace::{EyeView, Fov, FrameInput};

use super::super::state::{self, EndReason};
use super::super::{OpenXrError, Result, XrContext};
use super::depth::{chain_depth, depth_info};
use super::display_time::bad_display_time;
use super::frame_end::FrameEndChain;
use super::images;
use super::interruptions::{MAX_FAILED_FRAMES_IN_A_ROW, Pending, Severity, severity};
use super::placement::{compose, place_scene};
use super::scope::{Handed, Hold, OpenFrame, Unwind};
use super::tracking::Located;
use super::{INTERRUPTED, STATE_TIMEOUT, Session};
use crate::{Backend, FrameTarget};

/// How often the session says it is still waiting for a runtime that stopped it.
const PAUSE_LOG_EVERY: Duration = Duration::from_secs(30);

/// What preparing a begun frame came to.
enum Prepared {
    /// The frame for the app.
    Input(Box<FrameInput>),
    /// Not drawn (the head's orientation not tracked): already ended with no layers.
    NotDrawn,
}

impl Session {
    /// Waits and begins a frame; `None` when it is not to be rendered (it is then ended here
    /// with no layers, and counted).
    fn begin_frame(&mut self) -> Result<Option<xr::FrameState>> {
        let frame = self.waiter.wait().xr("xrWaitFrame")?;
        self.report.interruptions.frames_waited += 1;
        let display = frame.predicted_display_time.as_nanos();
        let now = Instant::now();
        if let Some(bad) = bad_display_time(display, self.last_display, now) {
            self.stream.begin().xr("xrBeginFrame")?;
            self.leave_bad_time(&frame, bad)?;
            return Ok(None);
        }
        self.last_display = Some((display, now));
        self.note_lateness(&frame);
        self.stream.begin().xr("xrBeginFrame")?;
        if !frame.should_render || self.exit_requested {
            self.stream
                .end(frame.predicted_display_time, self.blend, &[])
                .xr("xrEndFrame")?;
            if self.exit_requested {
                self.report.interruptions.not_rendered_exiting += 1;
            } else {
                self.report.frames_skipped += 1;
                self.pending.not_rendered(NotRendered::Runtime);
            }
            return Ok(None);
        }
        self.open = Some(OpenFrame::begun(frame.predicted_display_time));
        Ok(Some(frame))
    }

    /// The open frame, which every step after xrBeginFrame needs.
    fn open_frame(&mut self) -> Result<&mut OpenFrame> {
        self.open
            .as_mut()
            .ok_or_else(|| OpenXrError::FrameOrder("no frame is begun".into()))
    }

    /// Acquires and waits for the colour (and depth) swapchain image of the open frame,
    /// recording each step in it so an error can unwind exactly what was taken.
    fn acquire_images(&mut self) -> Result<(u32, Option<u32>)> {
        let image = self
            .swapchain
            .acquire_image()
            .xr("xrAcquireSwapchainImage")?;
        self.open_frame()?.color = Hold::Acquired;
        self.report.interruptions.image_wait_timeouts +=
            images::wait(&self.instance, &self.swapchain, "xrWaitSwapchainImage")?;
        self.open_frame()?.color = Hold::Waited;
        let Some((chain, _)) = &mut self.depth else {
            return Ok((image, None));
        };
        let depth = chain.acquire_image().xr("xrAcquireSwapchainImage(depth)")?;
        self.open_frame()?.depth = Hold::Acquired;
        if let Some((chain, _)) = &self.depth {
            self.report.interruptions.image_wait_timeouts +=
                images::wait(&self.instance, chain, "xrWaitSwapchainImage(depth)")?;
        }
        self.open_frame()?.depth = Hold::Waited;
        Ok((image, Some(depth)))
    }

    /// Everything between xrBeginFrame and handing the frame out: images, views, placement,
    /// actions, gaze. Any error leaves the open frame for the caller to unwind.
    fn prepare_frame(&mut self, display: xr::Time) -> Result<Prepared> {
        let (image, depth_image) = self.acquire_images()?;
        // Views are located after the wait for the image, as late as this loop allows.
        let (poses, mut views) = self.locate(display)?;
        if !(poses.position_valid && poses.orientation_valid) {
            self.report.frames_untracked += 1;
        }
        let mut tracking_events = Vec::new();
        let located = self.tracking.locate(poses, &mut tracking_events);
        for e in tracking_events {
            if let SessionEvent::TrackingLost(loss) = e {
                self.report.interruptions.tracking_losses[loss as usize] += 1;
            }
            self.pending.push(e);
        }
        let Located::Draw {
            head: head_space,
            eyes,
            held,
        } = located
        else {
            self.leave_open_frame();
            self.report.interruptions.not_rendered_tracking += 1;
            self.pending.not_rendered(NotRendered::Tracking);
            return Ok(Prepared::NotDrawn);
        };
        if held {
            self.report.interruptions.frames_position_held += 1;
            for (view, eye) in views.iter_mut().zip(eyes) {
                view.pose = super::super::convert::posef_of(&eye);
            }
        }
        let first_display = *self.first_display.get_or_insert(display);
        let placed = match self.world_from_space {
            Some(w) => w,
            None => {
                let placed = place_scene(
                    &head_space,
                    self.options.viewer_position_m,
                    self.options.scene_origin,
                );
                if self.report.space_changes > 0 {
                    tracing::info!(
                        "scene re-anchored at the head pose of frame {}",
                        self.next_index
                    );
                }
                self.world_from_space = Some(placed);
                placed
            }
        };
        // Live actions (and the eye-gaze action) are synced before the gaze is sampled and
        // before the placement is used, so a nudge shows in this very frame.
        let head_m = compose(&placed, &head_space).position;
        self.sync_actions(head_m)?;
        self.apply_injected(head_m);
        let world_from_space = self.world_from_space.unwrap_or(placed);
        self.poll_planes(display, &head_space, &world_from_space);
        self.poll_light(display, &world_from_space);
        let sampled = self
            .gaze
            .sample(&self.session, &self.view_space, display, first_display);
        self.report.gaze_samples.count(&sampled);
        let gaze = self.order_gaze(&sampled, display.as_nanos());
        let eye = |i: usize| EyeView {
            pose: compose(&world_from_space, &eyes[i]),
            fov: Fov {
                angle_left_rad: views[i].fov.angle_left,
                angle_right_rad: views[i].fov.angle_right,
                angle_up_rad: views[i].fov.angle_up,
                angle_down_rad: views[i].fov.angle_down,
            },
        };
        let input = FrameInput {
            index: self.next_index,
            time_ns: display.as_nanos(),
            head: compose(&world_from_space, &head_space),
            views: [eye(0), eye(1)],
            gaze,
        };
        self.open_frame()?.handed = Some(Handed {
            index: self.next_index,
            views,
            image,
            depth_image,
        });
        self.next_index += 1;
        Ok(Prepared::Input(Box::new(input)))
    }

    /// Leaves the open frame, if any, without showing it: acquired images waited for and
    /// released, xrEndFrame with no layers. Failures are logged (the caller is already on an
    /// error path, or dropping the session); the frame counts as ended either way. Whether
    /// there was a frame to leave.
    pub(super) fn leave_open_frame(&mut self) -> bool {
        let Some(open) = self.open.take() else {
            return false;
        };
        for step in open.unwind() {
            let done = match step {
                Unwind::WaitColor => {
                    images::wait(&self.instance, &self.swapchain, "xrWaitSwapchainImage").map(drop)
                }
                Unwind::ReleaseColor => {
                    images::release(&self.instance, &self.swapchain, "xrReleaseSwapchainImage")
                }
                Unwind::WaitDepth => match &self.depth {
                    Some((chain, _)) => {
                        images::wait(&self.instance, chain, "xrWaitSwapchainImage(depth)").map(drop)
                    }
                    None => Ok(()),
                },
                Unwind::ReleaseDepth => match &self.depth {
                    Some((chain, _)) => {
                        images::release(&self.instance, chain, "xrReleaseSwapchainImage(depth)")
                    }
                    None => Ok(()),
                },
                Unwind::EndWithoutLayers => self
                    .stream
                    .end(open.display, self.blend, &[])
                    .xr("xrEndFrame"),
            };
            if let Err(e) = done {
                tracing::warn!("while leaving the frame: {e}");
            }
        }
        true
    }

    /// Leaves the open frame after an error, counting it abandoned.
    pub(super) fn abandon_open_frame(&mut self) {
        if let Some(open) = &self.open {
            tracing::warn!(
                "frame at {} ns left without being shown: ending it with no layers",
                open.display.as_nanos()
            );
        }
        if self.leave_open_frame() {
            self.report.frames_abandoned += 1;
        }
    }

    /// Takes an error of a frame call as its severity says: `Ok` when the session goes on (one
    /// frame lost to a runtime failure) or ends (lost), the error itself when it is fatal.
    fn take_failure(&mut self, e: OpenXrError) -> Result<()> {
        match severity(&e) {
            Severity::Frame => {
                if let OpenXrError::Call { call, .. } = &e {
                    *self
                        .report
                        .interruptions
                        .failed_calls
                        .entry(call)
                        .or_default() += 1;
                }
                self.failed_in_a_row += 1;
                if self.failed_in_a_row > MAX_FAILED_FRAMES_IN_A_ROW {
                    return Err(OpenXrError::Unsupported(format!(
                        "{MAX_FAILED_FRAMES_IN_A_ROW} frames in a row failed; the last: {e}"
                    )));
                }
                tracing::warn!("{e}: the frame is left and the session goes on");
                self.pending.not_rendered(NotRendered::Failed);
                Ok(())
            }
            Severity::Lost(loss) => {
                tracing::warn!("{e}");
                self.lose(loss);
                Ok(())
            }
            Severity::Fatal => Err(e),
        }
    }

    /// Releases the handed-out frame's images and submits it with its projection layer.
    fn submit_frame(&mut self, handed: &Handed, display: xr::Time) -> Result<()> {
        images::release(&self.instance, &self.swapchain, "xrReleaseSwapchainImage")?;
        self.open_frame()?.color = Hold::Free;
        if let (Some((chain, _)), Some(_)) = (&self.depth, handed.depth_image) {
            images::release(&self.instance, chain, "xrReleaseSwapchainImage(depth)")?;
            self.open_frame()?.depth = Hold::Free;
        }
        let (w, h) = self.size;
        let rect = xr::Rect2Di {
            offset: xr::Offset2Di { x: 0, y: 0 },
            extent: xr::Extent2Di {
                width: w as i32,
                height: h as i32,
            },
        };
        let mut views: Vec<_> = handed
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
        if let (Some((chain, options)), Some(_)) = (&self.depth, handed.depth_image) {
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
            .views(&views)
            .layer_flags(self.layer_flags);
        let chain = FrameEndChain::new(
            self.ml_frame_end
                .then_some(self.hints.focus_distance_m)
                .flatten(),
            self.ml_dimmer.then_some(self.hints.global_dimmer).flatten(),
        );
        if chain.is_empty() {
            self.stream
                .end(display, self.blend, &[&layer])
                .xr("xrEndFrame")?;
        } else {
            let layers = [&layer as &xr::CompositionLayerBase<'_, xr::Vulkan>];
            let info = xr::sys::FrameEndInfo {
                ty: xr::sys::FrameEndInfo::TYPE,
                next: chain.head(),
                display_time: display,
                environment_blend_mode: self.blend,
                layer_count: 1,
                layers: layers.as_ptr() as *const *const xr::sys::CompositionLayerBaseHeader,
            };
            // SAFETY: the session is running with a frame begun (xrBeginFrame succeeded for
            // `handed`); `info`, the layer, its views, their depth infos and the chain all live
            // until the call returns, and the chain's structures are those the enabled
            // extensions define.
            let result = unsafe { (self.instance.fp().end_frame)(self.session.as_raw(), &info) };
            if result.into_raw() < 0 {
                return Err(OpenXrError::Call {
                    call: "xrEndFrame",
                    result,
                });
            }
            if let Some(m) = chain.focus_distance_m() {
                self.report.frames_with_focus_distance += 1;
                self.report.last_focus_distance_m = Some(m);
            }
            if chain.has_global_dimmer() {
                self.report.frames_with_global_dimmer += 1;
            }
        }
        drop(depth_infos);
        self.open = None;
        self.report.frames_submitted += 1;
        if handed.depth_image.is_some() {
            self.report.frames_with_depth += 1;
        }
        Ok(())
    }

    /// Waits while the session does not run frames: before it is first ready or while it
    /// walks to its end, for at most [`STATE_TIMEOUT`] in one state; after the runtime stopped
    /// it (the headset taken off), as long as it takes, saying so every
    /// [`PAUSE_LOG_EVERY`].
    fn wait_for_state(&mut self, since_change: Instant) -> Result<()> {
        match self.paused {
            Some((since, logged)) if logged.elapsed() >= PAUSE_LOG_EVERY => {
                tracing::info!(
                    "waiting for the runtime to make the session ready again (stopped {} s ago: \
                     is the headset off?)",
                    since.elapsed().as_secs()
                );
                self.paused = Some((since, Instant::now()));
            }
            Some(_) => {}
            None if since_change.elapsed() > STATE_TIMEOUT => {
                return Err(OpenXrError::Unsupported(format!(
                    "the session stayed {} for {} s (running: {}); is the runtime's compositor \
                     working?",
                    self.state,
                    STATE_TIMEOUT.as_secs(),
                    self.running
                )));
            }
            None => {}
        }
        std::thread::sleep(Duration::from_millis(5));
        Ok(())
    }
}

impl Backend for Session {
    type Error = OpenXrError;

    fn wait_frame(&mut self) -> Result<Option<FrameInput>> {
        if self.open.is_some() {
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
            if self
                .options
                .end
                .as_ref()
                .is_some_and(|end| end.load(Ordering::SeqCst))
            {
                self.stop(EndReason::AppDone)?;
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
                self.wait_for_state(since_change)?;
                continue;
            }
            let frame = match self.begin_frame() {
                Ok(Some(frame)) => frame,
                Ok(None) => continue,
                Err(e) => match severity(&e) {
                    // A frame call that fails (waiting, beginning) cannot be left one frame
                    // later: only a loss is survived here.
                    Severity::Lost(loss) => {
                        tracing::warn!("{e}");
                        self.leave_open_frame();
                        self.lose(loss);
                        continue;
                    }
                    _ => return Err(e),
                },
            };
            match self.prepare_frame(frame.predicted_display_time) {
                Ok(Prepared::Input(input)) => {
                    self.failed_in_a_row = 0;
                    return Ok(Some(*input));
                }
                Ok(Prepared::NotDrawn) => continue,
                Err(e) => {
                    self.abandon_open_frame();
                    self.take_failure(e)?;
                }
            }
        }
    }

    fn take_events(&mut self) -> Vec<SessionEvent> {
        let events = self.pending.take();
        Pending::log(&events);
        events
    }

    fn frame_target(&self) -> FrameTarget {
        match self.open.as_ref().and_then(|o| o.handed.as_ref()) {
            Some(handed) => FrameTarget::Swapchain {
                index: handed.image,
                depth_index: handed.depth_image,
                blend: self.display_blend,
            },
            None => FrameTarget::Own,
        }
    }

    fn end_frame(&mut self, frame: &FrameInput) -> Result<()> {
        let Some(open) = &self.open else {
            return Err(OpenXrError::FrameOrder(
                "end_frame without wait_frame".into(),
            ));
        };
        let display = open.display;
        let Some(handed) = open.handed.clone() else {
            return Err(OpenXrError::FrameOrder(
                "end_frame for a frame that was not handed out".into(),
            ));
        };
        if handed.index != frame.index {
            return Err(OpenXrError::FrameOrder(format!(
                "end_frame for frame {} but frame {} is in flight",
                frame.index, handed.index
            )));
        }
        match self.submit_frame(&handed, display) {
            Ok(()) => Ok(()),
            Err(e) => {
                // Whatever is still held (an image not released, the frame not ended) goes
                // back; a failure the session survives is counted, not returned.
                self.abandon_open_frame();
                self.take_failure(e)
            }
        }
    }

    fn set_frame_end_hints(&mut self, hints: crate::FrameEndHints) {
        self.hints = hints;
    }

    fn abandon_frame(&mut self) {
        self.abandon_open_frame();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        // A session dropped mid-frame (an error in the app) still ends its frame, so the
        // runtime is not left waiting.
        self.abandon_open_frame();
        if self.running && self.report.interruptions.lost.is_none() {
            let _ = self.session.request_exit();
        }
    }
}
