//! A window's Vulkan swapchain, and putting a finished picture on screen (`vitreous view`).
//!
//! The window and its surface are the caller's: a [`Presenter`] takes a `vk::SurfaceKHR`
//! already made on its context's instance and a [`PresentWindow`] standing for the window
//! (its size, and what the windowing system is told around each presentation), so this crate
//! knows no windowing library.
//!
//! # Synchronisation
//! [`FRAMES_IN_FLIGHT`] presentation slots are used round-robin. Each slot owns a fence (its
//! last submission finished), an acquire semaphore (the swapchain image may be written), a
//! command buffer and a host-visible staging buffer the picture is written into. Each
//! swapchain image owns a render-finished semaphore that its copy signals and its present waits
//! for: a semaphore per image, not per slot, because presentation may still hold a slot's
//! semaphore when the slot comes round again. [`Presenter::present`] waits for the slot's
//! fence before touching its staging buffer or command buffer.
//!
//! The picture is copied (`vkCmdCopyBufferToImage`) into the acquired image: the renderer's
//! images come back as bytes already (sRGB-encoded RGBA8), which the presenter writes into a
//! UNORM swapchain image unchanged, so the screen shows the bytes the PNG files hold.
//!
//! # Recreation
//! A swapchain that is out of date or suboptimal, or whose window changed size, is recreated
//! before the next picture after the device is idle; a window of zero size (minimised)
//! presents nothing until it has a size again.

mod staging;

use ash::vk;

use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use staging::{Staging, record_copy};

/// The window a [`Presenter`] puts pictures in, as far as presenting needs it. Whoever
/// implements it keeps the native window alive for as long as the value lives.
pub trait PresentWindow {
    /// Size of the window's drawable area now, pixels.
    fn size(&self) -> (u32, u32);

    /// A picture is about to be presented (winit: `pre_present_notify`, which on Wayland
    /// asks for a frame callback for it).
    fn presenting(&self);

    /// A picture was handed to presentation: ask for the next (winit: `request_redraw`).
    fn presented(&self);
}

/// Presentation slots in flight at once.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// What became of a picture handed to [`Presenter::present`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    /// It is on screen (queued for presentation).
    Shown,
    /// The window has no area (minimised): nothing was presented.
    Hidden,
    /// The swapchain was out of date: it is recreated, the picture was dropped.
    Recreated,
    /// The window did not ask for a picture (hidden): nothing was presented.
    NotAsked,
}

/// One presentation slot.
struct Slot {
    /// Signalled when the slot's last copy finished.
    fence: vk::Fence,
    /// Signalled when the image acquired for the slot may be written.
    acquired: vk::Semaphore,
    /// The copy's command buffer (freed with the pool).
    cmd: vk::CommandBuffer,
    /// Host-visible staging buffer for one picture.
    staging: Staging,
}

/// The swapchain and what belongs to each of its images.
struct Chain {
    /// The swapchain.
    swapchain: vk::SwapchainKHR,
    /// Its images (owned by the swapchain).
    images: Vec<vk::Image>,
    /// One render-finished semaphore per image.
    finished: Vec<vk::Semaphore>,
    /// Size of the images, pixels.
    extent: vk::Extent2D,
}

/// The window's surface and swapchain on its own Vulkan device.
///
/// Fields are freed in [`Drop`] in the reverse order of creation; the context (holding the
/// device and instance) and then the window drop after that.
pub struct Presenter<W: PresentWindow> {
    /// Presentation slots.
    slots: Vec<Slot>,
    /// The slot the next picture uses.
    next_slot: usize,
    /// The swapchain, once made (none while the window has no area).
    chain: Option<Chain>,
    /// Recreate the swapchain before the next picture.
    stale: bool,
    /// Image format of the swapchain.
    format: vk::SurfaceFormatKHR,
    /// Command pool of the slots.
    pool: vk::CommandPool,
    /// The surface.
    surface: vk::SurfaceKHR,
    /// Surface functions.
    surface_fn: ash::khr::surface::Instance,
    /// Swapchain functions.
    swapchain_fn: ash::khr::swapchain::Device,
    /// The last picture shown (RGBA8, rows from the top) and its size.
    last: Option<(Vec<u8>, u32, u32)>,
    /// Pictures handed to [`Presenter::present`] that were not shown.
    not_shown: u64,
    /// The Vulkan device the window's images live on; dropped after everything above.
    ctx: GpuContext,
    /// The window; dropped after its surface.
    window: W,
}

