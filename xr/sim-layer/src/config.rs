//! What the simulated headset offers, read from the environment when an instance is created.
//!
//! - `VITREOUS_SIM_TRACE`: the trace v1 file the eye data comes from (needed whenever an eye
//!   extension is offered).
//! - `VITREOUS_SIM_GAZE`: comma list of `ml`, `fb`, `ext` (default all three; `none` for none):
//!   which eye-tracking extensions the layer offers.
//! - `VITREOUS_SIM_BLEND`: comma list of `additive`, `alpha_blend` (default both, in that
//!   order; `none` for none): the blend modes listed before the runtime's own.
//! - `VITREOUS_SIM_SUBMITTED`: a CSV file that gets one line per submitted frame.
//! - `VITREOUS_SIM_BUTTONS`: a script of controller button presses (`crate::controller`).
//! - `VITREOUS_SIM_EYE_MAX`: `WxH`, the largest eye image the headset offers (each view's
//!   recommended and largest image rectangle are clamped to it).
//! - `VITREOUS_SIM_FORMATS`: comma list of `rgba8-srgb`, `bgra8-srgb`, `rgba8-unorm`,
//!   `bgra8-unorm`: the only swapchain colour formats the headset offers, in its order of
//!   preference (`crate::calls::swapchain`).
//! - `VITREOUS_SIM_ML_FRAME`: `1` to offer Magic Leap 2's frame controls (XR_ML_frame_end_info,
//!   XR_ML_global_dimmer): what the app chains to `xrEndFrame` is recorded, not passed on.
//! - `VITREOUS_SIM_PLANES`: `x,y,z,w,d` level rectangles facing up, separated by `;` (centre in
//!   metres in the frame of the head's level pose when a detection begins, width along x and
//!   depth along z): offered through XR_EXT_plane_detection (`crate::calls::planes`).
//! - `VITREOUS_SIM_LIGHT`: `x,y,z,r,g,b,a` and optionally `,turn_deg,at_s`: the room's light
//!   offered through XR_ML_light_estimation (`crate::calls::light`): the way the main light
//!   travels (in the frame of the head's level pose when the estimation is made), its colour
//!   (the irradiance it gives a surface facing it), a uniform ambient radiance `a`, and a turn
//!   of the main light by `turn_deg` about +y `at_s` seconds after the estimation was made.
//! - `VITREOUS_SIM_IMAGES`: a folder: every projection image the app releases is read back
//!   (Vulkan sessions) and each submitted view's alpha written to `alpha.csv` there
//!   (`crate::images`); with `VITREOUS_SIM_WORLD`, a picture of the real world (any PNG, scaled
//!   to each view), the last frame as the wearer would see it: `wearer-left.png`,
//!   `wearer-right.png`, the world dimmed by a segmented dimmer panel of
//!   `VITREOUS_SIM_PANEL` (`cells_across,cells_down,blur_deg`, default `64,48,1.5`) where the
//!   alpha asks, and the image's light added; with `VITREOUS_SIM_REGISTRATION` (`x_deg,y_deg`,
//!   right and down, each within 10 degrees) the app's light and panel land that far from the
//!   world, as a registration error puts them (to the nearest pixel), and the view without
//!   the error is written beside it (`wearer-left-registered.png`, ...).
//! - `VITREOUS_SIM_VIEWS`: `ipd_mm` or `ipd_mm,toe_out_deg`: the headset's eyes as
//!   `xrLocateViews` answers them, that far apart about the runtime's midpoint and each turned
//!   outwards by `toe_out_deg` (canted displays; `crate::views`).
//! - `VITREOUS_SIM_FAULTS`: a fault schedule (`crate::faults::schedule`): what a misbehaving
//!   headset does to the session, and when; `VITREOUS_SIM_FAULT_LOG`: the CSV file the layer
//!   logs each fault and what the app did about it to (`crate::faults::log`).
//!
//! About 800 lines: one parser per variable, beside the field it fills, with the error that
//! names the variable; the tests are most of the rest.

use std::ffi::CStr;
use std::fmt;
use std::path::PathBuf;

use openxr::sys;

