//! The GPU context: Vulkan instance, validation messenger, device, queue and allocator.
//!
//! One context serves the headless path (tests, replay, benchmarks) and the OpenXR path. The
//! only difference is who creates the instance and device: OpenXR's XR_KHR_vulkan_enable2 must
//! do it itself, so creation is injected through [`DeviceCreator`]; [`PlainVulkan`] is the
//! headless implementation.

use std::ffi::{CStr, c_char, c_void};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use crate::error::{RenderError, Result, VkContext};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The Vulkan API version the renderer asks for.
pub const API_VERSION: u32 = vk::API_VERSION_1_2;

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
    unsafe fn create_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance> {
        unsafe { entry.create_instance(info, None) }.vk("vkCreateInstance")
    }

    fn pick_physical_device(
        &mut self,
        instance: &ash::Instance,
        options: &ContextOptions,
    ) -> Result<vk::PhysicalDevice> {
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

    unsafe fn create_device(
        &mut self,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device> {
        unsafe { instance.create_device(physical, info, None) }.vk("vkCreateDevice")
    }
}

/// Counts and keeps the validation layer's messages.
#[derive(Debug, Default)]
pub struct ValidationLog {
    /// Messages of warning severity seen so far.
    warnings: AtomicU32,
    /// Messages of error severity seen so far.
    errors: AtomicU32,
    /// The first few messages' texts, for test failures and logs.
    first: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Number of warning messages so far.
    pub fn warnings(&self) -> u32 {
        self.warnings.load(Ordering::Relaxed)
    }

    /// Number of error messages so far.
    pub fn errors(&self) -> u32 {
        self.errors.load(Ordering::Relaxed)
    }

    /// The first (up to 20) warning and error messages.
    pub fn messages(&self) -> Vec<String> {
        self.first.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            self.errors.fetch_add(1, Ordering::Relaxed);
            tracing::error!(target: "vulkan", "{text}");
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            self.warnings.fetch_add(1, Ordering::Relaxed);
            tracing::warn!(target: "vulkan", "{text}");
        } else {
            tracing::debug!(target: "vulkan", "{text}");
            return;
        }
        if let Ok(mut first) = self.first.lock()
            && first.len() < 20
        {
            first.push(text);
        }
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the ValidationLog kept alive by the GpuContext for the messenger's
    // lifetime; `data` is valid for the duration of the callback per the Vulkan spec.
    let log = unsafe { &*(user as *const ValidationLog) };
    let text = unsafe {
        data.as_ref()
            .filter(|d| !d.p_message.is_null())
            .map(|d| CStr::from_ptr(d.p_message).to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    log.record(severity, text);
    vk::FALSE
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
    /// Device memory allocator; `None` only during drop.
    allocator: Option<Mutex<Allocator>>,
    /// Command pool for one-shot uploads.
    upload_pool: vk::CommandPool,
    /// Human-readable device name.
    pub device_name: String,
    /// Driver name and version info.
    pub driver: String,
    /// Nanoseconds per timestamp tick; `None` when the queue cannot write timestamps.
    pub timestamp_period_ns: Option<f32>,
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
        let entry = unsafe { ash::Entry::load() }?;

        let mut layers: Vec<*const c_char> = Vec::new();
        let mut instance_exts: Vec<*const c_char> = extra_instance_extensions
            .iter()
            .map(|e| e.as_ptr())
            .collect();
        if options.validation {
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
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&device_exts);
        let device = unsafe { creator.create_device(&instance, physical, &device_info) }?;
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
            unsafe { device.destroy_device(None) };
            RenderError::Allocation {
                what: "the allocator".into(),
                source,
            }
        })?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        let upload_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(pool) => pool,
            Err(e) => {
                drop(allocator);
                unsafe { device.destroy_device(None) };
                return Err(e).vk("vkCreateCommandPool");
            }
        };

        let props = unsafe { instance.get_physical_device_properties(physical) };
        let mut driver_props = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver_props);
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
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let timestamp_period_ns = (families[queue_family as usize].timestamp_valid_bits > 0
            && props.limits.timestamp_compute_and_graphics == vk::TRUE)
            .then_some(props.limits.timestamp_period);

        guard.0 = None;
        guard.1 = None;
        let ctx = GpuContext {
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
            allocator: Some(Mutex::new(allocator)),
            upload_pool,
            driver,
            timestamp_period_ns,
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

    /// The device memory allocator.
    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator
            .as_ref()
            .expect("allocator lives until drop")
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Records commands with `record`, submits them and waits until they finished.
    pub(crate) fn one_shot(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let device = &self.device;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.upload_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd =
            unsafe { device.allocate_command_buffers(&info) }.vk("vkAllocateCommandBuffers")?[0];
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { device.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
            record(cmd);
            unsafe { device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
            let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }
                .vk("vkCreateFence")?;
            let cmds = [cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            let waited = unsafe { device.queue_submit(self.queue, &submit, fence) }
                .vk("vkQueueSubmit")
                .and_then(|_| {
                    unsafe { device.wait_for_fences(&[fence], true, u64::MAX) }
                        .vk("vkWaitForFences")
                });
            unsafe { device.destroy_fence(fence, None) };
            waited
        })();
        unsafe { device.free_command_buffers(self.upload_pool, &[cmd]) };
        result
    }
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.upload_pool, None);
            // The allocator frees its memory blocks, so it must go before the device.
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
    unsafe { instance.get_physical_device_queue_family_properties(pd) }
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
        .map(|i| i as u32)
}

fn device_name(instance: &ash::Instance, pd: vk::PhysicalDevice) -> String {
    let props = unsafe { instance.get_physical_device_properties(pd) };
    props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "unnamed device".into())
}
