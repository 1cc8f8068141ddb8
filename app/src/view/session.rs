//! The viewer's frame sink: takes the user's actions, plans each frame's look, watches the
//! scene's files, and puts finished frames in the window with the overlay.
//!
//! Just over 600 lines: it is the viewer's one `FrameSink`, and each of its parts (actions,
//! reload requests, renderer hand-over, overlay lines, presentation) reads and writes the same
//! session state; the state machines it drives live in `conditions.rs`, `reload.rs` and the
//! renderer's `present` module.

use std::cell::RefCell;
use std::rc::Rc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use vitreous_render::renderer::{FrameResult, Want};
use vitreous_render::{ContextOptions, Presented, Renderer};
use vitreous_trace::format::{AtomicFile, TraceSample, TraceWriter};
use vitreous_trace::{FrameInput, GazeSample};

use super::ViewOptions;
use super::conditions::ViewConditions;
use super::desktop::Shared;
use super::edits::ViewEdits;
use super::input::{Action, KEYS};
use super::picture::{Overlay, SeeThrough, compose};
use super::reload::{Loaded, Watcher};
use super::surface::WindowPresenter;
use vitreous_frames::director::Director;
use vitreous_frames::frame_loop::{FramePlan, FrameSink};
use vitreous_frames::motion_clock::MotionClock;
use vitreous_frames::scene_edit::SceneEdit;
use vitreous_optics::display::registration::Misregistration;

/// The registration errors the see-through preview cycles through (key X), degrees to the
/// right: none, and the two the realism figures are measured at (docs/display.md).
const MISREGISTRATION_DEG: [f32; 3] = [0.0, 0.125, 0.25];
use vitreous_frames::validation::ValidationSummary;
use vitreous_gaze::{FilterKind, FixationDepth, GazeOverride};
use vitreous_scene::Scene;

mod overlay;

/// How long a window keeps its new size before the renderer is made for it.
const RESIZE_SETTLE: Duration = Duration::from_millis(200);

/// Why the frame loop was ended for a new renderer.
pub enum Request {
    /// The eye images need a new size.
    Resize,
    /// The scene was loaded anew.
    Reload(Box<Loaded>),
}

/// The sink (see the module docs).
pub struct ViewSink<'d> {
    /// What decides each frame's condition and gaze image instead of the user (a study's
    /// trials, `vitreous study run --view`).
    director: Option<&'d mut dyn Director>,
    /// The scene shown.
    loaded: Loaded,
    /// Conditions and planners.
    looks: ViewConditions,
    /// The scene's files.
    watcher: Watcher,
    /// The window's swapchain.
    presenter: WindowPresenter,
    /// Shared with the backend.
    shared: Rc<RefCell<Shared>>,
    /// Show the see-through preview instead of the display's light.
    preview: bool,
    /// The preview's registration error: an index of [`MISREGISTRATION_DEG`].
    misregistration: usize,
    /// Show the overlay.
    show_overlay: bool,
    /// List the keys in the overlay.
    help: bool,
    /// Tables of the preview.
    see: SeeThrough,
    /// The overlay's text drawer.
    overlay: Overlay,
    /// Eye image size of the current renderer.
    eye_size: (u32, u32),
    /// Fraction of the window's pixels the eye images are rendered at.
    render_scale: f32,
    /// A new renderer is needed.
    request: Option<Request>,
    /// The newest message for the overlay (a reload error, a note).
    status: Option<String>,
    /// Reloads refused.
    reload_errors: Vec<String>,
    /// Reloads taken.
    reloads: u32,
    /// Renderers made.
    renderers_made: u32,
    /// Validation messages of retired renderers' devices: warnings, errors, first texts.
    validation: (u32, u32, Vec<String>),
    /// Smoothed CPU and GPU milliseconds per frame, and frames per second.
    timing: (f64, Option<f64>, f64),
    /// When the last frame finished.
    last_finished: Option<Instant>,
    /// Where each frame's head pose and gaze are recorded.
    writer: Option<TraceWriter<AtomicFile>>,
    /// Time of the newest frame recorded, nanoseconds.
    recorded_until_ns: Option<i64>,
    /// The gaze images the pipeline decided, in order, each change once.
    gaze_images: Vec<String>,
    /// The scene's motion with the keys' edits and those of a trace played.
    edits: ViewEdits,
}