/// Environment variable naming the trace file.
pub const TRACE_VAR: &str = "VITREOUS_SIM_TRACE";
/// Environment variable: `1` plays the trace's eye data over and over, `0` (the default) holds
/// its last sample after its end.
pub const TRACE_LOOP_VAR: &str = "VITREOUS_SIM_TRACE_LOOP";
/// Environment variable choosing the eye-tracking extensions.
pub const GAZE_VAR: &str = "VITREOUS_SIM_GAZE";
/// Environment variable choosing the added blend modes.
pub const BLEND_VAR: &str = "VITREOUS_SIM_BLEND";
/// Environment variable naming the submitted-frames CSV.
pub const SUBMITTED_VAR: &str = "VITREOUS_SIM_SUBMITTED";
/// Environment variable naming the controller button script.
pub const BUTTONS_VAR: &str = "VITREOUS_SIM_BUTTONS";
/// Environment variable giving the largest eye image, `WxH` pixels.
pub const EYE_MAX_VAR: &str = "VITREOUS_SIM_EYE_MAX";
/// Environment variable listing the swapchain colour formats the headset offers.
pub const FORMATS_VAR: &str = "VITREOUS_SIM_FORMATS";
/// Whether the layer offers Magic Leap 2's frame controls, XR_ML_frame_end_info and
/// XR_ML_global_dimmer (`1` or `0`; unset: not).
pub const ML_FRAME_VAR: &str = "VITREOUS_SIM_ML_FRAME";
/// Environment variable listing the planes XR_EXT_plane_detection finds.
pub const PLANES_VAR: &str = "VITREOUS_SIM_PLANES";
/// The plane detection extension's name.
pub const PLANE_DETECTION: &CStr = c"XR_EXT_plane_detection";
/// Environment variable describing the light XR_ML_light_estimation estimates.
pub const LIGHT_VAR: &str = "VITREOUS_SIM_LIGHT";
/// The light estimation extension's name.
pub const LIGHT_ESTIMATION: &CStr = c"XR_ML_light_estimation";
/// Environment variable naming the folder the submitted images' record goes to.
pub const IMAGES_VAR: &str = "VITREOUS_SIM_IMAGES";
/// Environment variable naming a picture of the real world, for the wearer's view.
pub const WORLD_VAR: &str = "VITREOUS_SIM_WORLD";
/// Environment variable giving the simulated dimmer panel: cells across, down, blur (degrees).
pub const PANEL_VAR: &str = "VITREOUS_SIM_PANEL";

/// Environment variable giving the registration error of the wearer's view: degrees right,
/// down.
pub const REGISTRATION_VAR: &str = "VITREOUS_SIM_REGISTRATION";

/// Environment variable giving the headset's eye views: their distance apart (millimetres)
/// and, optionally, how far each is turned outwards (degrees).
pub const VIEWS_VAR: &str = "VITREOUS_SIM_VIEWS";

/// Environment variable naming the fault schedule.
pub const FAULTS_VAR: &str = "VITREOUS_SIM_FAULTS";
/// Environment variable naming the fault log.
pub const FAULT_LOG_VAR: &str = "VITREOUS_SIM_FAULT_LOG";

/// The sides `VITREOUS_SIM_EYE_MAX` takes, pixels.
pub const EYE_MAX_RANGE: std::ops::RangeInclusive<u32> = 16..=16384;

/// The swapchain colour formats `VITREOUS_SIM_FORMATS` names, with their `VkFormat` values
/// (the four 8-bit colour formats `crate::images::TexelLayout::of` reads).
pub const FORMAT_NAMES: [(&str, i64); 4] = [
    ("rgba8-srgb", 43),  // VK_FORMAT_R8G8B8A8_SRGB
    ("bgra8-srgb", 50),  // VK_FORMAT_B8G8R8A8_SRGB
    ("rgba8-unorm", 37), // VK_FORMAT_R8G8B8A8_UNORM
    ("bgra8-unorm", 44), // VK_FORMAT_B8G8R8A8_UNORM
];

/// An eye-tracking extension the layer can provide.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GazeExtension {
    /// `XR_ML_eye_tracker`: per-eye, combined and fixation poses, pupils.
    Ml,
    /// `XR_FB_eye_tracking_social`: a pose per eye.
    Fb,
    /// `XR_EXT_eye_gaze_interaction`: one combined ray through an action.
    Ext,
}

impl GazeExtension {
    /// All three, in the default order.
    pub const ALL: [GazeExtension; 3] = [GazeExtension::Ml, GazeExtension::Fb, GazeExtension::Ext];

