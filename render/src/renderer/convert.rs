//! Swapchain images of another 8-bit colour format than the one the renderer draws.
//!
//! A runtime may offer `B8G8R8A8_SRGB` (blue first) or only UNORM formats rather than the
//! renderer's `R8G8B8A8_SRGB`. Pipelines are made for one colour format, so such a frame is
//! drawn into the renderer's own eye image as always and then blitted into the swapchain
//! image: the blit reads the sRGB texels as linear light and writes them as the destination
//! format stores them, re-encoded for an `_SRGB` format and as linear values for a UNORM one
//! (OpenXR reads every format that is not sRGB as linear light). A readback of such a frame
//! copies the swapchain image itself and is turned back into RGBA sRGB bytes here, so it shows
//! what the runtime was handed.

use ash::vk;

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::memory::{layout_barrier, subresource_range};
use crate::target;

/// How an 8-bit colour format stores a texel's four bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Texels {
    /// Blue first (`B8G8R8A8_*`).
    pub bgra: bool,
    /// sRGB-encoded colour (`*_SRGB`); otherwise linear values (alpha is linear either way).
    pub srgb: bool,
}

impl Texels {
    /// The renderer's own eye images' texels.
    pub const OWN: Texels = Texels {
        bgra: false,
        srgb: true,
    };

    /// The texels of `format`, one of the four 8-bit RGBA/BGRA colour formats; `None` for any
    /// other.
    pub fn of(format: vk::Format) -> Option<Texels> {
        let (bgra, srgb) = match format {
            vk::Format::R8G8B8A8_SRGB => (false, true),
            vk::Format::B8G8R8A8_SRGB => (true, true),
            vk::Format::R8G8B8A8_UNORM => (false, false),
            vk::Format::B8G8R8A8_UNORM => (true, false),
            _ => return None,
        };
        Some(Texels { bgra, srgb })
    }

    /// Rewrites `bytes`, texels stored this way, as RGBA with sRGB-encoded colour (the
    /// renderer's own images' bytes). A linear value keeps its 8 bits: dark values, which
    /// sRGB spreads over more codes, come back coarser than the renderer drew them.
    pub fn to_own(self, bytes: &mut [u8]) {
        if self == Texels::OWN {
            return;
        }
        let encode: [u8; 256] = std::array::from_fn(|v| {
            if self.srgb {
                v as u8
            } else {
                vitreous_optics::srgb::from_linear(v as f32 / 255.0)
            }
        });
        for texel in bytes.chunks_exact_mut(4) {
            if self.bgra {
                texel.swap(0, 2);
            }
            for c in &mut texel[..3] {
                *c = encode[usize::from(*c)];
            }
        }
    }
}

/// Checks that frames can be blitted from the renderer's eye images into images of `format`:
/// a known 8-bit colour format the device blits into, from the renderer's format.
pub(super) fn check(ctx: &GpuContext, format: vk::Format) -> Result<()> {
    if Texels::of(format).is_none() {
        return Err(RenderError::InvalidInput(format!(
            "external images of format {format:?}: the renderer draws into 8-bit RGBA or BGRA \
             images only (sRGB or UNORM)"
        )));
    }
    let features = |f: vk::Format| {
        // SAFETY: the physical device is this context's.
        unsafe {
            ctx.instance
                .get_physical_device_format_properties(ctx.physical, f)
        }
        .optimal_tiling_features
    };
    let from = features(target::COLOR_FORMAT).contains(vk::FormatFeatureFlags::BLIT_SRC);
    let to = features(format).contains(vk::FormatFeatureFlags::BLIT_DST);
    if !(from && to) {
        return Err(RenderError::InvalidInput(format!(
            "external images of format {format:?}: the device cannot blit {:?} into them \
             (blit source {from}, destination {to})",
            target::COLOR_FORMAT
        )));
    }
    Ok(())
}

/// Records the copy of both layers of `from` (the renderer's eye image, in
/// TRANSFER_SRC_OPTIMAL, written by the eye passes before) into `to` (an external image of
/// another format, its contents discarded), converting each texel, and leaves `to` in
/// COLOR_ATTACHMENT_OPTIMAL, as an OpenXR swapchain image is released.
///
/// # Safety
/// `cmd` must be recording outside any render pass; `from` must be in TRANSFER_SRC_OPTIMAL
/// when the blit executes, after a dependency making the eye passes' writes visible to
/// transfer reads (the eye render pass's own); `to` must have been created with
/// transfer-destination usage in a format [`check`] accepted, with 2 layers of `extent`; both
/// must outlive the execution.
pub(super) unsafe fn record_blit(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    from: vk::Image,
    to: vk::Image,
    extent: vk::Extent2D,
) {
    let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 2);
    let layers = vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 2,
    };
    let corner = vk::Offset3D {
        x: extent.width as i32,
        y: extent.height as i32,
        z: 1,
    };
    let region = vk::ImageBlit {
        src_subresource: layers,
        src_offsets: [vk::Offset3D::default(), corner],
        dst_subresource: layers,
        dst_offsets: [vk::Offset3D::default(), corner],
    };
    let to_destination = layout_barrier(
        to,
        range,
        (vk::ImageLayout::UNDEFINED, vk::AccessFlags::empty()),
        (
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            vk::AccessFlags::TRANSFER_WRITE,
        ),
    );
    let to_attachment = layout_barrier(
        to,
        range,
        (
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            vk::AccessFlags::TRANSFER_WRITE,
        ),
        (
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::AccessFlags::COLOR_ATTACHMENT_READ
                | vk::AccessFlags::COLOR_ATTACHMENT_WRITE
                | vk::AccessFlags::TRANSFER_READ,
        ),
    );
    // SAFETY: the caller's contract: recording outside a render pass, `from` readable as a
    // transfer source, `to` a 2-layer image of `extent` with transfer-destination usage. The
    // first barrier waits for any earlier frame's use of `to` (colour output, the readback's
    // transfer) before discarding it; the second makes the blit's writes visible to whatever
    // reads or writes it next.
    unsafe {
        d.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_destination],
        );
        d.cmd_blit_image(
            cmd,
            from,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            to,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
            vk::Filter::NEAREST,
        );
        d.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_attachment],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_back_to_rgba_srgb() {
        // One texel as each format stores the sRGB colour (200, 100, 10) with alpha 128.
        let linear = |v: u8| (vitreous_optics::srgb::to_linear(v) * 255.0 + 0.5) as u8;
        let cases = [
            (vk::Format::R8G8B8A8_SRGB, [200, 100, 10, 128]),
            (vk::Format::B8G8R8A8_SRGB, [10, 100, 200, 128]),
            (
                vk::Format::R8G8B8A8_UNORM,
                [linear(200), linear(100), linear(10), 128],
            ),
            (
                vk::Format::B8G8R8A8_UNORM,
                [linear(10), linear(100), linear(200), 128],
            ),
        ];
        for (format, stored) in cases {
            let mut bytes = stored.to_vec();
            Texels::of(format).unwrap().to_own(&mut bytes);
            assert_eq!(bytes[3], 128, "{format:?}: alpha kept");
            // Exact for sRGB; a linear byte comes back within a few codes of its colour (10
            // in sRGB is 0.003 linear: byte 1, which encodes as 13).
            let tolerance = if Texels::of(format).unwrap().srgb {
                0
            } else {
                3
            };
            for (got, want) in bytes[..3].iter().zip([200u8, 100, 10]) {
                assert!(got.abs_diff(want) <= tolerance, "{format:?}: {bytes:?}");
            }
        }
        assert_eq!(Texels::of(vk::Format::R16G16B16A16_SFLOAT), None);
    }
}
