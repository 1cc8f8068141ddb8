//! Rendering into images the renderer does not own (OpenXR swapchain images).
//!
//! An OpenXR runtime hands out a few 2-layer colour images (its swapchain) and says, frame by
//! frame, which one to draw. [`Renderer::attach_external`] makes a framebuffer per image and
//! layer once; [`Renderer::submit_external`] then records the same passes as
//! [`Renderer::submit`] into the chosen image. Depth goes to the renderer's own depth buffer
//! (but see below), and the colour image is left in `COLOR_ATTACHMENT_OPTIMAL`, the layout OpenXR
//! expects back on release. A readback of such a frame copies the external image, so tests can
//! check what was really handed to the runtime.
//!
//! Images of another 8-bit colour format (a runtime offering BGRA first, or only UNORM) get
//! framebuffers over the renderer's own eye image instead, and each frame is blitted into the
//! chosen image after its passes ([`super::convert`]).
//!
//! With [`Renderer::attach_external_with_depth`], the eye passes write their depth into
//! external 2-layer depth images too (an OpenXR depth swapchain for
//! XR_KHR_composition_layer_depth): the depth attachment is stored and left in
//! `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`. The colour and depth swapchains hand out their images
//! independently, so there is a framebuffer per (colour image, depth image, layer).

use ash::vk;

use super::convert::{self, Texels};
use super::{Composition, FrameResult, Renderer, Want};
use crate::error::{RenderError, Result, VkContext};
use crate::look::FrameParams;
use crate::memory::{layout_barrier, subresource_range};
use crate::owned::Owned;
use crate::{pipeline, target};

/// Framebuffers over external images; the views, framebuffers and render pass are freed on
/// drop (the images are not).
pub(super) struct External {
    /// Framebuffer of each slot's left and right layer (slot = colour index * depth slots +
    /// depth index).
    framebuffers: Vec<[Owned<vk::Framebuffer>; 2]>,
    /// Per-layer colour views of the images.
    _views: Vec<Owned<vk::ImageView>>,
    /// Per-layer views of the depth images (the renderer's own, or each external one's).
    _depth_views: Vec<Owned<vk::ImageView>>,
    /// Render pass leaving colour in `COLOR_ATTACHMENT_OPTIMAL` (in `TRANSFER_SRC_OPTIMAL`,
    /// for the blit, when the images are of another format).
    render_pass: Owned<vk::RenderPass>,
    /// The images' format.
    format: vk::Format,
    /// The colour image of each slot, 2 layers each; not owned.
    pub(super) images: Vec<vk::Image>,
    /// Number of external colour images.
    color_count: usize,
    /// Number of external depth images (0: the renderer's own depth image is used).
    depth_count: usize,
}

impl External {
    /// The slot of colour image `color` and depth image `depth` (ignored without external
    /// depth images).
    fn slot(&self, color: usize, depth: usize) -> usize {
        color * self.depth_count.max(1) + if self.depth_count == 0 { 0 } else { depth }
    }
}

/// Which external image a frame is drawn into, and how.
#[derive(Clone, Copy, Debug)]
pub(super) struct ExternalDraw {
    /// Slot: index into [`External::images`] and [`External::framebuffers`], or
    /// [`OWN_TARGET`].
    pub(super) image: usize,
    /// What is drawn behind the glass and the alpha left.
    pub(super) composition: Composition,
}

/// The [`ExternalDraw::image`] that means the renderer's own eye images.
pub(super) const OWN_TARGET: usize = usize::MAX;

impl External {
    /// The render pass the external framebuffers belong to.
    pub(super) fn render_pass(&self) -> vk::RenderPass {
        self.render_pass.raw()
    }

    /// Whether frames are drawn into the renderer's own eye image and blitted into the
    /// external one (its format is not the renderer's).
    pub(super) fn blitted(&self) -> bool {
        self.format != target::COLOR_FORMAT
    }

    /// How the images store their texels.
    pub(super) fn texels(&self) -> Texels {
        Texels::of(self.format).unwrap_or(Texels::OWN)
    }

