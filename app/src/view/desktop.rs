//! The desktop backend: head pose from the mouse and keys, gaze from the cursor.
//!
//! The cursor is the gaze direction. What lies under it (the glass's bounding sphere, the
//! background plane) gives the fixation point: the glass's surface, or the refracted image on
//! the background plane behind it (Space or the wheel flips between them). Each eye's gaze ray
//! is synthesised towards that point, with optional angular noise, and handed to the frame
//! loop as a tracker sample, so the real pipeline (vergence, depth filter, gaze image, eq.
//! 13-15) decides the defocus from it.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;
use std::time::{Duration, Instant};

use glam::{EulerRot, Quat, Vec3};
use vitreous_trace::{EyeView, Fov, FrameInput, GazeRay, GazeSample, Pose};
use vitreous_xr::Backend;

use super::input::{Action, EyesShown, InputEvent, action_for_key, movement};
use super::playback::Playback;
use super::script::{Script, Step};
use super::window::DesktopWindow;
use vitreous_frames::scene_edit::SceneEdit;
use vitreous_scene::ViewingGeometry;

/// Radians of head turn per window width dragged.
const DRAG_RAD_PER_WIDTH: f32 = std::f32::consts::PI;

/// Walking speed, metres per second.
const SPEED_M_PER_S: f32 = 0.3;

/// Standard deviation of the gaze noise when it is on, radians (0.5 degrees).
const NOISE_RAD: f32 = 0.5 * std::f32::consts::PI / 180.0;

/// Fixation distance when nothing lies under the cursor, metres.
const FAR_FIXATION_M: f32 = 2.0;

/// How long a frame waits for the windowing system to ask for its picture before it is not
/// shown: a few display refreshes, so a shown window is never skipped and a hidden one costs
/// at most this per frame.
const REDRAW_WAIT: Duration = Duration::from_millis(50);

/// Which image under the cursor is fixated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FixationTarget {
    /// The glass's surface.
    Surface,
    /// The refracted image (the background plane seen through the glass).
    Refracted,
}

/// State the backend and the sink share: actions the user asked for, and how the window shows
/// the eyes (the cursor's meaning depends on it).
#[derive(Debug)]
pub struct Shared {
    /// Actions not yet taken by the sink.
    pub actions: VecDeque<Action>,
    /// Which eyes the window shows.
    pub eyes: EyesShown,
    /// Width / height of each eye image.
    pub eye_aspect: f32,
    /// What the gaze is fixating, and the fixation point's distance from the head, metres.
    pub fixation: (FixationTarget, f32),
    /// When the window last changed size.
    pub resized_at: Option<Instant>,
    /// Files the script replaced (for reload to look at at once).
    pub touched: Vec<std::path::PathBuf>,
    /// Whether noise is added to the gaze rays.
    pub noise: bool,
    /// The window can take a picture now without waiting (see
    /// [`DesktopWindow::redraw_due`]); set by the backend before each frame.
    pub window_ready: bool,
    /// The sink presented a picture this frame.
    pub presented: bool,
    /// Where a played trace is (position and length, seconds; whether paused).
    pub trace: Option<(f64, f64, bool)>,
    /// The object's centre once an edit or `[motion]` moved it, metres (what lies under the
    /// cursor follows it).
    pub object_center_m: Option<Vec3>,
}

/// What the arrow keys move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EditTarget {
    /// The glass object.
    #[default]
    Object,
    /// The light.
    Light,
    /// The registered world (floor, background, object, light) against the head.
    World,
}

