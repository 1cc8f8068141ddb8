//! Errors of the OpenXR backend.

use std::fmt::Write as _;

use ash::vk;
use openxr as xr;
use thiserror::Error;

/// Errors of the OpenXR backend. Messages say what was expected and what to do.
#[derive(Debug, Error)]
pub enum OpenXrError {
    /// The OpenXR loader library could not be loaded.
    #[error(
        "no OpenXR loader: {0}. Install one (Debian trixie: libopenxr-loader1) or run through \
         tools/monado/run-ci, which provisions Monado"
    )]
    NoLoader(String),
    /// No runtime is installed or active, or it failed to start.
    #[error(
        "no usable OpenXR runtime: {0}. Install and start one (Monado: monado-service), or \
         point XR_RUNTIME_JSON at its manifest"
    )]
    NoRuntime(String),
    /// `xrCreateInstance` failed with API layers enabled: a layer may have refused its
    /// settings, or the runtime failed.
    #[error(
        "xrCreateInstance failed ({error}) with the OpenXR API layers {layers} enabled: a layer \
         may have refused its settings (see its message above) or the runtime failed; run \
         without the layers (XR_ENABLE_API_LAYERS unset, no --validate) to tell which"
    )]
    LayersOrRuntime {
        /// What xrCreateInstance returned.
        error: String,
        /// The layers enabled, by the environment and by vitreous.
        layers: String,
    },
    /// The runtime lacks XR_KHR_vulkan_enable2.
    #[error(
        "the OpenXR runtime does not offer XR_KHR_vulkan_enable2, which vitreous needs to render \
         with Vulkan (offered: {0})"
    )]
    NoVulkan(String),
    /// The runtime or the headset is not there now and may come back:
    /// `XR_ERROR_RUNTIME_UNAVAILABLE` from xrCreateInstance, `XR_ERROR_FORM_FACTOR_UNAVAILABLE`
    /// from xrGetSystem (see [`OpenXrError::is_unavailable`]).
    #[error(
        "{call}: {result}: no OpenXR runtime or headset is available now. Connect the headset, \
         start the runtime (Monado: monado-service) or point XR_RUNTIME_JSON at its manifest"
    )]
    Unavailable {
        /// The call.
        call: &'static str,
        /// What it returned.
        result: xr::sys::Result,
    },
    /// `xrCreateInstance` failed with `XR_ERROR_INITIALIZATION_FAILED` or
    /// `XR_ERROR_RUNTIME_FAILURE`: the runtime could not start. At the first start that is the
    /// end (`detail` says why and what to do); after a loss the runtime may be starting again,
    /// and is asked again for a while ([`OpenXrError::may_come_back_after_loss`]).
    #[error("{detail}")]
    InstanceFailed {
        /// What xrCreateInstance returned.
        result: xr::sys::Result,
        /// The error as the first start reports it.
        detail: Box<OpenXrError>,
    },
    /// No head-mounted display is connected.
    #[error("no head-mounted display: {0}")]
    NoHmd(String),
    /// Something the runtime offers does not fit vitreous.
    #[error("{0}")]
    Unsupported(String),
    /// A failed OpenXR call.
    #[error("OpenXR call {call} failed: {result}")]
    Call {
        /// Which call.
        call: &'static str,
        /// What it returned.
        result: xr::sys::Result,
    },
    /// A Vulkan call made through the runtime failed.
    #[error("{call} (through the OpenXR runtime) failed: {result}")]
    Vulkan {
        /// Which call.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// The gaze trace could not be read.
    #[error(transparent)]
    Trace(#[from] vitreous_trace::format::TraceError),
    /// Frame calls came in the wrong order.
    #[error("frame order: {0}")]
    FrameOrder(String),
}

impl OpenXrError {
    /// Whether the runtime or the headset is only away for now: asking again later may work
    /// (after a lost session or runtime, the app asks again for a while).
    pub fn is_unavailable(&self) -> bool {
        matches!(self, OpenXrError::Unavailable { .. })
    }

    /// Whether, after a lost session or runtime, asking again may work: the runtime or the
    /// headset is away for now, or the runtime failed to start (one that is starting again
    /// after a crash or an update answers so until it is ready).
    pub fn may_come_back_after_loss(&self) -> bool {
        self.is_unavailable() || matches!(self, OpenXrError::InstanceFailed { .. })
    }
}

/// Why `xrCreateInstance` failed with `error`, given the layers vitreous asked for and the
/// value of `XR_ENABLE_API_LAYERS`: with any layer enabled, a layer may be what refused.
pub(super) fn instance_error(
    error: &str,
    requested: &[&str],
    from_env: Option<&str>,
) -> OpenXrError {
    let mut enabled: Vec<&str> = from_env
        .unwrap_or("")
        .split([':', ';', ','])
        .filter(|l| !l.is_empty())
        .collect();
    for layer in requested {
        if !enabled.contains(layer) {
            enabled.push(layer);
        }
    }
    if enabled.is_empty() {
        OpenXrError::NoRuntime(format!("xrCreateInstance: {error}"))
    } else {
        OpenXrError::LayersOrRuntime {
            error: error.to_owned(),
            layers: enabled.join(", "),
        }
    }
}

/// A short list of the graphics extensions a runtime offers, for the no-Vulkan message.
pub(super) fn extension_list(set: &xr::ExtensionSet) -> String {
    let mut s = String::new();
    for (on, name) in [
        (set.khr_vulkan_enable, "XR_KHR_vulkan_enable"),
        (set.khr_opengl_enable, "XR_KHR_opengl_enable"),
    ] {
        if on {
            let _ = write!(s, "{}{name}", if s.is_empty() { "" } else { ", " });
        }
    }
    if s.is_empty() {
        s.push_str("no graphics API extension");
    }
    s
}

/// Shorthand for results of this module.
pub type Result<T, E = OpenXrError> = std::result::Result<T, E>;

/// Names the failed call on an OpenXR result.
pub(crate) trait XrContext<T> {
    /// Converts the error, naming the call.
    fn xr(self, call: &'static str) -> Result<T>;
}

impl<T> XrContext<T> for std::result::Result<T, xr::sys::Result> {
    fn xr(self, call: &'static str) -> Result<T> {
        self.map_err(|result| OpenXrError::Call { call, result })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_instance_names_the_enabled_layers() {
        let error = "XR_ERROR_INITIALIZATION_FAILED";
        let message = |requested: &[&str], env| instance_error(error, requested, env).to_string();
        // No layer: the runtime is what failed.
        let none = message(&[], None);
        assert!(none.starts_with("no usable OpenXR runtime"), "{none}");
        assert_eq!(message(&[], Some("")), none);
        // Layers from the environment and from --validate, each named once.
        let both = message(
            &["XR_APILAYER_LUNARG_core_validation"],
            Some("XR_APILAYER_VITREOUS_sim:XR_APILAYER_LUNARG_core_validation"),
        );
        assert!(
            both.contains(
                "layers XR_APILAYER_VITREOUS_sim, XR_APILAYER_LUNARG_core_validation enabled"
            ) && both.contains(error)
                && !both.contains("Install"),
            "{both}"
        );
        let requested = message(&["XR_APILAYER_LUNARG_core_validation"], None);
        assert!(requested.contains("may have refused"), "{requested}");
    }
}