impl<'d> ViewSink<'d> {
    /// A sink showing `loaded` in `presenter`'s window.
    pub fn new(
        options: &ViewOptions,
        loaded: Loaded,
        presenter: WindowPresenter,
        shared: Rc<RefCell<Shared>>,
        filter: Option<FilterKind>,
        gaze: GazeOverride,
    ) -> Result<ViewSink<'d>> {
        let looks = ViewConditions::new(
            loaded.effects,
            loaded.caustics_loaded,
            loaded.setup.as_ref().map(|s| s.model.clone()),
            options.reflection,
            filter.unwrap_or(loaded.scene.gaze.filter),
            gaze,
        );
        let status = loaded.caustics_note.clone();
        let writer = match &options.record {
            Some(path) => Some(
                TraceWriter::create_with_edits(path)
                    .with_context(|| format!("creating {}", path.display()))?,
            ),
            None => None,
        };
        Ok(ViewSink {
            edits: ViewEdits::new(&loaded.scene),
            director: None,
            writer,
            recorded_until_ns: None,
            gaze_images: Vec::new(),
            watcher: Watcher::new(loaded.files.clone()),
            loaded,
            looks,
            presenter,
            shared,
            preview: options.preview,
            misregistration: 0,
            show_overlay: options.overlay,
            help: false,
            see: SeeThrough::new(),
            overlay: Overlay::new()?,
            eye_size: (0, 0),
            render_scale: options.render_scale,
            request: None,
            status,
            reload_errors: Vec::new(),
            reloads: 0,
            renderers_made: 0,
            validation: (0, 0, Vec::new()),
            timing: (0.0, None, 0.0),
            last_finished: None,
        })
    }

    /// The eye image size the window needs now.
    fn wanted_eye_size(&self) -> (u32, u32) {
        let (w, h) = self.presenter.window_size();
        let (ew, eh) = self.shared.borrow().eyes.eye_size(w.max(1), h.max(1));
        let scaled = |v: u32| ((v as f32 * self.render_scale).round() as u32).max(16);
        (scaled(ew), scaled(eh))
    }

    /// A renderer for the window as it is now.
    pub fn make_renderer(&mut self, options: &ContextOptions) -> Result<Renderer> {
        let size = self.wanted_eye_size();
        let renderer = self.loaded.renderer(size, options)?;
        self.took_renderer(size);
        Ok(renderer)
    }

    fn took_renderer(&mut self, size: (u32, u32)) {
        self.eye_size = size;
        self.shared.borrow_mut().eye_aspect = size.0 as f32 / size.1 as f32;
        self.renderers_made += 1;
        tracing::info!("eye images {}x{}", size.0, size.1);
    }

    /// Makes a renderer for a reloaded scene and, once it exists, shows that scene.
    pub fn adopt(&mut self, loaded: Loaded, options: &ContextOptions) -> Result<Renderer> {
        let size = self.wanted_eye_size();
        let renderer = loaded.renderer(size, options)?;
        let (filter, reflection, gaze) = self.looks.settings();
        let current = self.looks.condition();
        let start = if loaded.caustics_loaded || !current.caustics {
            current
        } else {
            loaded.effects
        };
        self.looks = ViewConditions::new(
            start,
            loaded.caustics_loaded,
            loaded.setup.as_ref().map(|s| s.model.clone()),
            reflection,
            filter,
            gaze,
        );
        self.watcher = Watcher::new(loaded.files.clone());
        self.edits.reset(&loaded.scene);
        self.shared.borrow_mut().object_center_m = None;
        self.status = Some(match &loaded.caustics_note {
            Some(note) => format!("reloaded; {note}"),
            None => "reloaded".into(),
        });
        self.loaded = loaded;
        self.reloads += 1;
        self.took_renderer(size);
        tracing::info!("scene reloaded");
        Ok(renderer)
    }

    /// The scene's motion and the keys' edits.
    pub fn motion(&self) -> &MotionClock {
        self.edits.motion()
    }

    /// Shows the scene edits of the trace played (see [`ViewEdits::play`]).
    pub fn play_edits(&mut self, edits: Vec<vitreous_trace::format::EditRecord>) {
        self.edits.play(edits);
    }

    /// Closes the recorded trace, if any.
    pub fn finish_recording(&mut self) -> Result<()> {
        if let Some(w) = self.writer.take() {
            w.finish().context("closing the recorded trace")?;
        }
        Ok(())
    }

    /// The scene shown.
    pub fn scene(&self) -> &Scene {
        &self.loaded.scene
    }

    /// Counts a renderer's validation messages before it goes.
    pub fn retire(&mut self, renderer: &Renderer) {
        let v = renderer.context().validation();
        self.validation.0 += v.warnings();
        self.validation.1 += v.errors();
        self.validation.2.extend(v.messages());
    }

    /// Reports a reload that could not take effect; the last good scene keeps running.
    pub fn report_reload_error(&mut self, error: String) {
        tracing::error!("reload refused, the last good scene keeps running: {error}");
        self.status = Some(format!("reload failed: {error}"));
        self.reload_errors.push(error);
    }

    /// Takes the pending request for a new renderer.
    pub fn take_request(&mut self) -> Option<Request> {
        self.request.take()
    }

    /// The last picture shown.
    pub fn last_shown(&self) -> Option<(&[u8], u32, u32)> {
        self.presenter.last_shown()
    }

    /// Validation of every device used (retired renderers and the window's).
    pub fn validation(&self) -> ValidationSummary {
        let window = ValidationSummary::of(self.presenter.context());
        let mut messages = self.validation.2.clone();
        messages.extend(window.messages);
        ValidationSummary {
            warnings: self.validation.0 + window.warnings,
            errors: self.validation.1 + window.errors,
            messages,
            ..window
        }
    }

    /// The window's size now.
    pub fn window_size(&self) -> (u32, u32) {
        self.presenter.window_size()
    }

    /// Frames whose picture was not shown.
    pub fn frames_not_shown(&self) -> u64 {
        self.presenter.frames_not_shown()
    }

    /// Renderers made so far.
    pub fn renderers_made(&self) -> u32 {
        self.renderers_made
    }

    /// Reloads taken.
    pub fn reloads(&self) -> u32 {
        self.reloads
    }

    /// Reloads refused, with their errors.
    pub fn reload_errors(&self) -> &[String] {
        &self.reload_errors
    }

    /// The gaze images decided, in order, each change once.
    pub fn gaze_images(&self) -> &[String] {
        &self.gaze_images
    }

    /// The condition shown.
    pub fn condition(&self) -> String {
        self.looks.condition().to_string()
    }

    /// Hands the frames' conditions and gaze images to `director`.
    pub fn set_director(&mut self, director: &'d mut dyn Director) {
        self.director = Some(director);
    }

    /// Applies one action of the user.
    fn act(&mut self, action: Action) -> Option<String> {
        if self.director.is_some()
            && matches!(
                action,
                Action::Condition(_) | Action::NextCondition | Action::GazeOverride
            )
        {
            return Some("the study decides the condition and the gaze image".into());
        }
        Some(match action {
            Action::Condition(i) => self.looks.choose(i),
            Action::NextCondition => self.looks.next(),
            Action::Reflection => self.looks.toggle_reflection(),
            Action::Filter => match self.looks.next_filter() {
                Ok(m) => m,
                Err(e) => format!("{e:#}"),
            },
            Action::GazeOverride => self.looks.next_gaze(),
            Action::Noise => {
                let mut s = self.shared.borrow_mut();
                s.noise = !s.noise;
                format!("gaze noise {}", if s.noise { "on" } else { "off" })
            }
            Action::Eyes => {
                let mut s = self.shared.borrow_mut();
                s.eyes = s.eyes.next();
                format!("eyes shown: {}", s.eyes)
            }
            Action::Preview => {
                self.preview = !self.preview;
                if self.preview {
                    "see-through preview".into()
                } else {
                    "display light alone".into()
                }
            }
            Action::Misregister => {
                self.misregistration = (self.misregistration + 1) % MISREGISTRATION_DEG.len();
                let deg = MISREGISTRATION_DEG[self.misregistration];
                if deg == 0.0 {
                    "preview registered".into()
                } else {
                    format!("preview with the display {deg} degrees right of the world")
                }
            }
            Action::Overlay => {
                self.show_overlay = !self.show_overlay;
                return None;
            }
            Action::Help => {
                self.help = !self.help;
                for (keys, what) in KEYS {
                    tracing::info!("{keys:>20}  {what}");
                }
                return None;
            }
            Action::Pause | Action::Step | Action::Seek(_) => {
                "trace keys act only while a trace plays (--trace)".into()
            }
            Action::Recentre
            | Action::FixationTarget
            | Action::Quit
            | Action::Nudge(..)
            | Action::Turn(_)
            | Action::Place
            | Action::EditTarget
            | Action::Edit(_) => return None,
        })
    }

    /// Looks for a changed scene file and, when one changed, loads the scene anew.
    fn check_reload(&mut self) {
        let touched = !std::mem::take(&mut self.shared.borrow_mut().touched).is_empty();
        let Some(file) = self.watcher.changed(touched) else {
            return;
        };
        tracing::info!("{} changed: reloading the scene", file.display());
        match Loaded::load(&self.loaded.scene.path, None) {
            Ok(loaded) => self.request = Some(Request::Reload(Box::new(loaded))),
            Err(e) => self.report_reload_error(format!("{e:#}")),
        }
    }
}

