//! The app's enabled-extension list, split into the extensions the layer provides (they must
//! not reach the runtime, which may not know them, or may list them without the hardware:
//! Monado lists XR_EXT_eye_gaze_interaction with no eye tracker) and the rest.

use std::ffi::CStr;

use crate::config::GazeExtension;

/// Magic Leap 2's frame controls, which the layer owns with `VITREOUS_SIM_ML_FRAME=1`.
pub const ML_FRAME_EXTENSIONS: [&CStr; 2] = [c"XR_ML_frame_end_info", c"XR_ML_global_dimmer"];

/// The result of [`split`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Split<'a> {
    /// The names to pass on, in the app's order.
    pub forwarded: Vec<&'a CStr>,
    /// The layer's extensions the app enabled, in the app's order, without repeats.
    pub owned: Vec<GazeExtension>,
    /// The layer's extensions the app enabled but the configuration does not offer (passed
    /// on: the runtime may have them).
    pub not_offered: Vec<GazeExtension>,
    /// The app enabled XR_EXT_plane_detection, which the layer answers.
    pub planes: bool,
    /// The app enabled XR_ML_light_estimation, which the layer answers.
    pub light: bool,
}

/// Splits `enabled` into what the layer handles (those in `offered`, the ML frame controls
/// when `ml_frame`, XR_EXT_plane_detection when `planes`, XR_ML_light_estimation when `light`)
/// and what goes on. An eye extension of
/// the layer that is not offered is reported in `not_offered` and also passed on (the runtime
/// may have it).
pub fn split<'a>(
    enabled: &[&'a CStr],
    offered: &[GazeExtension],
    ml_frame: bool,
    planes: bool,
    light: bool,
) -> Split<'a> {
    let mut out = Split {
        forwarded: Vec::with_capacity(enabled.len()),
        owned: Vec::new(),
        not_offered: Vec::new(),
        planes: false,
        light: false,
    };
    for &name in enabled {
        if ml_frame && ML_FRAME_EXTENSIONS.contains(&name) {
            continue;
        }
        if planes && name == crate::config::PLANE_DETECTION {
            out.planes = true;
            continue;
        }
        if light && name == crate::config::LIGHT_ESTIMATION {
            out.light = true;
            continue;
        }
        match GazeExtension::from_name(name) {
            Some(ext) if offered.contains(&ext) => {
                if !out.owned.contains(&ext) {
                    out.owned.push(ext);
                }
            }
            Some(ext) => {
                if !out.not_offered.contains(&ext) {
                    out.not_offered.push(ext);
                }
                out.forwarded.push(name);
            }
            None => out.forwarded.push(name),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use GazeExtension::*;

    #[test]
    fn the_layers_extensions_are_removed_and_the_rest_kept_in_order() {
        let enabled = [
            c"XR_KHR_vulkan_enable2",
            c"XR_EXT_eye_gaze_interaction",
            c"XR_KHR_composition_layer_depth",
            c"XR_FB_eye_tracking_social",
            c"XR_EXT_eye_gaze_interaction",
        ];
        let s = split(&enabled, &GazeExtension::ALL, false, false, false);
        assert_eq!(
            s.forwarded,
            vec![c"XR_KHR_vulkan_enable2", c"XR_KHR_composition_layer_depth"]
        );
        assert_eq!(s.owned, vec![Ext, Fb]);
        assert!(s.not_offered.is_empty());
    }

    #[test]
    fn the_ml_frame_controls_stay_with_the_layer_only_when_it_offers_them() {
        let enabled = [
            c"XR_ML_frame_end_info",
            c"XR_KHR_vulkan_enable2",
            c"XR_ML_global_dimmer",
        ];
        let s = split(&enabled, &[], true, false, false);
        assert_eq!(s.forwarded, vec![c"XR_KHR_vulkan_enable2"]);
        let s = split(&enabled, &[], false, false, false);
        assert_eq!(s.forwarded, enabled.to_vec());
    }

    #[test]
    fn plane_detection_stays_with_the_layer_only_when_it_has_planes() {
        let enabled = [c"XR_EXT_plane_detection", c"XR_KHR_vulkan_enable2"];
        let s = split(&enabled, &[], false, true, false);
        assert_eq!(s.forwarded, vec![c"XR_KHR_vulkan_enable2"]);
        assert!(s.planes);
        let s = split(&enabled, &[], false, false, false);
        assert_eq!(s.forwarded, enabled.to_vec());
        assert!(!s.planes);
    }

    #[test]
    fn light_estimation_stays_with_the_layer_only_when_it_has_a_light() {
        let enabled = [c"XR_ML_light_estimation", c"XR_KHR_vulkan_enable2"];
        let s = split(&enabled, &[], false, false, true);
        assert_eq!(s.forwarded, vec![c"XR_KHR_vulkan_enable2"]);
        assert!(s.light && !s.planes);
        let s = split(&enabled, &[], false, false, false);
        assert_eq!(s.forwarded, enabled.to_vec());
        assert!(!s.light);
    }

    #[test]
    fn extensions_not_offered_are_passed_on_and_reported() {
        let enabled = [c"XR_ML_eye_tracker", c"XR_EXT_eye_gaze_interaction"];
        let s = split(&enabled, &[Ext], false, false, false);
        assert_eq!(s.forwarded, vec![c"XR_ML_eye_tracker"]);
        assert_eq!(s.owned, vec![Ext]);
        assert_eq!(s.not_offered, vec![Ml]);
    }

    #[test]
    fn nothing_enabled_gives_nothing() {
        let s = split(&[], &GazeExtension::ALL, false, false, false);
        assert!(s.forwarded.is_empty() && s.owned.is_empty());
    }
}
