//! Rendering into images the renderer does not own (OpenXR swapchain images).
//!
//! An OpenXR runtime hands out a few 2-layer colour images (its swapchain) and says, frame by
//! frame, which one to draw. [`Renderer::attach_external`] makes a framebuffer per image and
//! layer once; [`Renderer::submit_external`] then records the same passes as
//! [`Renderer::submit`] into the chosen image. The eye images keep their own depth buffer (the
//! renderer's), and the colour image is left in `COLOR_ATTACHMENT_OPTIMAL`, the layout OpenXR
//! expects back on release. A readback of such a frame copies the external image, so tests can
//! check what was really handed to the runtime.

use ash::vk;

use super::{FrameResult, Renderer, Want};
use crate::camera::FrameParams;
use crate::context::GpuContext;
use crate::error::{RenderError, Result, VkContext};
use crate::target;

/// Framebuffers over external images.
pub(super) struct External {
    /// Render pass leaving colour in `COLOR_ATTACHMENT_OPTIMAL`.
    pub(super) render_pass: vk::RenderPass,
    /// The external images, 2 layers each; not owned.
    pub(super) images: Vec<vk::Image>,
    /// Per-layer colour views of the images, owned.
    views: Vec<vk::ImageView>,
    /// Per-layer views of the renderer's own depth image, owned.
    depth_views: Vec<vk::ImageView>,
    /// Framebuffer of each image's left and right layer.
    pub(super) framebuffers: Vec<[vk::Framebuffer; 2]>,
}

/// Which external image a frame is drawn into, and how.
#[derive(Clone, Copy, Debug)]
pub(super) struct ExternalDraw {
    /// Index into [`External::images`].
    pub(super) image: usize,
    /// Draw the real world (floor and background photos) behind the glass.
    pub(super) world_behind: bool,
}

impl External {
    /// Frees the views, framebuffers and render pass (not the images).
    ///
    /// # Safety
    /// The GPU must no longer use them.
    pub(super) unsafe fn destroy(&mut self, ctx: &GpuContext) {
        let d = &ctx.device;
        unsafe {
            for fb in self.framebuffers.drain(..).flatten() {
                if fb != vk::Framebuffer::null() {
                    d.destroy_framebuffer(fb, None);
                }
            }
            for view in self.views.drain(..).chain(self.depth_views.drain(..)) {
                d.destroy_image_view(view, None);
            }
            if self.render_pass != vk::RenderPass::null() {
                d.destroy_render_pass(self.render_pass, None);
                self.render_pass = vk::RenderPass::null();
            }
        }
    }
}

/// Records a layout change of both layers of a colour image, ordering colour-attachment and
/// transfer work on either side.
///
/// # Safety
/// `cmd` must be recording outside a render pass; `image` must be in layout `from`.
pub(super) unsafe fn transition(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    from: vk::ImageLayout,
    to: vk::ImageLayout,
) {
    let stages = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::TRANSFER;
    let access = vk::AccessFlags::COLOR_ATTACHMENT_WRITE
        | vk::AccessFlags::COLOR_ATTACHMENT_READ
        | vk::AccessFlags::TRANSFER_READ;
    let barrier = vk::ImageMemoryBarrier::default()
        .src_access_mask(access)
        .dst_access_mask(access)
        .old_layout(from)
        .new_layout(to)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 2,
        });
    unsafe {
        d.cmd_pipeline_barrier(
            cmd,
            stages,
            stages,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier],
        );
    }
}