impl FrameSink for ViewSink<'_> {
    fn pose(&mut self, input: &FrameInput) -> Option<vitreous_render::ScenePose> {
        let keyed: Vec<SceneEdit> = {
            let mut shared = self.shared.borrow_mut();
            let mut keyed = Vec::new();
            shared.actions.retain(|a| match a {
                Action::Edit(e) => {
                    keyed.push(*e);
                    false
                }
                _ => true,
            });
            keyed
        };
        let recording = self.writer.as_mut().map(|w| (w, self.recorded_until_ns));
        if let Some(status) = self.edits.apply(keyed, input, recording) {
            self.status = Some(status);
        }
        let (center_m, pose) = self.edits.pose(input)?;
        self.looks.set_object_pose(center_m, pose.world_from_model);
        self.shared.borrow_mut().object_center_m = Some(center_m);
        Some(pose)
    }

    fn started(&mut self, input: &FrameInput) -> Result<()> {
        // A trace's times increase strictly: a paused or rewound trace is not recorded again.
        if self.recorded_until_ns.is_some_and(|t| input.time_ns <= t) {
            return Ok(());
        }
        if let Some(w) = &mut self.writer {
            self.recorded_until_ns = Some(input.time_ns);
            let gaze = input.gaze.unwrap_or(GazeSample::none(input.time_ns));
            w.write(&TraceSample {
                time_ns: input.time_ns,
                head: input.head,
                gaze,
            })
            .context("recording the trace")?;
        }
        Ok(())
    }

    fn plan(&mut self, input: &FrameInput) -> FramePlan {
        let actions: Vec<Action> = self.shared.borrow_mut().actions.drain(..).collect();
        for action in actions {
            if let Some(change) = self.act(action) {
                tracing::info!("frame {}: {change}", input.index);
            }
        }
        if self.request.is_none() {
            self.check_reload();
        }
        if self.request.is_none() && self.wanted_eye_size() != self.eye_size {
            let (w, h) = self.presenter.window_size();
            let settled = self
                .shared
                .borrow()
                .resized_at
                .is_none_or(|t| t.elapsed() >= RESIZE_SETTLE);
            if settled && w > 0 && h > 0 {
                self.request = Some(Request::Resize);
            }
        }
        let mut blank = false;
        if let Some(director) = &mut self.director {
            let (set, gaze) = director.next_shown(input);
            if let Some(g) = gaze {
                self.looks.set_gaze(g);
            }
            blank = match set {
                Some(s) => !self.looks.show_set(s),
                None => true,
            };
        }
        let mut look = self.looks.plan(input);
        look.blank = blank;
        look.caustics &= self.edits.caustics_valid();
        if let Some(d) = self.looks.planner().last_defocus() {
            let image = d.image.to_string();
            if self.gaze_images.last() != Some(&image) {
                self.gaze_images.push(image);
            }
        }
        FramePlan {
            look,
            want: Want {
                eyes: true,
                world: self.preview,
            },
        }
    }

    fn finished(&mut self, _input: &FrameInput, result: &FrameResult) -> Result<()> {
        if let Some(e) = self.edits.take_error() {
            return Err(e);
        }
        if let Some(e) = self.director.as_mut().and_then(|d| d.take_error()) {
            return Err(e);
        }
        let now = Instant::now();
        let smooth = |old: f64, new: f64| {
            if old == 0.0 {
                new
            } else {
                old * 0.9 + new * 0.1
            }
        };
        let fps = self
            .last_finished
            .map(|t| 1.0 / now.duration_since(t).as_secs_f64().max(1e-6));
        self.last_finished = Some(now);
        self.timing = (
            smooth(self.timing.0, result.timing.cpu_submit_ms),
            result
                .timing
                .gpu_ms
                .map(|g| smooth(self.timing.1.unwrap_or(0.0), g)),
            fps.map_or(self.timing.2, |f| smooth(self.timing.2, f)),
        );
        let Some(readback) = &result.readback else {
            return Ok(());
        };
        let lines = if self.show_overlay {
            self.overlay_lines()
        } else {
            Vec::new()
        };
        let eyes = self.shared.borrow().eyes;
        let preview = self.preview.then_some(&self.see);
        // Through the scene's dimmers, the world the eye receives (as replay's previews).
        let display = vitreous_frames::wearer::WearerView::of_scene(&self.loaded.scene);
        let dimmed = match (&readback.world, self.preview && display.dims()) {
            (Some(world), true) => Some([0, 1].map(|e| {
                let size = [readback.width, readback.height];
                display.dimmed_world(&readback.eyes[e], &world[e], size)
            })),
            _ => None,
        };
        let world = dimmed.as_ref().or(readback.world.as_ref());
        // Misregistered, the display's light and panel over the world, composed here.
        let shift_deg = MISREGISTRATION_DEG[self.misregistration];
        let misregistered = match (&readback.world, self.preview && shift_deg > 0.0) {
            (Some(world), true) => {
                let size = [readback.width, readback.height];
                let fov = vitreous_frames::wearer::scene_fov_deg(&self.loaded.scene);
                let error = Misregistration::new([shift_deg, 0.0], 0.0)?;
                let mut shown = readback.clone();
                shown.eyes = [0, 1].map(|e| {
                    display.see_misregistered(
                        &readback.eyes[e],
                        &world[e],
                        size,
                        &error,
                        readback.width as f32 / fov[0],
                    )
                });
                Some(shown)
            }
            _ => None,
        };
        let (readback, preview) = match &misregistered {
            Some(shown) => (shown, None),
            None => (readback, preview),
        };
        let overlay = &self.overlay;
        let ready = self.shared.borrow().window_ready;
        let shown = self.presenter.present(ready, |out, w, h| {
            compose(out, w, h, readback, eyes, preview, world);
            overlay.draw(out, w, h, &lines);
        })?;
        self.shared.borrow_mut().presented = shown == Presented::Shown;
        Ok(())
    }

    fn stop_requested(&self) -> bool {
        self.request.is_some()
            || vitreous_frames::interrupt::requested()
            || self.director.as_ref().is_some_and(|d| d.ending())
    }
}