    /// The extension's name.
    pub fn name(self) -> &'static CStr {
        match self {
            GazeExtension::Ml => c"XR_ML_eye_tracker",
            GazeExtension::Fb => c"XR_FB_eye_tracking_social",
            GazeExtension::Ext => c"XR_EXT_eye_gaze_interaction",
        }
    }

    /// The extension's specification version, as the manifest lists it.
    pub fn spec_version(self) -> u32 {
        match self {
            GazeExtension::Ml => 1,
            GazeExtension::Fb => sys::FB_eye_tracking_social_SPEC_VERSION,
            GazeExtension::Ext => sys::EXT_eye_gaze_interaction_SPEC_VERSION,
        }
    }

    /// The short name used in `VITREOUS_SIM_GAZE`.
    pub fn short(self) -> &'static str {
        match self {
            GazeExtension::Ml => "ml",
            GazeExtension::Fb => "fb",
            GazeExtension::Ext => "ext",
        }
    }

    /// The extension whose name is `name`, if it is one of the layer's.
    pub fn from_name(name: &CStr) -> Option<GazeExtension> {
        GazeExtension::ALL.into_iter().find(|e| e.name() == name)
    }
}

/// What is wrong with an environment variable.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// The variable.
    pub var: &'static str,
    /// Its value.
    pub value: String,
    /// What was expected.
    pub expected: &'static str,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}={:?}: expected {}",
            self.var, self.value, self.expected
        )
    }
}

/// The simulated headset's configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// The eye-tracking extensions offered, without repeats.
    pub gaze: Vec<GazeExtension>,
    /// The blend modes listed before the runtime's, without repeats.
    pub blend: Vec<sys::EnvironmentBlendMode>,
    /// The trace file.
    pub trace: Option<PathBuf>,
    /// Whether the trace's eye data plays over and over.
    pub trace_loop: bool,
    /// The submitted-frames CSV.
    pub submitted: Option<PathBuf>,
    /// The controller button script.
    pub buttons: Option<PathBuf>,
    /// The largest eye image offered, width and height in pixels (`None`: the runtime's).
    pub eye_max: Option<(u32, u32)>,
    /// The swapchain colour formats offered (`VkFormat` values, of [`FORMAT_NAMES`]), in the
    /// headset's order of preference, without repeats (`None`: the runtime's).
    pub formats: Option<Vec<i64>>,
    /// XR_ML_frame_end_info and XR_ML_global_dimmer are the layer's: taken out of the
    /// instance's extensions and each frame's `XrFrameEndInfo` chain, and recorded.
    pub ml_frame: bool,
    /// The planes XR_EXT_plane_detection finds (none: the extension is not the layer's).
    pub planes: Vec<SimPlane>,
    /// The light XR_ML_light_estimation estimates (`None`: the extension is not the layer's).
    pub light: Option<SimLight>,
    /// The folder the submitted images' record goes to (`None`: not read back).
    pub images: Option<PathBuf>,
    /// A picture of the real world the wearer's view is made over.
    pub world: Option<PathBuf>,
    /// The simulated segmented dimmer's panel.
    pub panel: SimPanel,
    /// How far the app's light and panel land from the world in the wearer's view, degrees
    /// right and down.
    pub registration_deg: [f32; 2],
    /// The eyes `xrLocateViews` answers (`None`: the runtime's).
    pub views: Option<SimViews>,
    /// The fault schedule file.
    pub faults: Option<PathBuf>,
    /// The fault log file.
    pub fault_log: Option<PathBuf>,
}

/// A segmented dimmer panel, as `VITREOUS_SIM_PANEL` gives it: each cell takes away the mean
/// alpha of the pixels it covers, seen through a Gaussian blur.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimPanel {
    /// Cells across and down the view.
    pub cells: [u32; 2],
    /// Standard deviation of the blur, degrees.
    pub blur_deg: f32,
}

impl Default for SimPanel {
    /// Magic Leap 2's panel as vitreous's scenes guess it (docs/headsets.md).
    fn default() -> Self {
        SimPanel {
            cells: [64, 48],
            blur_deg: 1.5,
        }
    }
}

/// Parses `VITREOUS_SIM_PANEL`.
pub fn parse_panel(value: &str) -> Result<SimPanel, ConfigError> {
    let bad = || ConfigError {
        var: PANEL_VAR,
        value: value.to_owned(),
        expected: "cells_across,cells_down,blur_deg: two whole numbers 1..=1024 and a blur 0..=20 \
                   degrees",
    };
    let parts: Vec<&str> = value.split(',').map(str::trim).collect();
    let [across, down, blur] = parts.as_slice() else {
        return Err(bad());
    };
    let cell = |v: &str| {
        v.parse::<u32>()
            .ok()
            .filter(|c| (1..=1024).contains(c))
            .ok_or_else(bad)
    };
    let blur_deg = blur
        .parse::<f32>()
        .ok()
        .filter(|b| (0.0..=20.0).contains(b))
        .ok_or_else(bad)?;
    Ok(SimPanel {
        cells: [cell(across)?, cell(down)?],
        blur_deg,
    })
}