    /// The left and right framebuffers of slot `slot`.
    pub(super) fn framebuffers(&self, slot: usize) -> [vk::Framebuffer; 2] {
        let [left, right] = &self.framebuffers[slot];
        [left.raw(), right.raw()]
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
    let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 2);
    let barrier = layout_barrier(image, range, (from, access), (to, access));
    // SAFETY: the caller's contract: `cmd` records outside a render pass and `image` is in
    // layout `from`.
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
    /// The depth format the renderer draws, which external depth images must have.
    pub const DEPTH_FORMAT: vk::Format = target::DEPTH_FORMAT;

    /// Lets later frames be drawn into `images`: 2-layer colour images of `format` and the
    /// renderer's [size](Renderer::size), one layer per eye, created with colour-attachment
    /// (and, for readbacks, transfer-source) usage, such as an OpenXR swapchain's. Replaces
    /// images attached before. Depth goes to the renderer's own depth image.
    ///
    /// `format` is the renderer's colour format, `R8G8B8A8_SRGB` (shaders write linear light
    /// and the image encodes it), drawn into directly; or `B8G8R8A8_SRGB`, `R8G8B8A8_UNORM` or
    /// `B8G8R8A8_UNORM`, into which each frame is blitted from the renderer's own eye image
    /// (then the images need transfer-destination usage too, and the device must blit into
    /// the format). Other formats are refused with a clear error.
    ///
    /// # Safety
    /// The images must live, on this renderer's device, until [`Renderer::detach_external`]
    /// or the renderer's drop.
    pub unsafe fn attach_external(
        &mut self,
        images: &[vk::Image],
        format: vk::Format,
    ) -> Result<()> {
        // SAFETY: the caller's contract is this function's, for no depth images.
        unsafe { self.attach_external_with_depth(images, format, &[]) }
    }