/// The desktop backend (see the module docs).
pub struct DesktopBackend {
    /// The window and its events.
    window: DesktopWindow,
    /// Shared with the sink.
    shared: Rc<RefCell<Shared>>,
    /// Scripted input, if any.
    script: Option<Script>,
    /// Stop after this many frames.
    max_frames: Option<u64>,
    /// Index of the next frame.
    next_index: u64,
    /// When the session started.
    started: Instant,
    /// When the last frame was handed out.
    last_frame: Option<Instant>,
    /// Where the head starts (and R returns to), metres.
    home_m: Vec3,
    /// Head position, metres.
    position_m: Vec3,
    /// Head turn about the vertical, radians (positive: to the left).
    yaw_rad: f32,
    /// Head tilt, radians (positive: up).
    pitch_rad: f32,
    /// Cursor, fractions of the window from the top left.
    cursor: (f32, f32),
    /// The left button is down (dragging turns the head).
    dragging: bool,
    /// Keys held.
    held: Vec<String>,
    /// Vertical field of view, radians.
    fov_v_rad: f32,
    /// Interpupillary distance, metres.
    ipd_m: f32,
    /// The glass and background plane, for what lies under the cursor.
    geometry: ViewingGeometry,
    /// Random state of the gaze noise.
    rng: u64,
    /// A trace played instead of the user's head and gaze.
    playback: Option<Playback>,
    /// What the arrow keys move.
    edit_target: EditTarget,
    /// How far the registered world was moved against the head, metres (re-registration).
    world_offset_m: Vec3,
}

impl DesktopBackend {
    /// A backend for a window, starting at the scene's viewing position.
    pub fn new(
        window: DesktopWindow,
        shared: Rc<RefCell<Shared>>,
        script: Option<Script>,
        max_frames: Option<u64>,
        scene: &vitreous_scene::Scene,
    ) -> DesktopBackend {
        let fov = scene.output.fov;
        DesktopBackend {
            window,
            shared,
            script,
            max_frames,
            next_index: 0,
            started: Instant::now(),
            last_frame: None,
            home_m: scene.viewer.head_position_m,
            position_m: scene.viewer.head_position_m,
            yaw_rad: 0.0,
            pitch_rad: 0.0,
            cursor: (0.25, 0.5),
            dragging: false,
            held: Vec::new(),
            fov_v_rad: fov.angle_up_rad - fov.angle_down_rad,
            ipd_m: scene.viewer.ipd_m,
            geometry: scene.viewing_geometry(),
            rng: 0x9E37_79B9_7F4A_7C15,
            playback: None,
            edit_target: EditTarget::Object,
            world_offset_m: Vec3::ZERO,
        }
    }

    /// Plays a trace: head and gaze come from it instead of the mouse and keys.
    pub fn play(&mut self, playback: Playback) {
        self.playback = Some(playback);
    }

    /// Takes a reloaded scene's viewing geometry and eye spacing (the head stays where it is).
    pub fn set_scene(&mut self, scene: &vitreous_scene::Scene) {
        self.geometry = scene.viewing_geometry();
        self.ipd_m = scene.viewer.ipd_m;
        self.home_m = scene.viewer.head_position_m;
        let fov = scene.output.fov;
        self.fov_v_rad = fov.angle_up_rad - fov.angle_down_rad;
    }