/// Parses `VITREOUS_SIM_REGISTRATION`.
pub fn parse_registration(value: &str) -> Result<[f32; 2], ConfigError> {
    let bad = || ConfigError {
        var: REGISTRATION_VAR,
        value: value.to_owned(),
        expected: "x_deg,y_deg: two numbers from -10 to 10 degrees (right, down)",
    };
    let parts: Vec<f32> = value
        .split(',')
        .map(|v| v.trim().parse::<f32>().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    match parts[..] {
        [x, y] if [x, y].iter().all(|v| v.is_finite() && v.abs() <= 10.0) => Ok([x, y]),
        _ => Err(bad()),
    }
}

/// The headset's eye views, as `VITREOUS_SIM_VIEWS` gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimViews {
    /// Distance between the eyes, metres.
    pub ipd_m: f32,
    /// How far each eye's view is turned outwards about the head's up axis, degrees.
    pub toe_out_deg: f32,
}

impl SimViews {
    /// Eyes `ipd_mm` apart, each turned `toe_out_deg` outwards; `None` unless 40 to 90 mm apart
    /// and turned -10 to 10 degrees.
    pub fn new(ipd_mm: f32, toe_out_deg: f32) -> Option<SimViews> {
        ((40.0..=90.0).contains(&ipd_mm) && (-10.0..=10.0).contains(&toe_out_deg)).then_some(
            SimViews {
                ipd_m: ipd_mm / 1000.0,
                toe_out_deg,
            },
        )
    }
}

/// Parses `VITREOUS_SIM_VIEWS`.
pub fn parse_views(value: &str) -> Result<SimViews, ConfigError> {
    let bad = || ConfigError {
        var: VIEWS_VAR,
        value: value.to_owned(),
        expected: "ipd_mm[,toe_out_deg]: 40 to 90 millimetres, then -10 to 10 degrees",
    };
    let parts: Vec<f32> = value
        .split(',')
        .map(|v| v.trim().parse::<f32>().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    let (ipd_mm, toe_out_deg) = match parts[..] {
        [ipd] => (ipd, 0.0),
        [ipd, toe] => (ipd, toe),
        _ => return Err(bad()),
    };
    SimViews::new(ipd_mm, toe_out_deg).ok_or_else(bad)
}

/// The room's light, as `VITREOUS_SIM_LIGHT` gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimLight {
    /// The way the main light travels (unit), in the frame of the head's level pose when the
    /// estimation is made.
    pub direction: glam::Vec3,
    /// The main light's colour: the irradiance it gives a surface facing it (linear RGB).
    pub color: glam::Vec3,
    /// The ambient light's radiance, the same from every direction.
    pub ambient: f32,
    /// A turn of the main light about +y, degrees, and how long after the estimation was made
    /// it happens, seconds.
    pub turn: Option<(f32, f64)>,
}

impl SimLight {
    /// The way the main light travels `elapsed_s` seconds after the estimation was made.
    pub fn direction_at(&self, elapsed_s: f64) -> glam::Vec3 {
        match self.turn {
            Some((deg, at_s)) if elapsed_s >= at_s => {
                glam::Quat::from_rotation_y(deg.to_radians()) * self.direction
            }
            _ => self.direction,
        }
    }
}

/// Parses `VITREOUS_SIM_LIGHT`.
pub fn parse_light(value: &str) -> Result<SimLight, ConfigError> {
    let bad = || ConfigError {
        var: LIGHT_VAR,
        value: value.to_owned(),
        expected: "x,y,z,r,g,b,a[,turn_deg,at_s]: a direction that is not zero, colour and \
                   ambient at least 0, a turn time at least 0",
    };
    let v: Vec<f32> = value
        .split(',')
        .map(|n| n.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if !v.iter().all(|n| n.is_finite()) {
        return Err(bad());
    }
    let (base, turn) = match v[..] {
        [.., deg, at] if v.len() == 9 && at >= 0.0 => (&v[..7], Some((deg, f64::from(at)))),
        _ if v.len() == 7 => (&v[..], None),
        _ => return Err(bad()),
    };
    let direction = glam::Vec3::new(base[0], base[1], base[2]);
    let color = glam::Vec3::new(base[3], base[4], base[5]);
    if direction.length() < 1e-6 || color.min_element() < 0.0 || base[6] < 0.0 {
        return Err(bad());
    }
    Ok(SimLight {
        direction: direction.normalize(),
        color,
        ambient: base[6],
        turn,
    })
}

/// A level rectangle facing up, as `VITREOUS_SIM_PLANES` gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimPlane {
    /// Its centre, metres, in the frame of the head's level pose when a detection begins.
    pub center_m: glam::Vec3,
    /// Its width (along x) and depth (along z), metres.
    pub size_m: glam::Vec2,
}

