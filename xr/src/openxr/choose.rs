//! Pure choices the OpenXR backend makes from what a runtime offers: blend mode, gaze source,
//! swapchain format, reference space. No runtime is needed to test them.

use std::fmt;

use vitreous_trace::Blend;

/// Chooses the blend mode: `wanted` when the runtime offers it, else ADDITIVE, ALPHA_BLEND,
/// OPAQUE in that order, or with `dimmer` (the scene drives a segmented dimmer, which only
/// ALPHA_BLEND does) ALPHA_BLEND first. `Err` names what was offered when nothing usable is
/// (or when `wanted` is not offered: an explicit request is not silently replaced).
pub fn choose_blend(
    offered: &[Blend],
    wanted: Option<Blend>,
    dimmer: bool,
) -> Result<Blend, String> {
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
    let order = if dimmer {
        [Blend::AlphaBlend, Blend::Additive, Blend::Opaque]
    } else {
        [Blend::Additive, Blend::AlphaBlend, Blend::Opaque]
    };
    order
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
    /// XR_ML_eye_tracker (Magic Leap 2): a pose per eye, the fixation (vergence) point and the
    /// pupil diameters.
    MlEyeTracker,
    /// XR_FB_eye_tracking_social: a pose per eye, so fixation depth (vergence) is known.
    FbSocial,
    /// XR_EXT_eye_gaze_interaction: one combined ray with its sample time; no depth. Its
    /// samples are read and recorded, but the gaze image is decided from the trace (when
    /// given) or by hand.
    ExtGaze,
    /// A recorded trace's gaze, replayed by time since the session's first frame.
    Trace,
    /// No tracker: the gaze image is chosen by hand (experimenter, actions).
    Manual,
}

impl GazeSource {
    /// Whether the source gives each eye's gaze, which automatic defocus needs (eq. 15).
    pub fn per_eye(self) -> bool {
        matches!(
            self,
            GazeSource::MlEyeTracker | GazeSource::FbSocial | GazeSource::Trace
        )
    }

    /// A short name for summaries: `ml`, `fb`, `ext`, `trace`, `manual` (as `--gaze` takes).
    pub fn key(self) -> &'static str {
        match self {
            GazeSource::MlEyeTracker => "ml",
            GazeSource::FbSocial => "fb",
            GazeSource::ExtGaze => "ext",
            GazeSource::Trace => "trace",
            GazeSource::Manual => "manual",
        }
    }
}

impl fmt::Display for GazeSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GazeSource::MlEyeTracker => "XR_ML_eye_tracker (per-eye poses, fixation, pupils)",
            GazeSource::FbSocial => "XR_FB_eye_tracking_social (per-eye poses)",
            GazeSource::ExtGaze => "XR_EXT_eye_gaze_interaction (combined ray)",
            GazeSource::Trace => "recorded trace (--gaze-trace)",
            GazeSource::Manual => "manual (no eye tracker)",
        })
    }
}

/// Which gaze source `--gaze` asks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GazeChoice {
    /// The best the runtime offers (see [`choose_gaze`]).
    #[default]
    Auto,
    /// This source, or an error when it is not offered.
    Forced(GazeSource),
}

impl GazeChoice {
    /// Parses `auto`, `ml`, `fb`, `ext`, `trace` or `manual`.
    pub fn parse(s: &str) -> Option<GazeChoice> {
        Some(match s.trim().to_ascii_lowercase().as_str() {
            "auto" => GazeChoice::Auto,
            "ml" => GazeChoice::Forced(GazeSource::MlEyeTracker),
            "fb" => GazeChoice::Forced(GazeSource::FbSocial),
            "ext" => GazeChoice::Forced(GazeSource::ExtGaze),
            "trace" => GazeChoice::Forced(GazeSource::Trace),
            "manual" => GazeChoice::Forced(GazeSource::Manual),
            _ => return None,
        })
    }
}

/// What the runtime and the command line offer for gaze.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GazeOffer {
    /// XR_ML_eye_tracker is enabled and the system supports it.
    pub ml_eye_tracker: bool,
    /// XR_FB_eye_tracking_social is enabled and the system supports it.
    pub fb_social: bool,
    /// XR_EXT_eye_gaze_interaction is enabled.
    pub ext_gaze_extension: bool,
    /// The system reports `supportsEyeGazeInteraction`.
    pub ext_gaze_supported: bool,
    /// A gaze trace was given.
    pub trace: bool,
}

impl GazeOffer {
    /// Whether `source` is offered.
    pub fn offers(&self, source: GazeSource) -> bool {
        match source {
            GazeSource::MlEyeTracker => self.ml_eye_tracker,
            GazeSource::FbSocial => self.fb_social,
            GazeSource::ExtGaze => self.ext_gaze_extension && self.ext_gaze_supported,
            GazeSource::Trace => self.trace,
            GazeSource::Manual => true,
        }
    }

    /// The offered sources, best first: per-eye ML, per-eye FB, the combined EXT ray, the
    /// trace, manual.
    pub fn ranked(&self) -> Vec<GazeSource> {
        [
            GazeSource::MlEyeTracker,
            GazeSource::FbSocial,
            GazeSource::ExtGaze,
            GazeSource::Trace,
            GazeSource::Manual,
        ]
        .into_iter()
        .filter(|s| self.offers(*s))
        .collect()
    }
}

