//! A 2-layer colour + depth target, one layer per eye, and the render pass that draws into one
//! layer at a time.

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Result, VkContext};
use crate::memory::Image;

/// Colour format of eye images: 8-bit sRGB, the usual OpenXR swapchain format. Shaders write
/// linear light; the hardware encodes.
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Creates the render pass every eye pass uses: clear colour and depth, keep colour.
pub fn create_render_pass(ctx: &GpuContext) -> Result<vk::RenderPass> {
    create_render_pass_for(ctx, COLOR_FORMAT, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
}

/// Like [`create_render_pass`], for colour images of `color_format` left in `final_layout`
/// (an OpenXR swapchain image must be back in `COLOR_ATTACHMENT_OPTIMAL` when released).
/// Pipelines made for [`create_render_pass`] work in it when `color_format` is
/// [`COLOR_FORMAT`]: layouts do not matter for render pass compatibility.
pub fn create_render_pass_for(
    ctx: &GpuContext,
    color_format: vk::Format,
    final_layout: vk::ImageLayout,
) -> Result<vk::RenderPass> {
    create_render_pass_storing_depth(ctx, color_format, final_layout, false)
}

/// Like [`create_render_pass_for`]; with `store_depth` the depth attachment is stored (for a
/// depth image someone else reads afterwards: an OpenXR depth swapchain). Load/store ops do
/// not affect render-pass compatibility, so the same pipelines draw in both.
pub fn create_render_pass_storing_depth(
    ctx: &GpuContext,
    color_format: vk::Format,
    final_layout: vk::ImageLayout,
    store_depth: bool,
) -> Result<vk::RenderPass> {
    let attachments = [
        vk::AttachmentDescription::default()
            .format(color_format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(final_layout),
        vk::AttachmentDescription::default()
            .format(DEPTH_FORMAT)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(if store_depth {
                vk::AttachmentStoreOp::STORE
            } else {
                vk::AttachmentStoreOp::DONT_CARE
            })
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
    ];
    let color_ref = [vk::AttachmentReference {
        attachment: 0,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    }];
    let depth_ref = vk::AttachmentReference {
        attachment: 1,
        layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    };
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color_ref)
        .depth_stencil_attachment(&depth_ref)];
    let attachment_stages = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
        | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
        | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let attachment_writes =
        vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
    let dependencies = [
        // The previous frame's use of the same images (attachment writes, the readback copy)
        // must finish before this pass writes them again.
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(attachment_stages | vk::PipelineStageFlags::TRANSFER)
            .src_access_mask(attachment_writes)
            .dst_stage_mask(attachment_stages)
            .dst_access_mask(attachment_writes | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        // The colour written here is read by the readback copy.
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
    ];
    let info = vk::RenderPassCreateInfo::default()
        .attachments(&attachments)
        .subpasses(&subpasses)
        .dependencies(&dependencies);
    unsafe { ctx.device.create_render_pass(&info, None) }.vk("vkCreateRenderPass")
}

/// Colour and depth images with one layer per eye, and a framebuffer per layer.
pub struct StereoTarget {
    /// Colour, 2 layers.
    pub color: Image,
    /// Depth, 2 layers.
    pub depth: Image,
    /// Per-layer views (colour then depth for each eye), destroyed with the target.
    views: Vec<vk::ImageView>,
    /// Framebuffer of each eye's layer.
    pub framebuffers: [vk::Framebuffer; 2],
}

impl StereoTarget {
    /// Creates a target of `extent` per eye for `render_pass`.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        render_pass: vk::RenderPass,
        extent: vk::Extent2D,
    ) -> Result<StereoTarget> {
        let mut color = Image::new(
            ctx,
            name,
            COLOR_FORMAT,
            extent,
            2,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
        )?;
        let depth = Image::new(
            ctx,
            name,
            DEPTH_FORMAT,
            extent,
            2,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        );
        let depth = match depth {
            Ok(d) => d,
            Err(e) => {
                unsafe { color.destroy(ctx) };
                return Err(e);
            }
        };
        let mut target = StereoTarget {
            color,
            depth,
            views: Vec::new(),
            framebuffers: [vk::Framebuffer::null(); 2],
        };
        let built = (|| {
            for eye in 0..2 {
                let color_view = target.color.layer_view(ctx, eye)?;
                target.views.push(color_view);
                let depth_view = target.depth.layer_view(ctx, eye)?;
                target.views.push(depth_view);
                let attachments = [color_view, depth_view];
                let info = vk::FramebufferCreateInfo::default()
                    .render_pass(render_pass)
                    .attachments(&attachments)
                    .width(extent.width)
                    .height(extent.height)
                    .layers(1);
                target.framebuffers[eye as usize] =
                    unsafe { ctx.device.create_framebuffer(&info, None) }
                        .vk("vkCreateFramebuffer")?;
            }
            Ok(())
        })();
        match built {
            Ok(()) => Ok(target),
            Err(e) => {
                unsafe { target.destroy(ctx) };
                Err(e)
            }
        }
    }

    /// Frees the target.
    ///
    /// # Safety
    /// The GPU must no longer use it.
    pub unsafe fn destroy(&mut self, ctx: &GpuContext) {
        unsafe {
            for fb in self.framebuffers {
                if fb != vk::Framebuffer::null() {
                    ctx.device.destroy_framebuffer(fb, None);
                }
            }
            for view in self.views.drain(..) {
                ctx.device.destroy_image_view(view, None);
            }
            self.color.destroy(ctx);
            self.depth.destroy(ctx);
        }
    }
}