/// Parses `VITREOUS_SIM_PLANES`.
pub fn parse_planes(value: &str) -> Result<Vec<SimPlane>, ConfigError> {
    let bad = || ConfigError {
        var: PLANES_VAR,
        value: value.to_owned(),
        expected: "x,y,z,w,d rectangles (metres; w, d > 0) separated by ;",
    };
    value
        .split(';')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|p| {
            let v: Vec<f32> = p
                .split(',')
                .map(|n| n.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad())?;
            match v[..] {
                [x, y, z, w, d] if v.iter().all(|n| n.is_finite()) && w > 0.0 && d > 0.0 => {
                    Ok(SimPlane {
                        center_m: glam::Vec3::new(x, y, z),
                        size_m: glam::Vec2::new(w, d),
                    })
                }
                _ => Err(bad()),
            }
        })
        .collect()
}

impl Config {
    /// Reads the process environment.
    pub fn from_env() -> Result<Config, ConfigError> {
        Config::from_vars(|name| std::env::var_os(name).map(|v| v.to_string_lossy().into_owned()))
    }

    /// Reads the variables through `get` (the environment, or a table in tests). Empty
    /// values count as unset.
    pub fn from_vars(get: impl Fn(&str) -> Option<String>) -> Result<Config, ConfigError> {
        let get = |name: &str| get(name).filter(|v| !v.trim().is_empty());
        Ok(Config {
            gaze: parse_gaze(get(GAZE_VAR).as_deref())?,
            blend: parse_blend(get(BLEND_VAR).as_deref())?,
            trace: get(TRACE_VAR).map(PathBuf::from),
            trace_loop: flag(
                TRACE_LOOP_VAR,
                get(TRACE_LOOP_VAR),
                "1 (play the trace's eye data over and over) or 0",
            )?,
            submitted: get(SUBMITTED_VAR).map(PathBuf::from),
            buttons: get(BUTTONS_VAR).map(PathBuf::from),
            eye_max: get(EYE_MAX_VAR).map(|v| parse_eye_max(&v)).transpose()?,
            formats: get(FORMATS_VAR).map(|v| parse_formats(&v)).transpose()?,
            planes: get(PLANES_VAR)
                .map(|v| parse_planes(&v))
                .transpose()?
                .unwrap_or_default(),
            light: get(LIGHT_VAR).map(|v| parse_light(&v)).transpose()?,
            images: get(IMAGES_VAR).map(PathBuf::from),
            world: get(WORLD_VAR).map(PathBuf::from),
            panel: get(PANEL_VAR)
                .map(|v| parse_panel(&v))
                .transpose()?
                .unwrap_or_default(),
            registration_deg: get(REGISTRATION_VAR)
                .map(|v| parse_registration(&v))
                .transpose()?
                .unwrap_or_default(),
            views: get(VIEWS_VAR).map(|v| parse_views(&v)).transpose()?,
            faults: get(FAULTS_VAR).map(PathBuf::from),
            fault_log: get(FAULT_LOG_VAR).map(PathBuf::from),
            ml_frame: flag(
                ML_FRAME_VAR,
                get(ML_FRAME_VAR),
                "1 (offer XR_ML_frame_end_info and XR_ML_global_dimmer) or 0",
            )?,
        })
    }

    /// Whether `ext` is offered.
    pub fn offers(&self, ext: GazeExtension) -> bool {
        self.gaze.contains(&ext)
    }
}

/// Splits a comma list into trimmed, lower-case, non-empty items.
fn items(value: &str) -> impl Iterator<Item = String> + '_ {
    value
        .split(',')
        .map(|s| s.trim().to_ascii_lowercase())
        .filter(|s| !s.is_empty())
}

/// Parses `VITREOUS_SIM_GAZE` (unset: all three).
pub fn parse_gaze(value: Option<&str>) -> Result<Vec<GazeExtension>, ConfigError> {
    let Some(value) = value else {
        return Ok(GazeExtension::ALL.to_vec());
    };
    let mut out = Vec::new();
    for item in items(value) {
        let ext = match item.as_str() {
            "none" => continue,
            "ml" => GazeExtension::Ml,
            "fb" => GazeExtension::Fb,
            "ext" => GazeExtension::Ext,
            _ => {
                return Err(ConfigError {
                    var: GAZE_VAR,
                    value: value.to_owned(),
                    expected: "a comma list of ml, fb, ext (or none)",
                });
            }
        };
        if !out.contains(&ext) {
            out.push(ext);
        }
    }
    Ok(out)
}

