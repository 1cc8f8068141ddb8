//! The OpenXR runtime, the renderer whose Vulkan device it made, and the session drawing into
//! its swapchain images, owned together so they come down in the order they need: the renderer
//! lets go of the swapchain images, the session (which owns them) ends, then the renderer with
//! the device, then the runtime. The order is this type's, not its caller's statements'.

use anyhow::{Context, Result};
use vitreous_render::{ContextOptions, GpuContext, Renderer};
use vitreous_xr::openxr::ash::vk;
use vitreous_xr::openxr::{
    Runtime, Session, SessionOptions, SessionReport, VulkanHandles, XrDeviceCreator,
};

/// A live OpenXR session with the renderer attached to its swapchain images.
pub struct XrSession {
    /// `Some` until [`XrSession::close`] or the drop, which detach the images first.
    session: Option<Session>,
    /// Declared before the runtime: dropped before it (the device before the OpenXR instance).
    renderer: Renderer,
    /// Held only to go last.
    _runtime: Runtime,
    format: vk::Format,
}

/// What a closed session leaves to report.
pub struct Closed<T> {
    /// Releasing the swapchain images (an error after a lost device).
    pub detached: Result<()>,
    /// The session's own report.
    pub report: SessionReport,
    /// What `after` read from the renderer once the session had ended.
    pub after: T,
}

impl XrSession {
    /// Creates the renderer's Vulkan instance and device through `runtime`
    /// (XR_KHR_vulkan_enable2), the renderer on them (`make_renderer`), the session on that
    /// device, and attaches the session's swapchain images to the renderer.
    pub fn start(
        mut runtime: Runtime,
        context: &ContextOptions,
        make_renderer: impl FnOnce(GpuContext) -> Result<Renderer>,
        options: &SessionOptions,
    ) -> Result<XrSession> {
        let ctx = GpuContext::new(
            context,
            &mut XrDeviceCreator {
                runtime: &mut runtime,
            },
            &[],
            &[],
        )
        .context("setting up the Vulkan device through the OpenXR runtime")?;
        let renderer = make_renderer(ctx)?;
        let c = renderer.context();
        let handles = VulkanHandles {
            instance: c.instance.handle(),
            physical: c.physical,
            device: c.device.handle(),
            queue_family: c.queue_family,
            queue_index: 0,
        };
        // SAFETY: `handles` are the instance, device and queue `runtime` created just above for
        // the renderer's context; the session goes into the value that owns the renderer, whose
        // drop ends the session before the renderer's.
        let (session, images) =
            unsafe { runtime.start(handles, options) }.context("starting the OpenXR session")?;
        let mut this = XrSession {
            session: Some(session),
            renderer,
            _runtime: runtime,
            format: images.format,
        };
        if !images.srgb {
            // OpenXR reads a UNORM image as linear light: right, in 8 bits.
            tracing::warn!(
                "the runtime offers no sRGB swapchain format: frames are stored as linear \
                 8-bit values ({:?}), so dark gradients band",
                images.format
            );
        }
        // SAFETY: the images are the session's swapchain images, made on the renderer's device;
        // `this` holds the session and detaches them from the renderer before the session ends
        // (`close`, or the drop).
        unsafe {
            this.renderer.attach_external_with_depth(
                &images.images,
                images.format,
                &images.depth_images,
            )
        }
        .context("using the swapchain images")?;
        Ok(this)
    }

    /// The session and the renderer, for the frame loop.
    pub fn parts(&mut self) -> (&mut Session, &mut Renderer) {
        let session = self
            .session
            .as_mut()
            .expect("the session lives until `close` takes the value");
        (session, &mut self.renderer)
    }

    /// The session (its report, commands and command sender).
    pub fn session(&mut self) -> &mut Session {
        self.parts().0
    }

    /// The swapchain images' format.
    pub fn format(&self) -> vk::Format {
        self.format
    }

    /// Detaches the swapchain images and ends the session, then reads `after` from the
    /// renderer (e.g. the validation layers' messages, with those of the session's end), then
    /// lets the renderer and the runtime go.
    pub fn close<T>(mut self, after: impl FnOnce(&mut Renderer) -> T) -> Closed<T> {
        let detached = self
            .renderer
            .detach_external()
            .context("releasing the swapchain images");
        let session = self
            .session
            .take()
            .expect("the session lives until `close` takes the value");
        let report = session.report().clone();
        drop(session);
        Closed {
            detached,
            report,
            after: after(&mut self.renderer),
        }
    }
}

impl Drop for XrSession {
    /// An early end (an error): the images out of the renderer before their session ends.
    fn drop(&mut self) {
        if let Some(session) = self.session.take() {
            if let Err(e) = self.renderer.detach_external() {
                tracing::warn!("releasing the swapchain images: {e:#}");
            }
            drop(session);
        }
    }
}
