//! The GPU context: Vulkan instance, validation messenger, device, queue and allocator.
//!
//! One context serves the headless path (tests, replay, benchmarks) and the OpenXR path. The
//! only difference is who creates the instance and device: OpenXR's XR_KHR_vulkan_enable2 must
//! do it itself, so creation is injected through [`DeviceCreator`]; [`PlainVulkan`] is the
//! headless implementation.
//!
//! Just over 600 lines: the context's creation, which gives back what it made at every step
//! that can fail, reads best as one function.

use std::ffi::{CStr, c_char, c_void};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use crate::error::{RenderError, Result, VkContext};
pub use crate::validation::ValidationLog;
use crate::validation::debug_callback;
use crate::work::WorkTally;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The Vulkan API version the renderer asks for.
pub const API_VERSION: u32 = vk::API_VERSION_1_2;

/// How long any fence wait may take on a GPU before it is reported as
/// [`RenderError::Timeout`]: the slowest frame of a real GPU is a small fraction of it, and a GPU
/// that is silent for this long is hung.
pub const FENCE_TIMEOUT: Duration = Duration::from_secs(10);

/// The same on a CPU device (lavapipe), whose frames take as long as the scene's work and the
/// machine's load make them: a mesh searched at 16 positions per pixel at 1280 x 960 takes over
/// 10 s a frame on two busy cores (goblet-real.toml), and only a device that makes no progress
/// for this long is taken as hung.
pub const CPU_FENCE_TIMEOUT: Duration = Duration::from_secs(300);

/// How to set up the GPU context.
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable VK_LAYER_KHRONOS_validation with synchronisation validation, and count its
    /// messages (see [`GpuContext::validation`]).
    pub validation: bool,
    /// Pick the first device whose name contains this (case-insensitive); otherwise the best
    /// one (discrete, then integrated, then virtual, then CPU).
    pub device_name: Option<String>,
}

/// Creates the Vulkan instance and device: directly ([`PlainVulkan`]) or through an OpenXR
/// runtime.
pub trait DeviceCreator {
    /// Creates the instance from the renderer's create info (layers and extensions the
    /// renderer needs are already in it; an implementation may add its own).
    ///
    /// # Safety
    /// `info` must be a valid instance create info; the returned instance is owned by the
    /// caller, which destroys it.
    unsafe fn create_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance>;

    /// Chooses the physical device to render on.
    fn pick_physical_device(
        &mut self,
        instance: &ash::Instance,
        options: &ContextOptions,
    ) -> Result<vk::PhysicalDevice>;

    /// Creates the logical device.
    ///
    /// # Safety
    /// `physical` must come from `instance`; `info` must be valid for it.
    unsafe fn create_device(
        &mut self,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device>;
}

/// Creates the instance and device with plain Vulkan calls: the headless path.
#[derive(Debug, Default)]
pub struct PlainVulkan;

impl DeviceCreator for PlainVulkan {
    /// # Safety
    /// As [`DeviceCreator::create_instance`].
    unsafe fn create_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance> {
        // SAFETY: the trait's contract: `info` is a valid create info; the caller owns the
        // instance.
        unsafe { entry.create_instance(info, None) }.vk("vkCreateInstance")
    }