/// Parses `VITREOUS_SIM_BLEND` (unset: ADDITIVE then ALPHA_BLEND).
pub fn parse_blend(value: Option<&str>) -> Result<Vec<sys::EnvironmentBlendMode>, ConfigError> {
    use sys::EnvironmentBlendMode as M;
    let Some(value) = value else {
        return Ok(vec![M::ADDITIVE, M::ALPHA_BLEND]);
    };
    let mut out = Vec::new();
    for item in items(value) {
        let mode = match item.as_str() {
            "none" => continue,
            "additive" => M::ADDITIVE,
            "alpha_blend" | "alpha-blend" | "alpha" => M::ALPHA_BLEND,
            _ => {
                return Err(ConfigError {
                    var: BLEND_VAR,
                    value: value.to_owned(),
                    expected: "a comma list of additive, alpha_blend (or none)",
                });
            }
        };
        if !out.contains(&mode) {
            out.push(mode);
        }
    }
    Ok(out)
}

/// Parses `VITREOUS_SIM_EYE_MAX`: `WxH`, each side within [`EYE_MAX_RANGE`].
pub fn parse_eye_max(value: &str) -> Result<(u32, u32), ConfigError> {
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|n| EYE_MAX_RANGE.contains(n))
    };
    value
        .trim()
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((side(w)?, side(h)?)))
        .ok_or_else(|| ConfigError {
            var: EYE_MAX_VAR,
            value: value.to_owned(),
            expected: "WxH in pixels, each side 16 to 16384 (e.g. 1440x1760)",
        })
}

/// Parses `VITREOUS_SIM_FORMATS`: a comma list of names of [`FORMAT_NAMES`], at least one,
/// each at most once, into their `VkFormat` values in the order listed.
pub fn parse_formats(value: &str) -> Result<Vec<i64>, ConfigError> {
    let bad = || ConfigError {
        var: FORMATS_VAR,
        value: value.to_owned(),
        expected: "a comma list of rgba8-srgb, bgra8-srgb, rgba8-unorm, bgra8-unorm, at least \
                   one, each at most once (e.g. bgra8-srgb,bgra8-unorm)",
    };
    let mut out = Vec::new();
    for item in items(value) {
        let format = FORMAT_NAMES
            .iter()
            .find(|(name, _)| *name == item)
            .map(|&(_, f)| f)
            .ok_or_else(bad)?;
        if out.contains(&format) {
            return Err(bad());
        }
        out.push(format);
    }
    if out.is_empty() {
        return Err(bad());
    }
    Ok(out)
}

