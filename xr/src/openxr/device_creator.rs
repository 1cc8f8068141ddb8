//! The renderer's Vulkan instance and device, created through the OpenXR runtime as
//! XR_KHR_vulkan_enable2 requires: the runtime's `create_vulkan_*` calls (`vulkan.rs`) as the
//! renderer's [`DeviceCreator`].

use ash::vk;
use vitreous_render::context::API_VERSION;
use vitreous_render::{ContextOptions, DeviceCreator, RenderError};

use super::Runtime;

/// Creates the renderer's Vulkan instance and device through the OpenXR runtime.
pub struct XrDeviceCreator<'a> {
    /// The runtime.
    pub runtime: &'a mut Runtime,
}

fn creation(e: impl std::fmt::Display) -> RenderError {
    RenderError::Creation(e.to_string())
}

impl DeviceCreator for XrDeviceCreator<'_> {
    /// # Safety
    /// As [`DeviceCreator::create_instance`].
    unsafe fn create_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance, RenderError> {
        self.runtime
            .check_vulkan_version(API_VERSION)
            .map_err(creation)?;
        // SAFETY: `info` is valid (this function's own contract); the caller (GpuContext) owns
        // the instance and destroys it after every session of the runtime is gone.
        unsafe { self.runtime.create_vulkan_instance(entry, info) }.map_err(creation)
    }

    fn pick_physical_device(
        &mut self,
        instance: &ash::Instance,
        _options: &ContextOptions,
    ) -> Result<vk::PhysicalDevice, RenderError> {
        // The headset decides: it is driven by one GPU.
        self.runtime
            .vulkan_physical_device(instance)
            .map_err(creation)
    }

    /// # Safety
    /// As [`DeviceCreator::create_device`].
    unsafe fn create_device(
        &mut self,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device, RenderError> {
        // SAFETY: loading the Vulkan loader only runs its initialisation.
        let entry = unsafe { ash::Entry::load() }?;
        // SAFETY: `physical` came from `pick_physical_device`, i.e. from the runtime, and
        // `info` is valid (this function's own contract).
        unsafe {
            self.runtime
                .create_vulkan_device(&entry, instance, physical, info)
        }
        .map_err(creation)
    }
}