impl Renderer {
    /// Lets later frames be drawn into `images`: 2-layer colour images of `format` and the
    /// renderer's [size](Renderer::size), one layer per eye, created with colour-attachment
    /// (and, for readbacks, transfer-source) usage, such as an OpenXR swapchain's. Replaces
    /// images attached before.
    ///
    /// `format` must be the renderer's colour format, `R8G8B8A8_SRGB` (shaders write linear
    /// light and the image encodes it); other formats are refused with a clear error.
    ///
    /// # Safety
    /// The images must live, on this renderer's device, until [`Renderer::detach_external`]
    /// or the renderer's drop.
    pub unsafe fn attach_external(
        &mut self,
        images: &[vk::Image],
        format: vk::Format,
    ) -> Result<()> {
        if format != target::COLOR_FORMAT {
            return Err(RenderError::InvalidInput(format!(
                "external images of format {format:?}: the renderer draws {:?} only",
                target::COLOR_FORMAT
            )));
        }
        if images.is_empty() {
            return Err(RenderError::InvalidInput(
                "no external images to attach".into(),
            ));
        }
        self.detach_external()?;
        let ctx = &self.ctx;
        let render_pass =
            target::create_render_pass_for(ctx, format, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)?;
        let mut external = External {
            render_pass,
            images: images.to_vec(),
            views: Vec::new(),
            depth_views: Vec::new(),
            framebuffers: Vec::new(),
        };
        let built = (|| {
            for layer in 0..2 {
                external
                    .depth_views
                    .push(self.eye_target.depth.layer_view(ctx, layer)?);
            }
            for &image in images {
                let mut fbs = [vk::Framebuffer::null(); 2];
                for layer in 0..2u32 {
                    let info = vk::ImageViewCreateInfo::default()
                        .image(image)
                        .view_type(vk::ImageViewType::TYPE_2D)
                        .format(format)
                        .subresource_range(vk::ImageSubresourceRange {
                            aspect_mask: vk::ImageAspectFlags::COLOR,
                            base_mip_level: 0,
                            level_count: 1,
                            base_array_layer: layer,
                            layer_count: 1,
                        });
                    let view = unsafe { ctx.device.create_image_view(&info, None) }
                        .vk("vkCreateImageView")?;
                    external.views.push(view);
                    let attachments = [view, external.depth_views[layer as usize]];
                    let fb_info = vk::FramebufferCreateInfo::default()
                        .render_pass(render_pass)
                        .attachments(&attachments)
                        .width(self.extent.width)
                        .height(self.extent.height)
                        .layers(1);
                    fbs[layer as usize] = unsafe { ctx.device.create_framebuffer(&fb_info, None) }
                        .vk("vkCreateFramebuffer")?;
                }
                external.framebuffers.push(fbs);
            }
            Ok(())
        })();
        match built {
            Ok(()) => {
                self.external = Some(external);
                Ok(())
            }
            Err(e) => {
                unsafe { external.destroy(ctx) };
                Err(e)
            }
        }
    }

    /// Waits for every frame in flight and forgets the external images (they may then be
    /// destroyed). Frames still in flight are lost: call [`Renderer::flush`] first to keep them.
    pub fn detach_external(&mut self) -> Result<()> {
        if let Some(mut external) = self.external.take() {
            unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
            unsafe { external.destroy(&self.ctx) };
        }
        Ok(())
    }

    /// Number of attached external images (0 when none).
    pub fn external_count(&self) -> usize {
        self.external.as_ref().map_or(0, |e| e.images.len())
    }

    /// Like [`Renderer::submit`], drawing into attached external image `image` (its index in
    /// the slice given to [`Renderer::attach_external`]). With `world_behind`, the real world
    /// (the scene's floor and background photos) is drawn behind the glass, for displays that
    /// show no real world of their own (OpenXR's OPAQUE blend mode). A readback (`want.eyes`)
    /// copies the external image itself.
    ///
    /// The caller must have waited for the image to be free (OpenXR: xrWaitSwapchainImage); the
    /// rendering is submitted to the queue on return, as OpenXR requires before the image is
    /// released.
    pub fn submit_external(
        &mut self,
        image: usize,
        params: &FrameParams,
        want: Want,
        world_behind: bool,
    ) -> Result<Option<FrameResult>> {
        let count = self.external_count();
        if image >= count {
            return Err(RenderError::InvalidInput(format!(
                "external image {image} does not exist ({count} attached)"
            )));
        }
        self.submit_to(
            params,
            want,
            Some(ExternalDraw {
                image,
                world_behind,
            }),
        )
    }
}