/// A variable that is `1` or `0` (unset: `0`).
fn flag(
    var: &'static str,
    value: Option<String>,
    expected: &'static str,
) -> Result<bool, ConfigError> {
    match value.as_deref().map(str::trim) {
        None | Some("0") => Ok(false),
        Some("1") => Ok(true),
        Some(other) => Err(ConfigError {
            var,
            value: other.to_owned(),
            expected,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sys::EnvironmentBlendMode as M;
    use vitreous_xr::openxr::ml_eye_tracker;

    fn config(vars: &[(&str, &str)]) -> Result<Config, ConfigError> {
        Config::from_vars(|name| {
            vars.iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| (*v).to_owned())
        })
    }

    #[test]
    fn defaults_offer_everything() {
        let c = config(&[]).unwrap();
        assert_eq!(c.gaze, GazeExtension::ALL.to_vec());
        assert_eq!(c.blend, vec![M::ADDITIVE, M::ALPHA_BLEND]);
        assert_eq!((c.trace, c.submitted), (None, None));
        assert!(!c.trace_loop && !c.ml_frame);
    }

    #[test]
    fn flags_are_one_or_zero_and_a_bad_one_names_the_variable() {
        assert!(config(&[(TRACE_LOOP_VAR, "1")]).unwrap().trace_loop);
        assert!(!config(&[(TRACE_LOOP_VAR, " 0 ")]).unwrap().trace_loop);
        assert!(config(&[(ML_FRAME_VAR, "1")]).unwrap().ml_frame);
        for var in [TRACE_LOOP_VAR, ML_FRAME_VAR] {
            let e = config(&[(var, "yes")]).unwrap_err();
            assert_eq!((e.var, e.value.as_str()), (var, "yes"));
        }
    }

    #[test]
    fn planes_are_level_rectangles_and_a_bad_list_names_the_variable() {
        let c = config(&[(PLANES_VAR, "0,-0.25,-1.5,0.6,0.4; 1,-1,-2,4,4;")]).unwrap();
        assert_eq!(c.planes.len(), 2);
        assert_eq!(c.planes[0].center_m, glam::Vec3::new(0.0, -0.25, -1.5));
        assert_eq!(c.planes[1].size_m, glam::Vec2::new(4.0, 4.0));
        assert!(config(&[]).unwrap().planes.is_empty());
        for bad in ["0,0,0,1", "0,0,0,1,0", "a,0,0,1,1", "0,0,nan,1,1"] {
            let e = config(&[(PLANES_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, PLANES_VAR, "{bad}");
        }
    }

    #[test]
    fn a_registration_error_is_two_angles_and_a_bad_one_names_the_variable() {
        assert_eq!(config(&[]).unwrap().registration_deg, [0.0, 0.0]);
        let c = config(&[(REGISTRATION_VAR, "0.25, -0.125")]).unwrap();
        assert_eq!(c.registration_deg, [0.25, -0.125]);
        for bad in ["1", "1,2,3", "nan,0", "0,11", "a,b"] {
            let e = config(&[(REGISTRATION_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, REGISTRATION_VAR, "{bad}");
        }
    }

    #[test]
    fn views_are_a_distance_and_a_turn_and_bad_ones_name_the_variable() {
        assert_eq!(config(&[]).unwrap().views, None);
        let v = config(&[(VIEWS_VAR, "58")]).unwrap().views.unwrap();
        assert_eq!((v.ipd_m, v.toe_out_deg), (0.058, 0.0));
        let v = config(&[(VIEWS_VAR, " 70 , 4.5 ")]).unwrap().views.unwrap();
        assert_eq!((v.ipd_m, v.toe_out_deg), (0.07, 4.5));
        for bad in ["39", "91", "63,11", "nan", "63,inf", "63,1,2", "a", "63,"] {
            let e = config(&[(VIEWS_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, VIEWS_VAR, "{bad}");
        }
    }

    #[test]
    fn the_panel_defaults_to_magic_leap_2s_guess_and_a_bad_one_names_the_variable() {
        let c = config(&[(IMAGES_VAR, "/tmp/i")]).unwrap();
        assert_eq!(c.panel, SimPanel::default());
        assert_eq!(c.images, Some(PathBuf::from("/tmp/i")));
        let p = config(&[(PANEL_VAR, "32, 24, 0.5")]).unwrap().panel;
        assert_eq!((p.cells, p.blur_deg), ([32, 24], 0.5));
        for bad in [
            "32,24",
            "0,24,1",
            "32,24,-1",
            "32,24,nan",
            "a,b,c",
            "32,24,1,2",
        ] {
            let e = config(&[(PANEL_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, PANEL_VAR, "{bad}");
        }
    }

    #[test]
    fn the_light_is_a_direction_colour_and_ambient_with_an_optional_turn() {
        let c = config(&[(LIGHT_VAR, "0,-2,0, 3,3,3, 0.25")]).unwrap();
        let light = c.light.unwrap();
        assert_eq!(light.direction, glam::Vec3::NEG_Y);
        assert_eq!((light.ambient, light.turn), (0.25, None));
        let turned = parse_light("0,0,-1,1,1,1,0,30,2.5").unwrap();
        assert_eq!(turned.turn, Some((30.0, 2.5)));
        assert_eq!(turned.direction_at(2.4), glam::Vec3::NEG_Z);
        let after = turned.direction_at(2.5);
        assert!((after.angle_between(glam::Vec3::NEG_Z).to_degrees() - 30.0).abs() < 1e-3);
        assert!(config(&[]).unwrap().light.is_none());
        for bad in [
            "0,0,0,1,1,1,0",
            "0,-1,0,1,1",
            "0,-1,0,-1,1,1,0",
            "0,-1,0,1,1,1,-0.1",
            "0,-1,0,1,1,1,0,30",
            "0,-1,0,1,1,1,0,30,-1",
            "0,-1,nan,1,1,1,0",
        ] {
            let e = config(&[(LIGHT_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, LIGHT_VAR, "{bad}");
        }
    }

    #[test]
    fn gaze_list_is_parsed_in_order_without_repeats() {
        let c = config(&[(GAZE_VAR, " EXT, fb,ext ")]).unwrap();
        assert_eq!(c.gaze, vec![GazeExtension::Ext, GazeExtension::Fb]);
        assert!(c.offers(GazeExtension::Fb) && !c.offers(GazeExtension::Ml));
        assert!(config(&[(GAZE_VAR, "none")]).unwrap().gaze.is_empty());
        // Empty counts as unset.
        assert_eq!(config(&[(GAZE_VAR, "")]).unwrap().gaze.len(), 3);
    }

    #[test]
    fn unknown_names_are_refused_with_the_variable_named() {
        let e = config(&[(GAZE_VAR, "ml,htc")]).unwrap_err();
        assert_eq!(e.var, GAZE_VAR);
        assert!(
            e.to_string().contains("VITREOUS_SIM_GAZE=\"ml,htc\""),
            "{e}"
        );
        let e = config(&[(BLEND_VAR, "opaque")]).unwrap_err();
        assert_eq!(e.var, BLEND_VAR);
    }

    #[test]
    fn blend_list_accepts_spellings_and_none() {
        let c = config(&[(BLEND_VAR, "alpha-blend,additive")]).unwrap();
        assert_eq!(c.blend, vec![M::ALPHA_BLEND, M::ADDITIVE]);
        assert!(config(&[(BLEND_VAR, "none")]).unwrap().blend.is_empty());
    }

    #[test]
    fn paths_are_taken_as_given() {
        let c = config(&[(TRACE_VAR, "/tmp/a.trace"), (SUBMITTED_VAR, "/tmp/s.csv")]).unwrap();
        assert_eq!(c.trace, Some(PathBuf::from("/tmp/a.trace")));
        assert_eq!(c.submitted, Some(PathBuf::from("/tmp/s.csv")));
    }

    #[test]
    fn the_largest_eye_image_is_parsed_and_checked() {
        assert_eq!(config(&[]).unwrap().eye_max, None);
        let c = config(&[(EYE_MAX_VAR, " 320x240 ")]).unwrap();
        assert_eq!(c.eye_max, Some((320, 240)));
        assert_eq!(parse_eye_max("1440X1760"), Ok((1440, 1760)));
        for bad in [
            "320",
            "320x",
            "x240",
            "0x240",
            "15x240",
            "320x16385",
            "-1x5",
            "axb",
        ] {
            let e = config(&[(EYE_MAX_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, EYE_MAX_VAR, "{bad}");
            assert!(e.to_string().contains("16 to 16384"), "{e}");
        }
    }

    #[test]
    fn the_formats_are_parsed_in_order_and_checked() {
        assert_eq!(config(&[]).unwrap().formats, None);
        let c = config(&[(FORMATS_VAR, " BGRA8-SRGB, bgra8-unorm ")]).unwrap();
        assert_eq!(c.formats, Some(vec![50, 44]));
        assert_eq!(
            parse_formats("rgba8-unorm,rgba8-srgb,bgra8-unorm,bgra8-srgb"),
            Ok(vec![37, 43, 44, 50])
        );
        for bad in [
            ",",
            " , ",
            "rgba16f",
            "bgra8-srgb,bgra8",
            "bgra8-srgb,bgra8-srgb",
            "rgba8-unorm,RGBA8-UNORM",
        ] {
            let e = config(&[(FORMATS_VAR, bad)]).unwrap_err();
            assert_eq!(e.var, FORMATS_VAR, "{bad}");
            assert!(e.to_string().contains("VITREOUS_SIM_FORMATS="), "{e}");
            assert!(e.to_string().contains("each at most once"), "{e}");
        }
    }

    #[test]
    fn the_format_names_are_the_vulkan_formats_the_layer_reads() {
        use ash::vk::Format as F;
        let values: Vec<i64> = FORMAT_NAMES.iter().map(|&(_, f)| f).collect();
        let vulkan = [
            F::R8G8B8A8_SRGB,
            F::B8G8R8A8_SRGB,
            F::R8G8B8A8_UNORM,
            F::B8G8R8A8_UNORM,
        ];
        assert_eq!(
            values,
            vulkan.map(|f| i64::from(f.as_raw())).to_vec(),
            "names in the order of FORMAT_NAMES"
        );
        for (name, f) in FORMAT_NAMES {
            let layout = crate::images::TexelLayout::of(f).unwrap();
            assert_eq!(
                (layout.bgra, layout.srgb),
                (name.starts_with("bgra"), name.ends_with("srgb")),
                "{name}"
            );
        }
    }

    #[test]
    fn extension_names_round_trip() {
        for e in GazeExtension::ALL {
            assert_eq!(GazeExtension::from_name(e.name()), Some(e));
        }
        assert_eq!(
            GazeExtension::Ml.name().to_str().unwrap(),
            ml_eye_tracker::EXTENSION_NAME
        );
        assert_eq!(GazeExtension::from_name(c"XR_KHR_vulkan_enable2"), None);
    }
}
