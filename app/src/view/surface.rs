//! The window's Vulkan surface (ash-window) and the renderer's presenter on it.

use std::sync::Arc;

use anyhow::{Context, Result};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use vitreous_render::{GpuContext, PresentWindow, Presenter};
use winit::window::Window;

/// The winit window as the presenter sees it; keeps the window alive as long as its surface.
pub struct ShownWindow(
    /// The window.
    Arc<Window>,
);

impl PresentWindow for ShownWindow {
    fn size(&self) -> (u32, u32) {
        let s = self.0.inner_size();
        (s.width, s.height)
    }

    fn presenting(&self) {
        self.0.pre_present_notify();
    }

    fn presented(&self) {
        // The windowing system's answer is `RedrawRequested` (`DesktopWindow::redraw_due`).
        self.0.request_redraw();
    }
}

/// The presenter of the window's pictures.
pub type WindowPresenter = Presenter<ShownWindow>;

/// The instance extensions a surface on this window's display needs.
pub fn surface_extensions(window: &Window) -> Result<Vec<&'static std::ffi::CStr>> {
    let display = window.display_handle().context("the window's display")?;
    let names = ash_window::enumerate_required_extensions(display.as_raw())
        .context("no Vulkan surface extension for this display (X11 or Wayland expected)")?;
    Ok(names
        .iter()
        // SAFETY: `ash_window` returns pointers to static NUL-terminated extension names.
        .map(|&p| unsafe { std::ffi::CStr::from_ptr(p) })
        .collect())
}

/// The window's surface and the presenter on it, on `ctx`, which must have been made with
/// [`surface_extensions`] and `VK_KHR_swapchain`.
pub fn presenter(ctx: GpuContext, window: Arc<Window>) -> Result<WindowPresenter> {
    let display = window.display_handle().context("the window's display")?;
    let handle = window.window_handle().context("the window's handle")?;
    // SAFETY: the instance was created with the extensions `ash_window` asks for this
    // display (surface_extensions); the handles are the live window's, which the presenter
    // keeps alive (its `ShownWindow`) until the surface is destroyed in its Drop.
    let surface = unsafe {
        ash_window::create_surface(
            &ctx.entry,
            &ctx.instance,
            display.as_raw(),
            handle.as_raw(),
            None,
        )
    }
    .context("creating the window's Vulkan surface")?;
    // SAFETY: the surface was just made on `ctx`'s instance for `window`, which the
    // `ShownWindow` keeps alive; nothing else holds it, so the presenter owns it.
    unsafe { Presenter::new(ctx, surface, ShownWindow(window)) }
        .context("setting up presentation to the window")
}