    /// Applies one input event.
    fn apply(&mut self, event: InputEvent, shift: bool) {
        // A script holds Shift as a key (`down shift`).
        let shift = shift || self.held.iter().any(|h| h == "shift");
        match event {
            InputEvent::Key { name, pressed } => {
                self.held.retain(|h| *h != name);
                if pressed {
                    if let Some(action) = action_for_key(&name, shift) {
                        match action {
                            Action::Recentre => {
                                self.position_m = self.home_m;
                                self.yaw_rad = 0.0;
                                self.pitch_rad = 0.0;
                            }
                            Action::FixationTarget => self.flip_target(),
                            Action::Nudge(axis, m) => {
                                let edit = match self.edit_target {
                                    EditTarget::Object => SceneEdit::MoveObject(axis, m),
                                    EditTarget::Light => SceneEdit::MoveLight(axis, m),
                                    EditTarget::World => {
                                        self.world_offset_m += axis.unit() * m;
                                        SceneEdit::Register(axis, m)
                                    }
                                };
                                self.shared
                                    .borrow_mut()
                                    .actions
                                    .push_back(Action::Edit(edit));
                            }
                            Action::Turn(deg) => self
                                .shared
                                .borrow_mut()
                                .actions
                                .push_back(Action::Edit(SceneEdit::TurnObject(deg))),
                            Action::Place => self
                                .shared
                                .borrow_mut()
                                .actions
                                .push_back(Action::Edit(SceneEdit::PlaceObject)),
                            Action::EditTarget => {
                                self.edit_target = match self.edit_target {
                                    EditTarget::Object => EditTarget::Light,
                                    EditTarget::Light => EditTarget::World,
                                    EditTarget::World => EditTarget::Object,
                                };
                                tracing::info!("the arrow keys move the {:?}", self.edit_target);
                            }
                            Action::Pause | Action::Step | Action::Seek(_)
                                if self.playback.is_some() =>
                            {
                                self.trace_key(action);
                            }
                            other => self.shared.borrow_mut().actions.push_back(other),
                        }
                    }
                    self.held.push(name);
                }
            }
            InputEvent::Cursor { x, y } => {
                if self.dragging {
                    self.yaw_rad -= (x - self.cursor.0) * DRAG_RAD_PER_WIDTH;
                    self.pitch_rad = (self.pitch_rad - (y - self.cursor.1) * DRAG_RAD_PER_WIDTH)
                        .clamp(-1.4, 1.4);
                }
                self.cursor = (x, y);
            }
            InputEvent::Button { name, pressed } => {
                if name == "left" {
                    self.dragging = pressed;
                }
            }
            InputEvent::Wheel(n) => {
                if n != 0.0 {
                    self.flip_target();
                }
            }
        }
    }

    /// Pause, step or seek of the trace played.
    fn trace_key(&mut self, action: Action) {
        let Some(p) = &mut self.playback else { return };
        match action {
            Action::Pause => {
                tracing::info!("trace {}", p.toggle_pause());
            }
            Action::Step => p.step(),
            Action::Seek(s) => p.seek_ns(i64::from(s) * 1_000_000_000),
            _ => {}
        }
        let (at, of) = p.position_s();
        tracing::info!("trace at {at:.3} of {of:.3} s");
    }

    /// Fixates the other image under the cursor.
    fn flip_target(&mut self) {
        let mut shared = self.shared.borrow_mut();
        shared.fixation.0 = match shared.fixation.0 {
            FixationTarget::Surface => FixationTarget::Refracted,
            FixationTarget::Refracted => FixationTarget::Surface,
        };
        tracing::info!(
            "fixating the {:?} image under the cursor",
            shared.fixation.0
        );
    }

    /// The eyes' positions in the head frame, left then right.
    fn eye_offsets(&self) -> [Vec3; 2] {
        let half = Vec3::X * (self.ipd_m / 2.0);
        [-half, half]
    }

    /// The frame for a head pose and gaze: both eyes' views, with the scene's vertical field
    /// of view and the horizontal one of the eye images' aspect.
    fn frame(&mut self, head: Pose, gaze: Option<GazeSample>, time_ns: i64) -> FrameInput {
        let aspect = self.shared.borrow().eye_aspect;
        let tan_v = (self.fov_v_rad / 2.0).tan();
        let fov = Fov::symmetric(2.0 * (tan_v * aspect).atan(), self.fov_v_rad);
        let views = self.eye_offsets().map(|p| EyeView {
            pose: Pose {
                position: head.transform_point(p),
                orientation: head.orientation,
            },
            fov,
        });
        let input = FrameInput {
            index: self.next_index,
            time_ns,
            head,
            views,
            gaze,
        };
        self.next_index += 1;
        input
    }

    /// The head's orientation.
    fn orientation(&self) -> Quat {
        Quat::from_euler(EulerRot::YXZ, self.yaw_rad, self.pitch_rad, 0.0)
    }