    fn pick_physical_device(
        &mut self,
        instance: &ash::Instance,
        options: &ContextOptions,
    ) -> Result<vk::PhysicalDevice> {
        // SAFETY: `instance` is a live instance.
        let devices =
            unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
        let usable: Vec<_> = devices
            .into_iter()
            .filter(|&pd| graphics_queue_family(instance, pd).is_some())
            .collect();
        if usable.is_empty() {
            return Err(RenderError::NoDevice(
                "no Vulkan device with a graphics queue; install Mesa's lavapipe \
                 (Debian: apt-get install mesa-vulkan-drivers) for a CPU device"
                    .into(),
            ));
        }
        if let Some(wanted) = &options.device_name {
            let wanted_lower = wanted.to_lowercase();
            return usable
                .iter()
                .copied()
                .find(|&pd| {
                    device_name(instance, pd)
                        .to_lowercase()
                        .contains(&wanted_lower)
                })
                .ok_or_else(|| {
                    let names: Vec<_> =
                        usable.iter().map(|&pd| device_name(instance, pd)).collect();
                    RenderError::NoDevice(format!(
                        "no device named like '{wanted}'; available: {}",
                        names.join(", ")
                    ))
                });
        }
        // SAFETY: in the closure, `pd` was enumerated from the live `instance`.
        let rank =
            |pd: vk::PhysicalDevice| match unsafe { instance.get_physical_device_properties(pd) }
                .device_type
            {
                vk::PhysicalDeviceType::DISCRETE_GPU => 0,
                vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
                vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
                vk::PhysicalDeviceType::CPU => 3,
                _ => 4,
            };
        Ok(usable
            .into_iter()
            .min_by_key(|&pd| rank(pd))
            .expect("non-empty"))
    }

    /// # Safety
    /// As [`DeviceCreator::create_device`].
    unsafe fn create_device(
        &mut self,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device> {
        // SAFETY: the trait's contract: `physical` comes from `instance` and `info` is valid
        // for it.
        unsafe { instance.create_device(physical, info, None) }.vk("vkCreateDevice")
    }
}

/// The Vulkan objects every pass borrows.
pub struct GpuContext {
    /// The loaded Vulkan library.
    pub entry: ash::Entry,
    /// The instance.
    pub instance: ash::Instance,
    /// The validation messenger and its loader, when validation is on.
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Validation messages seen so far (all zero when validation is off).
    validation: Arc<ValidationLog>,
    /// Whether validation is on.
    validation_enabled: bool,
    /// The chosen physical device.
    pub physical: vk::PhysicalDevice,
    /// The logical device.
    pub device: ash::Device,
    /// Index of the graphics queue family.
    pub queue_family: u32,
    /// The graphics queue all work is submitted to.
    pub queue: vk::Queue,
    /// Device memory allocator, shared with every buffer's and image's memory; `None` only
    /// during drop.
    allocator: Option<Arc<Mutex<Allocator>>>,
    /// Allocations left before [`GpuContext::fail_allocation_after`]'s injected failure
    /// (`u32::MAX`: never).
    allocations_before_failure: AtomicU32,
    /// Set by [`GpuContext::pretend_r32_float_unfiltered`].
    r32_float_unfiltered: AtomicBool,
    /// Command pool for one-shot uploads.
    upload_pool: vk::CommandPool,
    /// Human-readable device name.
    pub device_name: String,
    /// Driver name and version info.
    pub driver: String,
    /// Nanoseconds per timestamp tick; `None` when the queue cannot write timestamps.
    pub timestamp_period_ns: Option<f32>,
    /// Whether the device counts shader invocations (pipeline-statistics queries, enabled).
    pub pipeline_statistics: bool,
    /// Whether fragment shaders may write storage buffers and use atomics on them
    /// (`fragmentStoresAndAtomics`): the glass counts the positions it shades with them.
    pub fragment_atomics: bool,
    /// The work recorded into command buffers, counted as it is recorded.
    pub(crate) work: WorkTally,
    /// How long a fence wait may take before it is a timeout: [`FENCE_TIMEOUT`], or
    /// [`CPU_FENCE_TIMEOUT`] on a CPU device.
    fence_timeout: Duration,
}

impl GpuContext {
    /// A context without any XR runtime: plain Vulkan on the best (or the named) device.
    pub fn headless(options: &ContextOptions) -> Result<GpuContext> {
        GpuContext::new(options, &mut PlainVulkan, &[], &[])
    }

