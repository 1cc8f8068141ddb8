//! Vulkan through the runtime (XR_KHR_vulkan_enable2): the runtime creates the renderer's
//! instance and device and names the physical device its headset is driven by; these are the
//! calls [`super::XrDeviceCreator`], the renderer's device creator, makes.

use ash::vk;
use ash::vk::Handle;
use openxr as xr;

use super::{OpenXrError, Result, Runtime, XrContext};

impl Runtime {
    /// Checks that the renderer's Vulkan API version is one the runtime accepts.
    pub fn check_vulkan_version(&self, api_version: u32) -> Result<()> {
        let reqs = self
            .instance
            .graphics_requirements::<xr::Vulkan>(self.system)
            .xr("xrGetVulkanGraphicsRequirements2KHR")?;
        let ours = xr::Version::new(
            vk::api_version_major(api_version) as u16,
            vk::api_version_minor(api_version) as u16,
            0,
        );
        let min = reqs.min_api_version_supported;
        let max = reqs.max_api_version_supported;
        let key = |v: xr::Version| (v.major(), v.minor());
        if key(ours) < key(min) || key(ours) > key(max) {
            return Err(OpenXrError::Unsupported(format!(
                "the runtime accepts Vulkan {}.{} to {}.{}; vitreous uses {}.{}",
                min.major(),
                min.minor(),
                max.major(),
                max.minor(),
                ours.major(),
                ours.minor()
            )));
        }
        Ok(())
    }

    /// Creates the Vulkan instance through the runtime (xrCreateVulkanInstanceKHR).
    ///
    /// # Safety
    /// `info` must be a valid instance create info; the caller owns and destroys the instance
    /// after every session made from this runtime is gone.
    pub unsafe fn create_vulkan_instance(
        &mut self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<ash::Instance> {
        let gipa = entry.static_fn().get_instance_proc_addr;
        // SAFETY: `info` is valid (the caller's contract) and `gipa` is the loader's own
        // vkGetInstanceProcAddr; the runtime only reads both during the call.
        let raw = unsafe {
            self.instance.create_vulkan_instance(
                self.system,
                std::mem::transmute::<
                    vk::PFN_vkGetInstanceProcAddr,
                    xr::sys::platform::VkGetInstanceProcAddr,
                >(gipa),
                info as *const vk::InstanceCreateInfo as *const _,
            )
        }
        .xr("xrCreateVulkanInstanceKHR")?
        .map_err(|result| OpenXrError::Vulkan {
            call: "vkCreateInstance",
            result: vk::Result::from_raw(result),
        })?;
        let handle = vk::Instance::from_raw(raw as u64);
        self.vk_instance = Some(handle);
        // SAFETY: `handle` is the instance the runtime just created with this entry's loader.
        Ok(unsafe { ash::Instance::load(entry.static_fn(), handle) })
    }

    /// The physical device the runtime's headset is driven by (xrGetVulkanGraphicsDevice2KHR).
    pub fn vulkan_physical_device(&self, instance: &ash::Instance) -> Result<vk::PhysicalDevice> {
        // SAFETY: `instance` was created through this runtime (create_vulkan_instance), on
        // this system.
        let raw = unsafe {
            self.instance
                .vulkan_graphics_device(self.system, instance.handle().as_raw() as _)
        }
        .xr("xrGetVulkanGraphicsDevice2KHR")?;
        Ok(vk::PhysicalDevice::from_raw(raw as u64))
    }

    /// Creates the logical device through the runtime (xrCreateVulkanDeviceKHR).
    ///
    /// # Safety
    /// `physical` must come from [`Runtime::vulkan_physical_device`]; `info` must be valid.
    pub unsafe fn create_vulkan_device(
        &mut self,
        entry: &ash::Entry,
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<ash::Device> {
        let gipa = entry.static_fn().get_instance_proc_addr;
        // SAFETY: `physical` came from the runtime and `info` is valid (the caller's contract).
        let raw = unsafe {
            self.instance.create_vulkan_device(
                self.system,
                std::mem::transmute::<
                    vk::PFN_vkGetInstanceProcAddr,
                    xr::sys::platform::VkGetInstanceProcAddr,
                >(gipa),
                physical.as_raw() as _,
                info as *const vk::DeviceCreateInfo as *const _,
            )
        }
        .xr("xrCreateVulkanDeviceKHR")?
        .map_err(|result| OpenXrError::Vulkan {
            call: "vkCreateDevice",
            result: vk::Result::from_raw(result),
        })?;
        // SAFETY: `raw` is the device the runtime just created on `instance`.
        Ok(unsafe { ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(raw as u64)) })
    }
}