    /// Like [`Renderer::attach_external`], and the eye passes' depth is written into (and
    /// kept in) `depth_images`: 2-layer [`Renderer::DEPTH_FORMAT`] images of the renderer's
    /// size with depth-attachment usage, such as an OpenXR depth swapchain's, left in
    /// `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`. Empty `depth_images`: the renderer's own depth.
    ///
    /// # Safety
    /// As [`Renderer::attach_external`], for the depth images too.
    pub unsafe fn attach_external_with_depth(
        &mut self,
        images: &[vk::Image],
        format: vk::Format,
        depth_images: &[vk::Image],
    ) -> Result<()> {
        let blitted = format != target::COLOR_FORMAT;
        if blitted {
            convert::check(&self.ctx, format)?;
        }
        if images.is_empty() {
            return Err(RenderError::InvalidInput(
                "no external images to attach".into(),
            ));
        }
        self.detach_external()?;
        let ctx = &self.ctx;
        let render_pass = target::create_render_pass_storing_depth(
            ctx,
            target::COLOR_FORMAT,
            if blitted {
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL
            } else {
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
            },
            !depth_images.is_empty(),
        )?;
        let layer_view = |image: vk::Image,
                          format: vk::Format,
                          aspect: vk::ImageAspectFlags,
                          layer: u32|
         -> Result<Owned<vk::ImageView>> {
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: aspect,
                    base_mip_level: 0,
                    level_count: 1,
                    base_array_layer: layer,
                    layer_count: 1,
                });
            // SAFETY: the caller of `attach_external_with_depth` guarantees the image is a
            // live 2-layer image of this device; the view is owned right away.
            let view =
                unsafe { ctx.device.create_image_view(&info, None) }.vk("vkCreateImageView")?;
            Ok(Owned::new(ctx, view))
        };
        // Depth views: [depth image][layer], flattened. Everything made here is owned, so an
        // error part way frees it on the way out.
        let mut depth_views = Vec::new();
        if depth_images.is_empty() {
            for layer in 0..2 {
                depth_views.push(self.eye_target.depth.layer_view(ctx, layer)?);
            }
        } else {
            for &depth in depth_images {
                for layer in 0..2 {
                    depth_views.push(layer_view(
                        depth,
                        target::DEPTH_FORMAT,
                        vk::ImageAspectFlags::DEPTH,
                        layer,
                    )?);
                }
            }
        }
        let depth_slots = depth_images.len().max(1);
        let mut views = Vec::with_capacity(images.len() * 2);
        let mut slot_images = Vec::with_capacity(images.len() * depth_slots);
        let mut framebuffers = Vec::with_capacity(images.len() * depth_slots);
        for &image in images {
            // Drawn into: the image itself, or the renderer's own eye image to blit from.
            let (left, right) = if blitted {
                let own = &self.eye_target.color;
                (own.layer_view(ctx, 0)?, own.layer_view(ctx, 1)?)
            } else {
                (
                    layer_view(image, format, vk::ImageAspectFlags::COLOR, 0)?,
                    layer_view(image, format, vk::ImageAspectFlags::COLOR, 1)?,
                )
            };
            let color_views = [left.raw(), right.raw()];
            views.push(left);
            views.push(right);
            for depth in 0..depth_slots {
                let framebuffer = |layer: usize| {
                    pipeline::framebuffer(
                        ctx,
                        render_pass.raw(),
                        &[color_views[layer], depth_views[depth * 2 + layer].raw()],
                        self.extent,
                    )
                };
                framebuffers.push([framebuffer(0)?, framebuffer(1)?]);
                slot_images.push(image);
            }
        }
        self.external = Some(External {
            framebuffers,
            _views: views,
            _depth_views: depth_views,
            render_pass,
            format,
            images: slot_images,
            color_count: images.len(),
            depth_count: depth_images.len(),
        });
        Ok(())
    }

    /// Waits for every frame in flight and forgets the external images (they may then be
    /// destroyed). Frames still in flight are lost: call [`Renderer::flush`] first to keep them.
    pub fn detach_external(&mut self) -> Result<()> {
        if let Some(external) = self.external.take() {
            // SAFETY: waiting for idle has no preconditions. On a failed wait (a lost device)
            // the objects may still be destroyed.
            let waited = unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle");
            drop(external);
            waited?;
        }
        Ok(())
    }

    /// Number of attached external colour images (0 when none).
    pub fn external_count(&self) -> usize {
        self.external.as_ref().map_or(0, |e| e.color_count)
    }

    /// Number of attached external depth images (0 when none, or when the renderer's own
    /// depth image is used).
    pub fn external_depth_count(&self) -> usize {
        self.external.as_ref().map_or(0, |e| e.depth_count)
    }

    /// Like [`Renderer::submit`], drawing into attached external image `image` (its index in
    /// the slice given to [`Renderer::attach_external`]), composed for the display as
    /// `composition` says: with [`Composition::Opaque`] the real world (the scene's floor and
    /// background photos) is drawn behind the glass, for displays that show no real world of
    /// their own; [`Composition::AlphaBlend`] leaves alpha 0. A readback (`want.eyes`) copies
    /// the external image itself.
    ///
    /// The caller must have waited for the image to be free (OpenXR: xrWaitSwapchainImage); the
    /// rendering is submitted to the queue on return, as OpenXR requires before the image is
    /// released.
    pub fn submit_external(
        &mut self,
        image: usize,
        params: &FrameParams,
        want: Want,
        composition: Composition,
    ) -> Result<Option<FrameResult>> {
        self.submit_external_with_depth(image, None, params, want, composition)
    }

    /// Like [`Renderer::submit_external`], writing depth into attached external depth image
    /// `depth` (its index in the depth slice given to
    /// [`Renderer::attach_external_with_depth`]); needed exactly when depth images are
    /// attached.
    pub fn submit_external_with_depth(
        &mut self,
        image: usize,
        depth: Option<usize>,
        params: &FrameParams,
        want: Want,
        composition: Composition,
    ) -> Result<Option<FrameResult>> {
        let count = self.external_count();
        if image >= count {
            return Err(RenderError::InvalidInput(format!(
                "external image {image} does not exist ({count} attached)"
            )));
        }
        let depth_count = self.external_depth_count();
        let depth = match (depth, depth_count) {
            (None, 0) => 0,
            (Some(d), n) if d < n => d,
            (d, n) => {
                return Err(RenderError::InvalidInput(format!(
                    "external depth image {d:?} with {n} depth images attached"
                )));
            }
        };
        let slot = self.external.as_ref().map_or(0, |e| e.slot(image, depth));
        self.submit_to(
            params,
            want,
            Some(ExternalDraw {
                image: slot,
                composition,
            }),
        )
    }
}