    /// Creates the context, letting `creator` create the instance and device. The extra
    /// extension names are added to what the renderer itself needs.
    pub fn new(
        options: &ContextOptions,
        creator: &mut dyn DeviceCreator,
        extra_instance_extensions: &[&CStr],
        extra_device_extensions: &[&CStr],
    ) -> Result<GpuContext> {
        // SAFETY: loading the system's Vulkan loader runs its initialisation; the loader is
        // trusted like any linked library, and `entry` keeps it loaded as long as the context.
        let entry = unsafe { ash::Entry::load() }?;

        let mut layers: Vec<*const c_char> = Vec::new();
        let mut instance_exts: Vec<*const c_char> = extra_instance_extensions
            .iter()
            .map(|e| e.as_ptr())
            .collect();
        if options.validation {
            // SAFETY: `entry` is a loaded Vulkan entry point.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .vk("vkEnumerateInstanceLayerProperties")?;
            let found = available
                .iter()
                .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
            if !found {
                return Err(RenderError::ValidationLayerMissing);
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            instance_exts.push(ash::ext::debug_utils::NAME.as_ptr());
            instance_exts.push(ash::ext::validation_features::NAME.as_ptr());
        }

        let app_info = vk::ApplicationInfo::default()
            .application_name(c"vitreous")
            .application_version(1)
            .engine_name(c"vitreous")
            .api_version(API_VERSION);
        let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
        let mut instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&instance_exts);
        if options.validation {
            instance_info = instance_info.push_next(&mut validation_features);
        }
        // SAFETY: `instance_info` and everything it points to (names, layers, extensions,
        // validation features) live until the call returns; the instance is owned by the
        // guard below until the context takes it.
        let instance = unsafe { creator.create_instance(&entry, &instance_info) }?;
        let mut guard = InstanceGuard(Some(instance.clone()), None);

        let validation = Arc::new(ValidationLog::default());
        let debug = if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                        | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&validation) as *mut c_void);
            // SAFETY: the callback's user data is the `ValidationLog` in `validation`, an `Arc`
            // the context keeps until after it destroys the messenger; the guard destroys
            // the messenger if construction fails.
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            Some((loader, messenger))
        } else {
            None
        };
        guard.1 = debug.clone();

