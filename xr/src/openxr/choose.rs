//! Pure choices the OpenXR backend makes from what a runtime offers: blend mode, gaze source,
//! swapchain format, reference space. No runtime is needed to test them.

use std::fmt;

/// How the display combines rendered light with the real world (OpenXR environment blend
/// modes, as far as vitreous cares).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    /// Light added onto the real world: optical see-through (Magic Leap 2). What vitreous is for.
    Additive,
    /// Rendered pixels blended over a camera view of the world by their alpha.
    AlphaBlend,
    /// Only the rendered picture is shown (VR): vitreous draws the scene's real-world photos
    /// behind the glass so the whole picture is visible.
    Opaque,
}

impl Blend {
    /// Whether the app must draw the real world itself.
    pub fn needs_world_behind(self) -> bool {
        self == Blend::Opaque
    }

    /// Parses `additive`, `alpha-blend` (or `alpha`) and `opaque`.
    pub fn parse(s: &str) -> Option<Blend> {
        match s.trim().to_ascii_lowercase().as_str() {
            "additive" => Some(Blend::Additive),
            "alpha-blend" | "alpha_blend" | "alpha" => Some(Blend::AlphaBlend),
            "opaque" => Some(Blend::Opaque),
            _ => None,
        }
    }
}

impl fmt::Display for Blend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Blend::Additive => "additive",
            Blend::AlphaBlend => "alpha-blend",
            Blend::Opaque => "opaque",
        })
    }
}

/// Chooses the blend mode: `wanted` when the runtime offers it, else ADDITIVE, ALPHA_BLEND,
/// OPAQUE in that order. `Err` names what was offered when nothing usable is (or when
/// `wanted` is not offered: an explicit request is not silently replaced).
pub fn choose_blend(offered: &[Blend], wanted: Option<Blend>) -> Result<Blend, String> {
    let list = || {
        if offered.is_empty() {
            "none".to_owned()
        } else {
            offered
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    if let Some(wanted) = wanted {
        return if offered.contains(&wanted) {
            Ok(wanted)
        } else {
            Err(format!(
                "blend mode {wanted} was asked for but the runtime offers only: {}",
                list()
            ))
        };
    }
    [Blend::Additive, Blend::AlphaBlend, Blend::Opaque]
        .into_iter()
        .find(|b| offered.contains(b))
        .ok_or_else(|| {
            format!(
                "the runtime offers no usable blend mode (offered: {})",
                list()
            )
        })
}

/// Where gaze comes from in a live session.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GazeSource {
    /// XR_FB_eye_tracking_social: a pose per eye, so fixation depth (vergence) is known.
    FbSocial,
    /// XR_EXT_eye_gaze_interaction: one combined ray with its sample time; no depth.
    ExtGaze,
    /// A recorded trace's gaze, replayed by time since the session's first frame.
    Trace,
    /// No tracker: the gaze image is chosen by hand (experimenter, actions).
    Manual,
}

impl fmt::Display for GazeSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GazeSource::FbSocial => "XR_FB_eye_tracking_social (per-eye poses)",
            GazeSource::ExtGaze => "XR_EXT_eye_gaze_interaction (combined ray)",
            GazeSource::Trace => "recorded trace (--gaze-trace)",
            GazeSource::Manual => "manual (no eye tracker)",
        })
    }
}

/// What the runtime and the command line offer for gaze.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GazeOffer {
    /// XR_FB_eye_tracking_social is enabled and the system supports it.
    pub fb_social: bool,
    /// XR_EXT_eye_gaze_interaction is enabled.
    pub ext_gaze_extension: bool,
    /// The system reports `supportsEyeGazeInteraction`.
    pub ext_gaze_supported: bool,
    /// A gaze trace was given.
    pub trace: bool,
}

/// Chooses the gaze source: per-eye poses, then the combined ray, then a trace, then manual.
pub fn choose_gaze(offer: GazeOffer) -> GazeSource {
    if offer.fb_social {
        GazeSource::FbSocial
    } else if offer.ext_gaze_extension && offer.ext_gaze_supported {
        GazeSource::ExtGaze
    } else if offer.trace {
        GazeSource::Trace
    } else {
        GazeSource::Manual
    }
}

/// Vulkan format codes vitreous knows (VkFormat values).
pub mod vk_format {
    /// VK_FORMAT_R8G8B8A8_UNORM.
    pub const R8G8B8A8_UNORM: i64 = 37;
    /// VK_FORMAT_R8G8B8A8_SRGB.
    pub const R8G8B8A8_SRGB: i64 = 43;
    /// VK_FORMAT_B8G8R8A8_UNORM.
    pub const B8G8R8A8_UNORM: i64 = 44;
    /// VK_FORMAT_B8G8R8A8_SRGB.
    pub const B8G8R8A8_SRGB: i64 = 50;
}

/// A swapchain colour format and whether the image encodes sRGB itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ColorFormat {
    /// The VkFormat value.
    pub vk_format: i64,
    /// True for an `_SRGB` format (write linear light); false for `_UNORM` (the shader must
    /// encode).
    pub srgb: bool,
}

