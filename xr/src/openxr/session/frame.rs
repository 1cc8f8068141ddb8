//! The frame scope: waiting for and beginning a frame, acquiring the swapchain images,
//! locating the views, and ending the frame with its projection (and depth) layer.
//!
//! From xrBeginFrame to xrEndFrame the session holds an [`OpenFrame`] that records what the
//! frame has taken from the runtime. Every way out of it ends the frame: [`Backend::end_frame`]
//! with the layer; an error while the frame is being prepared, [`Backend::abandon_frame`] (the
//! app's error after the frame was handed out) and a session dropped mid-frame all unwind it
//! ([`Session::abandon_open_frame`]): acquired images waited for and released, xrEndFrame with
//! no layers. Errors of that clean-up are logged; the error that caused it is the one returned.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use openxr as xr;

use super::super::convert::pose_of;
use super::super::state::{self, EndReason};
use super::super::{DepthOptions, OpenXrError, Result, XrContext};
use super::frame_end::FrameEndChain;
use super::placement::{compose, place_scene};
use super::scope::{Handed, Hold, OpenFrame, Unwind};
use super::{INTERRUPTED, STATE_TIMEOUT, Session};
use crate::frame::{Backend, EyeView, Fov, FrameInput, FrameTarget, Pose};

impl Session {
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
        self.swapchain
            .wait_image(xr::Duration::INFINITE)
            .xr("xrWaitSwapchainImage")?;
        self.open_frame()?.color = Hold::Waited;
        let Some((chain, _)) = &mut self.depth else {
            return Ok((image, None));
        };
        let depth = chain.acquire_image().xr("xrAcquireSwapchainImage(depth)")?;
        self.open_frame()?.depth = Hold::Acquired;
        if let Some((chain, _)) = &mut self.depth {
            chain
                .wait_image(xr::Duration::INFINITE)
                .xr("xrWaitSwapchainImage(depth)")?;
        }
        self.open_frame()?.depth = Hold::Waited;
        Ok((image, Some(depth)))
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

    /// Everything between xrBeginFrame and handing the frame out: images, views, placement,
    /// actions, gaze. Any error leaves the open frame for the caller to unwind.
    fn prepare_frame(&mut self, display: xr::Time) -> Result<FrameInput> {
        let (image, depth_image) = self.acquire_images()?;
        // Views are located after the wait for the image, as late as this loop allows.
        let (head_space, views, tracked) = self.locate(display)?;
        if !tracked {
            self.report.frames_untracked += 1;
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
        let gaze = sampled.frame;
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
        self.open_frame()?.handed = Some(Handed {
            index: self.next_index,
            views,
            image,
            depth_image,
        });
        self.next_index += 1;
        Ok(input)
    }

    /// Leaves the open frame, if any, without showing it: acquired images waited for and
    /// released, xrEndFrame with no layers. Failures are logged (the caller is already on an
    /// error path, or dropping the session); the frame counts as ended either way.
    pub(super) fn abandon_open_frame(&mut self) {
        let Some(open) = self.open.take() else {
            return;
        };
        tracing::warn!(
            "frame at {} ns left without being shown: ending it with no layers",
            open.display.as_nanos()
        );
        for step in open.unwind() {
            let done = match step {
                Unwind::WaitColor => self
                    .swapchain
                    .wait_image(xr::Duration::INFINITE)
                    .xr("xrWaitSwapchainImage"),
                Unwind::ReleaseColor => {
                    self.swapchain.release_image().xr("xrReleaseSwapchainImage")
                }
                Unwind::WaitDepth => match &mut self.depth {
                    Some((chain, _)) => chain
                        .wait_image(xr::Duration::INFINITE)
                        .xr("xrWaitSwapchainImage(depth)"),
                    None => Ok(()),
                },
                Unwind::ReleaseDepth => match &mut self.depth {
                    Some((chain, _)) => chain.release_image().xr("xrReleaseSwapchainImage(depth)"),
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
        self.report.frames_abandoned += 1;
    }

    /// Releases the handed-out frame's images and submits it with its projection layer.
    fn submit_frame(&mut self, handed: &Handed, display: xr::Time) -> Result<()> {
        self.swapchain
            .release_image()
            .xr("xrReleaseSwapchainImage")?;
        self.open_frame()?.color = Hold::Free;
        if let (Some((chain, _)), Some(_)) = (&mut self.depth, handed.depth_image) {
            chain.release_image().xr("xrReleaseSwapchainImage(depth)")?;
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
            return match self.prepare_frame(frame.predicted_display_time) {
                Ok(input) => Ok(Some(input)),
                Err(e) => {
                    self.abandon_open_frame();
                    Err(e)
                }
            };
        }
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
        let submitted = self.submit_frame(&handed, display);
        if submitted.is_err() {
            // Whatever is still held (an image not released, the frame not ended) goes back.
            self.abandon_open_frame();
        }
        submitted
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
        if self.running {
            let _ = self.session.request_exit();
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

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk;

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
        // SAFETY: `infos` lives, unmoved, until the end of this test, past every use of `views`.
        unsafe { chain_depth(&mut views, &mut infos) };
        for (eye, v) in views.iter().enumerate() {
            // SAFETY: `chain_depth` set `next` to an element of `infos`, still alive here.
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