        let physical = creator.pick_physical_device(&instance, options)?;
        let queue_family = graphics_queue_family(&instance, physical).ok_or_else(|| {
            RenderError::NoDevice("the chosen device has no graphics queue".into())
        })?;
        let priorities = [1.0f32];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let device_exts: Vec<*const c_char> =
            extra_device_extensions.iter().map(|e| e.as_ptr()).collect();
        // Pipeline-statistics queries (counted work, `work.rs`) where the device has them.
        // SAFETY: `physical` belongs to the live `instance`.
        let features = unsafe { instance.get_physical_device_features(physical) };
        // And atomics in fragment shaders, where the glass counts the positions it shades.
        let features = vk::PhysicalDeviceFeatures::default()
            .pipeline_statistics_query(features.pipeline_statistics_query == vk::TRUE)
            .fragment_stores_and_atomics(features.fragment_stores_and_atomics == vk::TRUE);
        let pipeline_statistics = features.pipeline_statistics_query == vk::TRUE;
        let fragment_atomics = features.fragment_stores_and_atomics == vk::TRUE;
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&device_exts)
            .enabled_features(&features);
        // SAFETY: `physical` was picked from `instance`, and `device_info` names one queue of
        // a family it has; the device is destroyed below on any later failure, or by the
        // context's drop.
        let device = unsafe { creator.create_device(&instance, physical, &device_info) }?;
        // SAFETY: queue 0 of `queue_family` was requested in `device_info`.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|source| {
            // SAFETY: nothing has been made on the device yet.
            unsafe { device.destroy_device(None) };
            RenderError::Allocation {
                what: "the allocator".into(),
                source,
            }
        })?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: a valid create info for a family of this device.
        let upload_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(pool) => pool,
            Err(e) => {
                drop(allocator);
                // SAFETY: the allocator (which owned the only device memory) is gone and
                // nothing else was made on the device.
                unsafe { device.destroy_device(None) };
                return Err(e).vk("vkCreateCommandPool");
            }
        };

        // SAFETY: `physical` belongs to the live `instance`,
        // and `props2`'s chain points to `driver_props`, alive for the call.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let mut driver_props = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver_props);
        // SAFETY: as above.
        unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
        let driver = format!(
            "{} {}",
            driver_props
                .driver_name_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            driver_props
                .driver_info_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        )
        .trim()
        .to_owned();
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let timestamp_period_ns = (families[queue_family as usize].timestamp_valid_bits > 0
            && props.limits.timestamp_compute_and_graphics == vk::TRUE)
            .then_some(props.limits.timestamp_period);

        guard.0 = None;
        guard.1 = None;
        let fence_timeout = if props.device_type == vk::PhysicalDeviceType::CPU {
            CPU_FENCE_TIMEOUT
        } else {
            FENCE_TIMEOUT
        };
        let ctx = GpuContext {
            fence_timeout,
            device_name: device_name(&instance, physical),
            entry,
            instance,
            debug,
            validation,
            validation_enabled: options.validation,
            physical,
            device,
            queue_family,
            queue,
            allocator: Some(Arc::new(Mutex::new(allocator))),
            allocations_before_failure: AtomicU32::new(u32::MAX),
            r32_float_unfiltered: AtomicBool::new(false),
            upload_pool,
            driver,
            timestamp_period_ns,
            pipeline_statistics,
            fragment_atomics,
            work: WorkTally::default(),
        };
        tracing::info!(
            device = %ctx.device_name,
            driver = %ctx.driver,
            validation = options.validation,
            "Vulkan device ready"
        );
        Ok(ctx)
    }

    /// Validation messages seen so far.
    pub fn validation(&self) -> &ValidationLog {
        &self.validation
    }

    /// Whether the validation layer is on.
    pub fn validation_enabled(&self) -> bool {
        self.validation_enabled
    }

    /// The validation log itself, which outlives the context (to check, after a failed
    /// construction dropped the context, that the device's destruction found no leaks).
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        Arc::clone(&self.validation)
    }

    /// Makes the allocation after the next `count` ones fail with [`RenderError::Injected`]
    /// (once; later ones succeed again). For tests that construction unwinds cleanly
    /// whichever step fails.
    #[doc(hidden)]
    pub fn fail_allocation_after(&self, count: u32) {
        self.allocations_before_failure
            .store(count, Ordering::Relaxed);
    }

    /// Whether the device filters sampled R32_SFLOAT images linearly (optional in Vulkan;
    /// where it does not, the floor overlay filters the caustic gain from four loads).
    pub fn filters_r32_float(&self) -> bool {
        // SAFETY: the physical device is this context's.
        let features = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical, vk::Format::R32_SFLOAT)
        }
        .optimal_tiling_features;
        features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
            && !self.r32_float_unfiltered.load(Ordering::Relaxed)
    }

    /// From now on [`GpuContext::filters_r32_float`] answers no, as on a device without the
    /// feature: for tests of the overlay's four-load path on devices that filter.
    #[doc(hidden)]
    pub fn pretend_r32_float_unfiltered(&self) {
        self.r32_float_unfiltered.store(true, Ordering::Relaxed);
    }

    /// Counts one allocation towards an injected failure; the error when it is due.
    pub(crate) fn check_injected_failure(&self, what: &str) -> Result<()> {
        let left = self.allocations_before_failure.load(Ordering::Relaxed);
        match left {
            u32::MAX => Ok(()),
            0 => {
                self.allocations_before_failure
                    .store(u32::MAX, Ordering::Relaxed);
                Err(RenderError::Injected(what.to_owned()))
            }
            n => {
                self.allocations_before_failure
                    .store(n - 1, Ordering::Relaxed);
                Ok(())
            }
        }
    }

    /// A shared handle to the device memory allocator, for memory that frees itself.
    pub(crate) fn shared_allocator(&self) -> Arc<Mutex<Allocator>> {
        Arc::clone(self.allocator.as_ref().expect("allocator lives until drop"))
    }

    /// Waits for `fence` for at most [`FENCE_TIMEOUT`] ([`CPU_FENCE_TIMEOUT`] on a CPU device);
    /// `what` names the work in the timeout error. A lost device is [`RenderError::DeviceLost`].
    pub(crate) fn wait_fence(&self, fence: vk::Fence, what: &'static str) -> Result<()> {
        let nanos = self.fence_timeout.as_nanos() as u64;
        // SAFETY: `fence` is a live fence of this device (the callers own it) and no other
        // thread resets it while we wait (they hold `&mut` or own it outright).
        match unsafe { self.device.wait_for_fences(&[fence], true, nanos) } {
            Err(vk::Result::TIMEOUT) => Err(RenderError::Timeout {
                what,
                seconds: self.fence_timeout.as_secs(),
            }),
            other => other.vk("vkWaitForFences"),
        }
    }

    /// Records commands with `record`, submits them and waits (at most [`FENCE_TIMEOUT`], or
    /// [`CPU_FENCE_TIMEOUT`] on a CPU device)
    /// until they finished. On a timeout the command buffer and fence are leaked, not freed
    /// under the GPU, and the caller must leak what the commands use too
    /// ([`RenderError::gpu_may_still_run`]).
    ///
    /// `record` gets a command buffer in the recording state, outside any render pass; the
    /// objects it records must live until this returns.
    pub(crate) fn one_shot(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let device = &self.device;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.upload_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the upload pool is live and only used from here, with `&self` (the pool is
        // transient and one_shot is not re-entered: recording closures do not call it).
        let cmd =
            unsafe { device.allocate_command_buffers(&info) }.vk("vkAllocateCommandBuffers")?[0];
        let mut fence = vk::Fence::null();
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            // SAFETY: `cmd` was just allocated and is in the initial state.
            unsafe { device.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
            record(cmd);
            // SAFETY: `cmd` is recording and `record` left no render pass open.
            unsafe { device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
            // SAFETY: a plain fence; destroyed below unless the wait times out.
            fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }
                .vk("vkCreateFence")?;
            let cmds = [cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            // SAFETY: `cmd` is executable, the fence unsignalled, and the queue is only used
            // from the thread that owns the context's users.
            unsafe { device.queue_submit(self.queue, &submit, fence) }.vk("vkQueueSubmit")?;
            self.wait_fence(fence, "a one-shot upload or readback")
        })();
        if result.as_ref().is_err_and(RenderError::gpu_may_still_run) {
            return result;
        }
        // SAFETY: the submission (if any) finished, or the device is lost (when objects may
        // be destroyed regardless); the fence may be null when it was never created.
        unsafe {
            device.destroy_fence(fence, None);
            device.free_command_buffers(self.upload_pool, &[cmd]);
        }
        result
    }
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        // Every buffer and image should be gone by now (their owners drop before the
        // context); one still alive would free its memory into an allocator without a device.
        if let Some(allocator) = &self.allocator
            && Arc::strong_count(allocator) > 1
        {
            tracing::error!(
                alive = Arc::strong_count(allocator) - 1,
                "GPU memory outlives its context; destroying the device anyway"
            );
        }
        // SAFETY: the context is the last owner of the device: the objects made on it were
        // dropped before it (they are held by the context's users, declared before it), so
        // after the idle wait nothing uses them; the allocator frees its memory blocks, so it
        // goes before the device, and the messenger and instance go last.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.upload_pool, None);
            self.allocator.take();
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// Destroys a half-built instance (and its messenger) if construction fails part way.
struct InstanceGuard(
    Option<ash::Instance>,
    Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
);

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        if let Some(instance) = self.0.take() {
            // SAFETY: construction failed before a device was made (or after it was
            // destroyed), so the messenger and instance have no children left.
            unsafe {
                if let Some((loader, messenger)) = self.1.take() {
                    loader.destroy_debug_utils_messenger(messenger, None);
                }
                instance.destroy_instance(None);
            }
        }
    }
}

fn graphics_queue_family(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<u32> {
    // SAFETY: `pd` was enumerated from the live `instance`.
    unsafe { instance.get_physical_device_queue_family_properties(pd) }
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
        .map(|i| i as u32)
}

fn device_name(instance: &ash::Instance, pd: vk::PhysicalDevice) -> String {
    // SAFETY: `pd` was enumerated from the live `instance`.
    let props = unsafe { instance.get_physical_device_properties(pd) };
    props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "unnamed device".into())
}
