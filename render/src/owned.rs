//! Vulkan handles that destroy themselves.
//!
//! Every object the renderer creates on the device is held by an [`Owned`] (or by a
//! [`crate::memory::Buffer`] / [`crate::memory::Image`], which also free their memory), so a
//! constructor that fails part way drops what it made so far, in reverse order, and a pass is
//! freed by dropping it. The device itself belongs to [`GpuContext`], which every owner of
//! these objects declares (or is handed) so that it drops last.

use ash::vk;

use crate::context::GpuContext;

/// A Vulkan object made on a device, destroyable with that device alone.
pub(crate) trait DeviceChild: Copy + Default + Eq {
    /// Destroys the object.
    ///
    /// # Safety
    /// `self` must have been created on `device` (or be null) and no pending GPU work may use
    /// it; it must not be used afterwards.
    unsafe fn destroy(self, device: &ash::Device);
}

macro_rules! device_child {
    ($($ty:ty => $destroy:ident),* $(,)?) => {$(
        impl DeviceChild for $ty {
            /// # Safety
            /// As [`DeviceChild::destroy`].
            unsafe fn destroy(self, device: &ash::Device) {
                // SAFETY: the caller upholds the trait's contract (made on `device`, idle,
                // not used again); destroying a null handle is a no-op in Vulkan.
                unsafe { device.$destroy(self, None) }
            }
        }
    )*};
}

device_child! {
    vk::RenderPass => destroy_render_pass,
    vk::Pipeline => destroy_pipeline,
    vk::PipelineLayout => destroy_pipeline_layout,
    vk::DescriptorSetLayout => destroy_descriptor_set_layout,
    vk::DescriptorPool => destroy_descriptor_pool,
    vk::Framebuffer => destroy_framebuffer,
    vk::ImageView => destroy_image_view,
    vk::Sampler => destroy_sampler,
    vk::CommandPool => destroy_command_pool,
    vk::Fence => destroy_fence,
    vk::QueryPool => destroy_query_pool,
    vk::ShaderModule => destroy_shader_module,
}

/// A Vulkan object destroyed when this is dropped.
pub(crate) struct Owned<H: DeviceChild> {
    /// The device it was made on (a cheap copy of the dispatch table).
    device: ash::Device,
    /// The object.
    handle: H,
}

impl<H: DeviceChild> Owned<H> {
    /// Takes ownership of `handle`, made on `ctx`'s device.
    pub fn new(ctx: &GpuContext, handle: H) -> Owned<H> {
        Owned {
            device: ctx.device.clone(),
            handle,
        }
    }

    /// The raw handle, valid while `self` lives.
    pub fn raw(&self) -> H {
        self.handle
    }
}

impl<H: DeviceChild> Drop for Owned<H> {
    fn drop(&mut self) {
        if self.handle != H::default() {
            // SAFETY: `handle` was made on `device` (see `new`); whoever holds an `Owned`
            // drops it only once the GPU is done with it (the renderer waits for the device to
            // be idle before dropping its passes, and construction has submitted nothing that
            // uses an object it is unwinding), and the `GpuContext` owning the device is
            // dropped after every `Owned` (it is the last field of its owners).
            unsafe { std::mem::take(&mut self.handle).destroy(&self.device) };
        }
    }
}