impl<W: PresentWindow> Presenter<W> {
    /// The presentation slots for `surface` on `ctx`, whose device must have been made with
    /// `VK_KHR_swapchain`.
    ///
    /// # Safety
    /// `surface` must be a live surface made on `ctx.instance` for the native window `window`
    /// stands for, which `window` keeps alive as long as it lives; nothing else may destroy
    /// it: the presenter owns it from this call on (and destroys it, also when this fails).
    pub unsafe fn new(ctx: GpuContext, surface: vk::SurfaceKHR, window: W) -> Result<Self> {
        let surface_fn = ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance);
        let swapchain_fn = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        // From here on the guard owns what is made; Drop frees whatever exists.
        let mut presenter = Presenter {
            slots: Vec::new(),
            next_slot: 0,
            chain: None,
            stale: true,
            format: vk::SurfaceFormatKHR::default(),
            pool: vk::CommandPool::null(),
            surface,
            surface_fn,
            swapchain_fn,
            last: None,
            not_shown: 0,
            ctx,
            window,
        };
        presenter.init()?;
        Ok(presenter)
    }

    /// Checks presentation support, picks the format and makes the slots.
    fn init(&mut self) -> Result<()> {
        let (pd, family) = (self.ctx.physical, self.ctx.queue_family);
        // SAFETY: physical device, queue family and surface are live and of this instance.
        let supported = unsafe {
            self.surface_fn
                .get_physical_device_surface_support(pd, family, self.surface)
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !supported {
            return Err(RenderError::Presentation(format!(
                "the Vulkan device {} cannot present to this window from its graphics queue",
                self.ctx.device_name
            )));
        }
        // SAFETY: as above.
        let formats = unsafe {
            self.surface_fn
                .get_physical_device_surface_formats(pd, self.surface)
        }
        .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        self.format = pick_format(&formats).ok_or_else(|| {
            RenderError::Presentation(format!(
                "the window offers no 8-bit RGBA or BGRA UNORM format: {formats:?}"
            ))
        })?;
        let d = &self.ctx.device;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: a valid create info for the device's queue family; freed in Drop.
        self.pool = unsafe { d.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(FRAMES_IN_FLIGHT as u32);
        // SAFETY: the pool is live and used only here.
        let cmds = unsafe { d.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?;
        for cmd in cmds {
            let signalled = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            // SAFETY: a valid create info; the fence goes into a slot (freed in Drop) at once,
            // so it does not leak on a later error.
            let fence = unsafe { d.create_fence(&signalled, None) }.vk("vkCreateFence")?;
            self.slots.push(Slot {
                fence,
                acquired: vk::Semaphore::null(),
                cmd,
                staging: Staging::EMPTY,
            });
            let slot = self.slots.last_mut().expect("pushed above");
            // SAFETY: a valid create info; stored in the slot (freed in Drop) at once.
            slot.acquired =
                unsafe { d.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                    .vk("vkCreateSemaphore")?;
        }
        Ok(())
    }

    /// The presenting device's context (its validation log).
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Size of the window's drawable area now, pixels.
    pub fn window_size(&self) -> (u32, u32) {
        self.window.size()
    }

    /// The last picture put on screen (RGBA8, rows from the top), with its width and height.
    pub fn last_shown(&self) -> Option<(&[u8], u32, u32)> {
        self.last.as_ref().map(|(p, w, h)| (p.as_slice(), *w, *h))
    }

    /// Pictures handed to [`Presenter::present`] that were not shown.
    pub fn frames_not_shown(&self) -> u64 {
        self.not_shown
    }

    /// Puts a picture on screen if the window asked for one (`asked`: the windowing system
    /// asked for a picture since the last one, winit's `RedrawRequested`). `draw` fills an
    /// RGBA8 buffer of the given width and height (the swapchain's size, rows from the top);
    /// it is not called when nothing is presented.
    pub fn present(
        &mut self,
        asked: bool,
        draw: impl FnOnce(&mut [u8], u32, u32),
    ) -> Result<Presented> {
        let shown = self.present_asked(asked, draw)?;
        if shown != Presented::Shown {
            self.not_shown += 1;
        }
        Ok(shown)
    }

    /// [`Presenter::present`] without the count.
    fn present_asked(
        &mut self,
        asked: bool,
        draw: impl FnOnce(&mut [u8], u32, u32),
    ) -> Result<Presented> {
        if !asked {
            return Ok(Presented::NotAsked);
        }
        let (w, h) = self.window_size();
        if w == 0 || h == 0 {
            return Ok(Presented::Hidden);
        }
        let size_changed = self
            .chain
            .as_ref()
            .is_none_or(|c| (c.extent.width, c.extent.height) != (w, h));
        if (self.stale || size_changed) && !self.recreate()? {
            return Ok(Presented::Hidden);
        }
        let chain = self
            .chain
            .as_ref()
            .ok_or_else(|| RenderError::Presentation("no swapchain after recreation".into()))?;
        let extent = chain.extent;
        let slot_index = self.next_slot;
        let d = &self.ctx.device;
        let slot = &self.slots[slot_index];
        // SAFETY: the fence is live; waiting has no other precondition.
        unsafe { d.wait_for_fences(&[slot.fence], true, u64::MAX) }
            .vk("vkWaitForFences (a presentation slot)")?;
        // SAFETY: swapchain and semaphore are live; the slot's semaphore is unsignalled (its
        // last acquire was waited on by the slot's last submission, finished per its fence).
        let acquired = unsafe {
            self.swapchain_fn.acquire_next_image(
                chain.swapchain,
                u64::MAX,
                slot.acquired,
                vk::Fence::null(),
            )
        };
        let image_index = match acquired {
            Ok((index, suboptimal)) => {
                self.stale |= suboptimal;
                index
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                return Ok(Presented::Recreated);
            }
            Err(e) => return Err(e).vk("vkAcquireNextImageKHR"),
        };
        let bytes = u64::from(extent.width) * u64::from(extent.height) * 4;
        self.slots[slot_index].staging.ensure(&self.ctx, bytes)?;
        let mut picture = vec![0u8; bytes as usize];
        draw(&mut picture, extent.width, extent.height);
        let d = &self.ctx.device;
        let slot = &mut self.slots[slot_index];
        let chain = self
            .chain
            .as_ref()
            .ok_or_else(|| RenderError::Presentation("no swapchain".into()))?;
        let bgra = matches!(self.format.format, vk::Format::B8G8R8A8_UNORM);
        // SAFETY: the buffer was sized for `bytes` above, and no submitted work uses it (the
        // slot's fence signalled above).
        let staging = unsafe { slot.staging.bytes_mut(bytes as usize) };
        if bgra {
            // Red and blue swapped in place by an index loop (per-pixel iterators cost more
            // than the copy in unoptimised builds), then one copy into mapped memory.
            let mut i = 0;
            while i + 3 < picture.len() {
                picture.swap(i, i + 2);
                picture[i + 3] = 255;
                i += 4;
            }
        }
        staging.copy_from_slice(&picture);
        let image = chain.images[image_index as usize];
        let finished = chain.finished[image_index as usize];
        // SAFETY: the slot's command buffer and fence are free (fence signalled); the image was
        // acquired with the slot's semaphore, which the submission waits for before the copy;
        // the staging buffer and image outlive the submission (recreation and Drop wait for
        // the device to be idle first).
        unsafe {
            d.reset_fences(&[slot.fence]).vk("vkResetFences")?;
            d.reset_command_buffer(slot.cmd, vk::CommandBufferResetFlags::empty())
                .vk("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(slot.cmd, &begin)
                .vk("vkBeginCommandBuffer")?;
            record_copy(d, slot.cmd, slot.staging.buffer, image, extent);
            d.end_command_buffer(slot.cmd).vk("vkEndCommandBuffer")?;
            let waits = [slot.acquired];
            let stages = [vk::PipelineStageFlags::TRANSFER];
            let cmds = [slot.cmd];
            let signals = [finished];
            let submit = vk::SubmitInfo::default()
                .wait_semaphores(&waits)
                .wait_dst_stage_mask(&stages)
                .command_buffers(&cmds)
                .signal_semaphores(&signals);
            d.queue_submit(self.ctx.queue, &[submit], slot.fence)
                .vk("vkQueueSubmit (presentation copy)")?;
        }
        self.next_slot = (self.next_slot + 1) % FRAMES_IN_FLIGHT;
        let swapchains = [chain.swapchain];
        let indices = [image_index];
        let waits = [finished];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        // The windowing system is told a picture follows (Wayland: a frame callback for it),
        // and asked for the next one, which it asks for in turn once this one is taken.
        self.window.presenting();
        // SAFETY: the image was acquired from this swapchain and the submission above signals
        // the semaphore presentation waits for.
        let result = unsafe { self.swapchain_fn.queue_present(self.ctx.queue, &info) };
        self.window.presented();
        match result {
            Ok(suboptimal) => self.stale |= suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.stale = true,
            Err(e) => return Err(e).vk("vkQueuePresentKHR"),
        }
        self.last = Some((picture, extent.width, extent.height));
        Ok(Presented::Shown)
    }

    /// Makes a swapchain of the window's current size; false when the window has no area.
    fn recreate(&mut self) -> Result<bool> {
        let (pd, surface) = (self.ctx.physical, self.surface);
        // SAFETY: physical device and surface are live.
        let caps = unsafe {
            self.surface_fn
                .get_physical_device_surface_capabilities(pd, surface)
        }
        .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let (w, h) = self.window_size();
        let extent = if caps.current_extent.width == u32::MAX {
            vk::Extent2D {
                width: w.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: h.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        } else {
            caps.current_extent
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(false);
        }
        if !caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_DST)
        {
            return Err(RenderError::Presentation(
                "the window's swapchain images cannot be copied to (no TRANSFER_DST usage)".into(),
            ));
        }
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        // SAFETY: waiting for idle has no precondition; afterwards no copy uses the old
        // swapchain's images or semaphores, which are freed below.
        unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
        let old = self.chain.take();
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface)
            .min_image_count(count)
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(
                old.as_ref()
                    .map_or(vk::SwapchainKHR::null(), |c| c.swapchain),
            );
        // SAFETY: a valid create info for this live surface; the old swapchain (retired by
        // this call) is destroyed right after, with the device idle.
        let created = unsafe { self.swapchain_fn.create_swapchain(&info, None) };
        if let Some(old) = old {
            self.destroy_chain(old);
        }
        let swapchain = created.vk("vkCreateSwapchainKHR")?;
        let mut chain = Chain {
            swapchain,
            images: Vec::new(),
            finished: Vec::new(),
            extent,
        };
        // SAFETY: the swapchain is live.
        let images = unsafe { self.swapchain_fn.get_swapchain_images(swapchain) };
        chain.images = match images {
            Ok(images) => images,
            Err(e) => {
                self.destroy_chain(chain);
                return Err(e).vk("vkGetSwapchainImagesKHR");
            }
        };
        for _ in 0..chain.images.len() {
            // SAFETY: a valid create info; stored in the chain at once.
            match unsafe {
                self.ctx
                    .device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            } {
                Ok(s) => chain.finished.push(s),
                Err(e) => {
                    self.destroy_chain(chain);
                    return Err(e).vk("vkCreateSemaphore");
                }
            }
        }
        tracing::debug!(
            "window swapchain {}x{}, {} images",
            extent.width,
            extent.height,
            chain.images.len()
        );
        self.chain = Some(chain);
        self.stale = false;
        Ok(true)
    }

    /// Frees a swapchain and its semaphores. Call only with the device idle.
    fn destroy_chain(&self, chain: Chain) {
        // SAFETY: the caller's contract: no work uses the semaphores or the images any more.
        unsafe {
            for s in chain.finished {
                self.ctx.device.destroy_semaphore(s, None);
            }
            self.swapchain_fn.destroy_swapchain(chain.swapchain, None);
        }
    }
}

impl<W: PresentWindow> Drop for Presenter<W> {
    fn drop(&mut self) {
        let d = &self.ctx.device;
        // SAFETY: after the device is idle no submitted work uses any object freed here; each
        // is freed once (null handles are ignored by the destroy calls). The surface goes
        // before the instance (dropped with `ctx` after this) and before the window.
        unsafe {
            let _ = d.device_wait_idle();
            for slot in &mut self.slots {
                slot.staging.free(d);
                d.destroy_semaphore(slot.acquired, None);
                d.destroy_fence(slot.fence, None);
            }
            if let Some(chain) = self.chain.take() {
                self.destroy_chain(chain);
            }
            d.destroy_command_pool(self.pool, None);
            self.surface_fn.destroy_surface(self.surface, None);
        }
    }
}

/// An 8-bit UNORM format (the picture's bytes are already sRGB-encoded), BGRA first.
fn pick_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM]
        .iter()
        .find_map(|&f| {
            formats
                .iter()
                .copied()
                .find(|s| s.format == f && s.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unorm_format_is_picked_and_srgb_formats_are_not() {
        let f = |format| vk::SurfaceFormatKHR {
            format,
            color_space: vk::ColorSpaceKHR::SRGB_NONLINEAR,
        };
        assert_eq!(
            pick_format(&[f(vk::Format::B8G8R8A8_SRGB), f(vk::Format::R8G8B8A8_UNORM)]),
            Some(f(vk::Format::R8G8B8A8_UNORM))
        );
        assert_eq!(pick_format(&[f(vk::Format::B8G8R8A8_SRGB)]), None);
    }
}
