//! Errors of the OpenXR backend.

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
    /// The runtime lacks XR_KHR_vulkan_enable2.
    #[error(
        "the OpenXR runtime does not offer XR_KHR_vulkan_enable2, which vitreous needs to render \
         with Vulkan (offered: {0})"
    )]
    NoVulkan(String),
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
    Trace(#[from] crate::trace::TraceError),
    /// Frame calls came in the wrong order.
    #[error("frame order: {0}")]
    FrameOrder(String),
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