/// Chooses the swapchain format from the runtime's list (its order is its preference):
/// RGBA8 sRGB, then BGRA8 sRGB, then RGBA8/BGRA8 UNORM.
pub fn choose_format(offered: &[i64]) -> Option<ColorFormat> {
    use vk_format::*;
    [
        (R8G8B8A8_SRGB, true),
        (B8G8R8A8_SRGB, true),
        (R8G8B8A8_UNORM, false),
        (B8G8R8A8_UNORM, false),
    ]
    .into_iter()
    .find(|(f, _)| offered.contains(f))
    .map(|(vk_format, srgb)| ColorFormat { vk_format, srgb })
}

/// The reference space the scene is placed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpaceChoice {
    /// STAGE: floor-level, room-fixed; the scene stays put across recentring.
    Stage,
    /// LOCAL: eye-level at start.
    Local,
}

/// STAGE when offered, else LOCAL (which every runtime offers).
pub fn choose_space(stage_offered: bool) -> SpaceChoice {
    if stage_offered {
        SpaceChoice::Stage
    } else {
        SpaceChoice::Local
    }
}

/// Size of each eye image: the recommended size (or `wanted`) clamped to the runtime's
/// maximum and to at least 16 pixels per side.
pub fn choose_size(
    recommended: (u32, u32),
    max: (u32, u32),
    wanted: Option<(u32, u32)>,
) -> (u32, u32) {
    let (w, h) = wanted.unwrap_or(recommended);
    (w.clamp(16, max.0.max(16)), h.clamp(16, max.1.max(16)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blend_prefers_additive_then_alpha_then_opaque() {
        use Blend::*;
        assert_eq!(
            choose_blend(&[Opaque, AlphaBlend, Additive], None),
            Ok(Additive)
        );
        assert_eq!(choose_blend(&[Opaque, AlphaBlend], None), Ok(AlphaBlend));
        assert_eq!(choose_blend(&[Opaque], None), Ok(Opaque));
        assert!(choose_blend(&[], None).unwrap_err().contains("none"));
    }

    #[test]
    fn blend_override_is_honoured_only_when_offered() {
        use Blend::*;
        assert_eq!(choose_blend(&[Additive, Opaque], Some(Opaque)), Ok(Opaque));
        let err = choose_blend(&[Opaque], Some(Additive)).unwrap_err();
        assert!(err.contains("additive") && err.contains("opaque"), "{err}");
    }

    #[test]
    fn only_opaque_needs_the_world_drawn_behind() {
        assert!(Blend::Opaque.needs_world_behind());
        assert!(!Blend::Additive.needs_world_behind());
        assert!(!Blend::AlphaBlend.needs_world_behind());
        assert_eq!(Blend::parse("Alpha-Blend"), Some(Blend::AlphaBlend));
        assert_eq!(Blend::parse("glass"), None);
    }

    #[test]
    fn gaze_source_order_is_per_eye_then_combined_then_trace_then_manual() {
        let all = GazeOffer {
            fb_social: true,
            ext_gaze_extension: true,
            ext_gaze_supported: true,
            trace: true,
        };
        assert_eq!(choose_gaze(all), GazeSource::FbSocial);
        let no_fb = GazeOffer {
            fb_social: false,
            ..all
        };
        assert_eq!(choose_gaze(no_fb), GazeSource::ExtGaze);
        // Monado's case: the extension is listed but no device has eyes.
        let listed_only = GazeOffer {
            ext_gaze_supported: false,
            ..no_fb
        };
        assert_eq!(choose_gaze(listed_only), GazeSource::Trace);
        let nothing = GazeOffer {
            trace: false,
            ..listed_only
        };
        assert_eq!(choose_gaze(nothing), GazeSource::Manual);
    }

    #[test]
    fn format_prefers_srgb_and_reports_unorm() {
        use vk_format::*;
        assert_eq!(
            choose_format(&[B8G8R8A8_UNORM, R8G8B8A8_SRGB]),
            Some(ColorFormat {
                vk_format: R8G8B8A8_SRGB,
                srgb: true
            })
        );
        assert_eq!(
            choose_format(&[B8G8R8A8_UNORM]),
            Some(ColorFormat {
                vk_format: B8G8R8A8_UNORM,
                srgb: false
            })
        );
        assert_eq!(choose_format(&[97]), None);
    }

    #[test]
    fn stage_is_used_when_offered() {
        assert_eq!(choose_space(true), SpaceChoice::Stage);
        assert_eq!(choose_space(false), SpaceChoice::Local);
    }

    #[test]
    fn size_is_clamped_to_the_runtime_maximum() {
        assert_eq!(choose_size((320, 240), (1920, 1080), None), (320, 240));
        assert_eq!(
            choose_size((320, 240), (1920, 1080), Some((4000, 8))),
            (1920, 16)
        );
    }
}
