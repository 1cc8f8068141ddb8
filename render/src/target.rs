//! A 2-layer colour + depth target, one layer per eye, and the render pass that draws into one
//! layer at a time.

use ash::vk;

use crate::context::GpuContext;
use crate::error::Result;
use crate::memory::Image;
use crate::owned::Owned;
use crate::pipeline;

/// Colour format of eye images: 8-bit sRGB, the usual OpenXR swapchain format. Shaders write
/// linear light; the hardware encodes.
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Creates the render pass every eye pass uses: clear colour and depth, keep colour, left
/// for the readback copy.
pub fn create_render_pass(ctx: &GpuContext) -> Result<Owned<vk::RenderPass>> {
    create_render_pass_storing_depth(
        ctx,
        COLOR_FORMAT,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        false,
    )
}

/// Like [`create_render_pass`], for colour images of `color_format` left in `final_layout`
/// (an OpenXR swapchain image must be back in `COLOR_ATTACHMENT_OPTIMAL` when released); with
/// `store_depth` the depth attachment is stored (an OpenXR depth swapchain). Pipelines made
/// for [`create_render_pass`] work in it when `color_format` is [`COLOR_FORMAT`]: layouts and
/// load/store ops do not matter for render pass compatibility.
pub fn create_render_pass_storing_depth(
    ctx: &GpuContext,
    color_format: vk::Format,
    final_layout: vk::ImageLayout,
    store_depth: bool,
) -> Result<Owned<vk::RenderPass>> {
    pipeline::eye_render_pass(ctx, color_format, DEPTH_FORMAT, final_layout, store_depth)
}

/// Colour and depth images with one layer per eye, and a framebuffer per layer; all freed on
/// drop (framebuffers, then views, then images).
pub struct StereoTarget {
    /// Framebuffer of each eye's layer.
    framebuffers: Vec<Owned<vk::Framebuffer>>,
    /// Per-layer views (colour then depth for each eye).
    _views: Vec<Owned<vk::ImageView>>,
    /// Colour, 2 layers.
    pub color: Image,
    /// Depth, 2 layers.
    pub depth: Image,
}

impl StereoTarget {
    /// Creates a target of `extent` per eye for `render_pass`.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        render_pass: vk::RenderPass,
        extent: vk::Extent2D,
    ) -> Result<StereoTarget> {
        StereoTarget::with_usage(ctx, name, render_pass, extent, vk::ImageUsageFlags::empty())
    }

    /// Like [`StereoTarget::new`], both images also usable as `usage` says (`SAMPLED`: read
    /// by shaders afterwards).
    pub fn with_usage(
        ctx: &GpuContext,
        name: &str,
        render_pass: vk::RenderPass,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> Result<StereoTarget> {
        let color = Image::new(
            ctx,
            name,
            COLOR_FORMAT,
            extent,
            2,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC | usage,
        )?;
        let depth = Image::new(
            ctx,
            name,
            DEPTH_FORMAT,
            extent,
            2,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | usage,
        )?;
        let mut views = Vec::with_capacity(4);
        let mut framebuffers = Vec::with_capacity(2);
        for eye in 0..2 {
            let color_view = color.layer_view(ctx, eye)?;
            let depth_view = depth.layer_view(ctx, eye)?;
            framebuffers.push(pipeline::framebuffer(
                ctx,
                render_pass,
                &[color_view.raw(), depth_view.raw()],
                extent,
            )?);
            views.push(color_view);
            views.push(depth_view);
        }
        Ok(StereoTarget {
            framebuffers,
            _views: views,
            color,
            depth,
        })
    }

    /// The framebuffer of each eye's layer.
    pub fn framebuffers(&self) -> [vk::Framebuffer; 2] {
        [self.framebuffers[0].raw(), self.framebuffers[1].raw()]
    }
}
