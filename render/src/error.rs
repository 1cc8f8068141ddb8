//! The renderer's error type.

use ash::vk;

/// Everything that can go wrong while setting up or driving the GPU.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The Vulkan loader (libvulkan.so.1) could not be loaded.
    #[error(
        "cannot load the Vulkan loader: {0}. Install it (Debian: apt-get install libvulkan1 \
         mesa-vulkan-drivers) or run tools/demo, which does"
    )]
    Loader(#[from] ash::LoadingError),
    /// No physical device offers what the renderer needs.
    #[error("no usable Vulkan device: {0}")]
    NoDevice(String),
    /// The validation layer was requested but is not installed.
    #[error(
        "Vulkan validation was requested but VK_LAYER_KHRONOS_validation is not installed \
         (Debian: apt-get install vulkan-validationlayers)"
    )]
    ValidationLayerMissing,
    /// The device was lost (driver crash, GPU reset): from a submit, a fence wait or any
    /// other call. Nothing more can be rendered with this context.
    #[error("the Vulkan device was lost (driver crash or GPU reset); restart to render again")]
    DeviceLost,
    /// The GPU did not finish submitted work within the allowed time.
    #[error(
        "the GPU did not finish {what} within {seconds} s; the device may be hung or far too \
         slow for this load"
    )]
    Timeout {
        /// What was waited for.
        what: &'static str,
        /// How long, seconds.
        seconds: u64,
    },
    /// Any other failed Vulkan call.
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        /// Which call failed.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// GPU memory could not be allocated.
    #[error("GPU memory allocation for {what} failed: {source}")]
    Allocation {
        /// What the memory was for.
        what: String,
        /// The allocator's reason.
        source: gpu_allocator::AllocationError,
    },
    /// Input data the renderer was given is unusable.
    #[error("invalid render input: {0}")]
    InvalidInput(String),
    /// A device creation step injected by the caller (e.g. an OpenXR runtime) failed.
    #[error("device creation failed: {0}")]
    Creation(String),
    /// A window cannot be presented to as [`crate::present::Presenter`] needs (no
    /// presentation from the graphics queue, no usable format or image usage, no host-visible
    /// memory for its pictures).
    #[error("presenting to a window: {0}")]
    Presentation(String),
    /// A failure forced by [`crate::GpuContext::fail_allocation_after`], to test unwinding.
    #[error("injected failure while allocating memory for {0}")]
    Injected(String),
}

impl RenderError {
    /// Whether work submitted before this error may still be running on the GPU, so that
    /// what it uses must not be freed (a fence wait timed out).
    pub fn gpu_may_still_run(&self) -> bool {
        matches!(self, RenderError::Timeout { .. })
    }
}

/// Shorthand for results of this crate.
pub type Result<T, E = RenderError> = std::result::Result<T, E>;

/// Attaches the name of the failed call to a `vk::Result`.
pub(crate) trait VkContext<T> {
    /// Converts the error, naming the call; device loss becomes its own variant.
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| match result {
            vk::Result::ERROR_DEVICE_LOST => RenderError::DeviceLost,
            result => RenderError::Vulkan { call, result },
        })
    }
}
