//! The window and its events (winit, X11 or Wayland), pumped once per frame by the desktop
//! backend so the frame loop, not the event loop, drives the program.

use std::sync::Arc;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::platform::pump_events::EventLoopExtPumpEvents;
use winit::window::{Window, WindowAttributes, WindowId};

use super::input::InputEvent;

/// What the event handler collected since the last pump.
struct Handler {
    /// How to make the window.
    attributes: WindowAttributes,
    /// The window, once the event loop made it.
    window: Option<Arc<Window>>,
    /// Why the window could not be made.
    error: Option<String>,
    /// Input since the last pump.
    events: Vec<InputEvent>,
    /// The window was asked to close.
    close_requested: bool,
    /// The window changed size since the last pump.
    resized: bool,
    /// Shift is held.
    shift: bool,
    /// The windowing system asked for a picture (`RedrawRequested`) since the last one was
    /// presented: presenting now does not wait for it.
    redraw_due: bool,
}

impl ApplicationHandler for Handler {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            match event_loop.create_window(self.attributes.clone()) {
                Ok(w) => self.window = Some(Arc::new(w)),
                Err(e) => self.error = Some(e.to_string()),
            }
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => self.close_requested = true,
            WindowEvent::Resized(_) | WindowEvent::ScaleFactorChanged { .. } => {
                self.resized = true;
            }
            WindowEvent::RedrawRequested => self.redraw_due = true,
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } => {
                if event.repeat {
                    return;
                }
                let name = match &event.logical_key {
                    Key::Character(c) => c.to_lowercase(),
                    Key::Named(named) => match named_key(*named) {
                        Some(n) => n.to_string(),
                        None => return,
                    },
                    _ => return,
                };
                self.events.push(InputEvent::Key {
                    name,
                    pressed: event.state == ElementState::Pressed,
                });
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some(w) = &self.window {
                    let size = w.inner_size();
                    if size.width > 0 && size.height > 0 {
                        self.events.push(InputEvent::Cursor {
                            x: (position.x / f64::from(size.width)).clamp(0.0, 1.0) as f32,
                            y: (position.y / f64::from(size.height)).clamp(0.0, 1.0) as f32,
                        });
                    }
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let name = match button {
                    MouseButton::Left => "left",
                    MouseButton::Right => "right",
                    MouseButton::Middle => "middle",
                    _ => return,
                };
                self.events.push(InputEvent::Button {
                    name: name.into(),
                    pressed: state == ElementState::Pressed,
                });
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                self.events.push(InputEvent::Wheel(notches));
            }
            _ => {}
        }
    }
}

/// The names of the named keys the viewer uses.
fn named_key(key: NamedKey) -> Option<&'static str> {
    Some(match key {
        NamedKey::F1 => "f1",
        NamedKey::Tab => "tab",
        NamedKey::Space => "space",
        NamedKey::Escape => "escape",
        NamedKey::Shift => "shift",
        NamedKey::ArrowLeft => "left",
        NamedKey::ArrowRight => "right",
        NamedKey::ArrowUp => "up",
        NamedKey::ArrowDown => "down",
        NamedKey::PageUp => "pageup",
        NamedKey::PageDown => "pagedown",
        _ => return None,
    })
}

/// What one pump of the event loop brought.
#[derive(Default)]
pub struct Pumped {
    /// Input events, in order.
    pub events: Vec<InputEvent>,
    /// Whether shift was held at the end.
    pub shift: bool,
    /// The user closed the window (or the display went away).
    pub closed: bool,
    /// The window changed size.
    pub resized: bool,
}

impl Pumped {
    /// Adds what a later pump brought.
    pub fn merge(&mut self, later: Pumped) {
        self.events.extend(later.events);
        self.shift = later.shift;
        self.closed |= later.closed;
        self.resized |= later.resized;
    }
}

/// The window and its event loop.
pub struct DesktopWindow {
    /// The event loop, pumped by [`DesktopWindow::pump`].
    event_loop: EventLoop<()>,
    /// Its handler, holding the window.
    handler: Handler,
}

impl DesktopWindow {
    /// Opens a window of `width` x `height` pixels titled `title`.
    pub fn open(title: &str, width: u32, height: u32) -> Result<DesktopWindow> {
        let event_loop = EventLoop::new().context(
            "opening a window: no display (set DISPLAY or WAYLAND_DISPLAY; headless: run under \
             xvfb-run -a)",
        )?;
        let mut handler = Handler {
            attributes: Window::default_attributes()
                .with_title(title)
                .with_inner_size(PhysicalSize::new(width, height)),
            window: None,
            error: None,
            events: Vec::new(),
            close_requested: false,
            resized: false,
            shift: false,
            redraw_due: true,
        };
        let mut this_loop = event_loop;
        for _ in 0..200 {
            let _ = this_loop.pump_app_events(Some(Duration::from_millis(10)), &mut handler);
            if handler.window.is_some() || handler.error.is_some() {
                break;
            }
        }
        if let Some(e) = handler.error.take() {
            bail!("opening a window: {e}");
        }
        if handler.window.is_none() {
            bail!("opening a window: the windowing system made none within 2 s");
        }
        Ok(DesktopWindow {
            event_loop: this_loop,
            handler,
        })
    }

    /// The window.
    pub fn window(&self) -> Arc<Window> {
        self.handler.window.clone().expect("made in open")
    }

    /// Whether the windowing system is ready for the next picture: it asked for one since
    /// [`DesktopWindow::picture_presented`]. On Wayland this is the frame callback of the last
    /// picture: a hidden or minimised window gets none, and presenting to it with FIFO would
    /// block until it is shown again.
    pub fn redraw_due(&self) -> bool {
        self.handler.redraw_due
    }

    /// A picture was presented (after `pre_present_notify`, followed by `request_redraw`):
    /// the next waits for the windowing system to ask again.
    pub fn picture_presented(&mut self) {
        self.handler.redraw_due = false;
    }

    /// Handles the events waiting (waiting up to `wait` for one) and returns them.
    pub fn pump(&mut self, wait: Duration) -> Pumped {
        let status = self
            .event_loop
            .pump_app_events(Some(wait), &mut self.handler);
        let exited = matches!(status, winit::platform::pump_events::PumpStatus::Exit(_));
        Pumped {
            events: std::mem::take(&mut self.handler.events),
            shift: self.handler.shift,
            closed: exited || std::mem::take(&mut self.handler.close_requested),
            resized: std::mem::take(&mut self.handler.resized),
        }
    }
}