    /// One standard normal deviate (Box-Muller on a xorshift generator).
    fn gaussian(&mut self) -> f32 {
        let mut uniform = || {
            self.rng ^= self.rng << 13;
            self.rng ^= self.rng >> 7;
            self.rng ^= self.rng << 17;
            ((self.rng >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (u1, u2) = (uniform(), uniform());
        ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    }
}

/// The fixation point along a ray from `origin` (unit `dir`, scene frame): the glass's front
/// surface or the background plane behind it when the ray meets the glass, else the
/// background plane, else a point [`FAR_FIXATION_M`] away.
pub fn fixation_point(
    geometry: &ViewingGeometry,
    origin: Vec3,
    dir: Vec3,
    target: FixationTarget,
) -> Vec3 {
    let to_center = geometry.center_m - origin;
    let along = to_center.dot(dir);
    let miss_sq = to_center.length_squared() - along * along;
    let r_sq = geometry.radius_m * geometry.radius_m;
    let sphere_t = (miss_sq <= r_sq && along > 0.0).then(|| along - (r_sq - miss_sq).sqrt());
    let denom = dir.dot(geometry.plane_normal);
    let plane_t = (denom.abs() > 1e-4)
        .then(|| (geometry.plane_point_m - origin).dot(geometry.plane_normal) / denom)
        .filter(|t| *t > 0.0);
    let t = match (sphere_t, target) {
        (Some(t), FixationTarget::Surface) => t.max(0.01),
        // Behind the glass: the plane, or 0.2 m behind its centre when the plane is not there.
        (Some(_), FixationTarget::Refracted) => {
            plane_t.filter(|p| *p > along).unwrap_or(along + 0.2)
        }
        (None, _) => plane_t.unwrap_or(FAR_FIXATION_M),
    };
    origin + dir * t
}

impl Backend for DesktopBackend {
    type Error = std::convert::Infallible;

    fn wait_frame(&mut self) -> Result<Option<FrameInput>, Self::Error> {
        if self.max_frames.is_some_and(|n| self.next_index >= n) {
            return Ok(None);
        }
        if std::mem::take(&mut self.shared.borrow_mut().presented) {
            self.window.picture_presented();
        }
        let mut wait = Duration::ZERO;
        let mut pumped = loop {
            let pumped = self.window.pump(wait);
            let size = self.window.window().inner_size();
            // Minimised (no area): nothing to draw; wait for events instead of spinning.
            if pumped.closed || (size.width > 0 && size.height > 0) {
                break pumped;
            }
            for event in pumped.events {
                self.apply(event, pumped.shift);
            }
            wait = Duration::from_millis(50);
        };
        // Wait a little for the windowing system to ask for the next picture; a window that
        // does not ask (hidden, minimised on Wayland) gets none this frame rather than a
        // present that would block the loop (and its close button) until it is shown.
        let deadline = Instant::now() + REDRAW_WAIT;
        while !self.window.redraw_due() && !pumped.closed {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            pumped.merge(self.window.pump(left));
        }
        self.shared.borrow_mut().window_ready = self.window.redraw_due();
        if pumped.closed {
            return Ok(None);
        }
        if pumped.resized {
            self.shared.borrow_mut().resized_at = Some(Instant::now());
        }
        for event in pumped.events {
            self.apply(event, pumped.shift);
        }
        if let Some(script) = &mut self.script {
            for step in script.due(self.next_index) {
                match step {
                    Step::Input(event) => self.apply(event, false),
                    Step::Resize { width, height } => {
                        let size = winit::dpi::PhysicalSize::new(width, height);
                        // None: the request is being carried out; a Resized event follows.
                        let _ = self.window.window().request_inner_size(size);
                    }
                    Step::Minimise(on) => self.window.window().set_minimized(on),
                    Step::Copy { from, to } => {
                        // A failed copy is the script's error, reported and not fatal.
                        match std::fs::copy(&from, &to) {
                            Ok(_) => self.shared.borrow_mut().touched.push(to),
                            Err(e) => tracing::error!(
                                "script: copying {} to {}: {e}",
                                from.display(),
                                to.display()
                            ),
                        }
                    }
                }
            }
        }
        if self.shared.borrow().actions.contains(&Action::Quit) {
            return Ok(None);
        }
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32().min(0.1));
        self.last_frame = Some(now);
        if let Some(p) = &mut self.playback {
            let (time_ns, head, gaze) = p.advance((dt * 1e9) as i64);
            let (at, of) = p.position_s();
            let paused = p.paused();
            self.shared.borrow_mut().trace = Some((at, of, paused));
            let input = self.frame(head, Some(gaze), time_ns);
            return Ok(Some(input));
        }
        let orientation = self.orientation();
        let [mx, my, mz] = movement(&self.held);
        self.position_m += orientation * Vec3::new(mx, my, -mz) * SPEED_M_PER_S * dt;
        // The world moved by the re-registration is the head moved the other way.
        let head = Pose {
            position: self.position_m - self.world_offset_m,
            orientation,
        };
        if let Some(center) = self.shared.borrow().object_center_m {
            self.geometry.center_m = center;
        }
        let (eyes_shown, aspect, target, noise) = {
            let s = self.shared.borrow();
            (s.eyes, s.eye_aspect, s.fixation.0, s.noise)
        };
        let tan_v = (self.fov_v_rad / 2.0).tan();
        // The cursor's ray from the eye whose image it is over.
        let (eye, u, v) = eyes_shown.locate(self.cursor.0, self.cursor.1);
        let dir_local = Vec3::new(
            (2.0 * u - 1.0) * tan_v * aspect,
            (1.0 - 2.0 * v) * tan_v,
            -1.0,
        )
        .normalize();
        let eye_local = self.eye_offsets();
        let origin = head.transform_point(eye_local[eye]);
        let point = fixation_point(&self.geometry, origin, orientation * dir_local, target);
        self.shared.borrow_mut().fixation.1 = (point - head.position).length();
        let point_head = orientation.inverse() * (point - head.position);
        let time_ns = now.duration_since(self.started).as_nanos() as i64;
        let mut ray = |origin: Vec3| {
            let mut d = (point_head - origin).normalize();
            if noise {
                let (a, b) = (self.gaussian() * NOISE_RAD, self.gaussian() * NOISE_RAD);
                d = (Quat::from_rotation_x(a) * Quat::from_rotation_y(b) * d).normalize();
            }
            GazeRay {
                origin,
                direction: d,
                valid: true,
            }
        };
        let gaze = GazeSample::binocular(time_ns, ray(eye_local[0]), ray(eye_local[1]));
        Ok(Some(self.frame(head, Some(gaze), time_ns)))
    }

    fn end_frame(&mut self, _frame: &FrameInput) -> Result<(), Self::Error> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> ViewingGeometry {
        ViewingGeometry {
            center_m: Vec3::new(0.0, 0.0, -0.2),
            radius_m: 0.075,
            plane_point_m: Vec3::new(0.0, 0.0, -0.4),
            plane_normal: Vec3::Z,
            two_surface_ior: None,
            lens: None,
            world_from_model: glam::Mat4::IDENTITY,
        }
    }

    #[test]
    fn the_cursor_on_the_glass_fixates_its_surface_or_the_plane_behind() {
        let g = geometry();
        let p = fixation_point(&g, Vec3::ZERO, Vec3::NEG_Z, FixationTarget::Surface);
        assert!((p.z + 0.125).abs() < 1e-5, "{p}");
        let p = fixation_point(&g, Vec3::ZERO, Vec3::NEG_Z, FixationTarget::Refracted);
        assert!((p.z + 0.4).abs() < 1e-5, "{p}");
    }

    #[test]
    fn off_the_glass_both_targets_fixate_the_background() {
        let g = geometry();
        let dir = Vec3::new(0.5, 0.0, -1.0).normalize();
        for target in [FixationTarget::Surface, FixationTarget::Refracted] {
            let p = fixation_point(&g, Vec3::ZERO, dir, target);
            assert!((p.z + 0.4).abs() < 1e-5, "{p}");
        }
        let p = fixation_point(&g, Vec3::ZERO, Vec3::Z, FixationTarget::Surface);
        assert!((p.z - FAR_FIXATION_M).abs() < 1e-5, "{p}");
    }
}