/// Chooses the gaze source: the forced one when offered (`Err` says what is offered when it is
/// not), else the best offered one (see [`GazeOffer::ranked`]).
pub fn choose_gaze(offer: GazeOffer, choice: GazeChoice) -> Result<GazeSource, String> {
    match choice {
        GazeChoice::Forced(source) if offer.offers(source) => Ok(source),
        GazeChoice::Forced(source) => Err(format!(
            "--gaze {} was asked for but {} (offered: {})",
            source.key(),
            match source {
                GazeSource::MlEyeTracker =>
                    "the runtime does not offer XR_ML_eye_tracker on this system",
                GazeSource::FbSocial =>
                    "the runtime does not offer XR_FB_eye_tracking_social on this system",
                GazeSource::ExtGaze =>
                    "the runtime does not offer XR_EXT_eye_gaze_interaction with an eye tracker",
                GazeSource::Trace => "no --gaze-trace was given",
                GazeSource::Manual => "manual is always offered",
            },
            offer
                .ranked()
                .iter()
                .map(|s| s.key())
                .collect::<Vec<_>>()
                .join(", ")
        )),
        GazeChoice::Auto => Ok(offer.ranked()[0]),
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
    /// True for an `_SRGB` format (the image encodes the linear light written); false for
    /// `_UNORM` (OpenXR reads the values as linear light, stored in 8 bits).
    pub srgb: bool,
}

/// Chooses the swapchain format from the runtime's list, whatever its order: RGBA8 sRGB (the
/// renderer's own, drawn into directly), then BGRA8 sRGB, then RGBA8/BGRA8 UNORM (blitted
/// into from the renderer's image).
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
            choose_blend(&[Opaque, AlphaBlend, Additive], None, false),
            Ok(Additive)
        );
        assert_eq!(
            choose_blend(&[Opaque, AlphaBlend], None, false),
            Ok(AlphaBlend)
        );
        assert_eq!(choose_blend(&[Opaque], None, false), Ok(Opaque));
        assert!(choose_blend(&[], None, false).unwrap_err().contains("none"));
    }

    #[test]
    fn a_dimmer_scene_prefers_alpha_blend_which_drives_the_dimmer() {
        use Blend::*;
        let offered = [Additive, AlphaBlend];
        assert_eq!(choose_blend(&offered, None, true), Ok(AlphaBlend));
        assert_eq!(choose_blend(&[Additive, Opaque], None, true), Ok(Additive));
        // An explicit choice still wins.
        assert_eq!(choose_blend(&offered, Some(Additive), true), Ok(Additive));
    }

    #[test]
    fn blend_override_is_honoured_only_when_offered() {
        use Blend::*;
        assert_eq!(
            choose_blend(&[Additive, Opaque], Some(Opaque), false),
            Ok(Opaque)
        );
        let err = choose_blend(&[Opaque], Some(Additive), false).unwrap_err();
        assert!(err.contains("additive") && err.contains("opaque"), "{err}");
    }

    #[test]
    fn only_opaque_needs_the_world_drawn_behind() {
        assert!(Blend::Opaque.needs_world_behind());
        assert!(!Blend::Additive.needs_world_behind());
        assert!(!Blend::AlphaBlend.needs_world_behind());
        assert!(Blend::AlphaBlend.uses_source_alpha());
        assert!(!Blend::Additive.uses_source_alpha() && !Blend::Opaque.uses_source_alpha());
        assert_eq!(Blend::parse("Alpha-Blend"), Some(Blend::AlphaBlend));
        assert_eq!(Blend::parse("glass"), None);
    }

    #[test]
    fn gaze_source_order_is_ml_then_fb_then_combined_then_trace_then_manual() {
        let all = GazeOffer {
            ml_eye_tracker: true,
            fb_social: true,
            ext_gaze_extension: true,
            ext_gaze_supported: true,
            trace: true,
        };
        let auto = |o| choose_gaze(o, GazeChoice::Auto).unwrap();
        assert_eq!(auto(all), GazeSource::MlEyeTracker);
        let no_ml = GazeOffer {
            ml_eye_tracker: false,
            ..all
        };
        assert_eq!(auto(no_ml), GazeSource::FbSocial);
        let no_fb = GazeOffer {
            fb_social: false,
            ..no_ml
        };
        assert_eq!(auto(no_fb), GazeSource::ExtGaze);
        assert!(!GazeSource::ExtGaze.per_eye() && GazeSource::MlEyeTracker.per_eye());
        // Monado's case: the extension is listed but no device has eyes.
        let listed_only = GazeOffer {
            ext_gaze_supported: false,
            ..no_fb
        };
        assert_eq!(auto(listed_only), GazeSource::Trace);
        let nothing = GazeOffer {
            trace: false,
            ..listed_only
        };
        assert_eq!(auto(nothing), GazeSource::Manual);
    }

    #[test]
    fn a_forced_gaze_source_is_used_or_refused_with_what_is_offered() {
        let fb_only = GazeOffer {
            fb_social: true,
            ..GazeOffer::default()
        };
        let ml = GazeChoice::parse("ML").unwrap();
        let err = choose_gaze(fb_only, ml).unwrap_err();
        assert!(
            err.contains("XR_ML_eye_tracker") && err.contains("offered: fb, manual"),
            "{err}"
        );
        assert_eq!(
            choose_gaze(fb_only, GazeChoice::parse("manual").unwrap()),
            Ok(GazeSource::Manual)
        );
        let err = choose_gaze(fb_only, GazeChoice::parse("trace").unwrap()).unwrap_err();
        assert!(err.contains("--gaze-trace"), "{err}");
        assert_eq!(GazeChoice::parse("auto"), Some(GazeChoice::Auto));
        assert_eq!(GazeChoice::parse("eyes"), None);
        for s in ["ml", "fb", "ext", "trace", "manual"] {
            match GazeChoice::parse(s) {
                Some(GazeChoice::Forced(g)) => assert_eq!(g.key(), s),
                other => panic!("{s}: {other:?}"),
            }
        }
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
