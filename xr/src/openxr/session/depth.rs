//! Depth submission (XR_KHR_composition_layer_depth): each projection view chains the depth
//! of its eye's layer of the depth swapchain. The `openxr` crate's safe API cannot chain it, so
//! the views are rebuilt from their raw structures.

use openxr as xr;

use super::super::DepthOptions;

/// The depth info of one eye's layer: image `layer` of `swapchain` over `rect`, depth 0..1
/// from `near_m` to `far_m` (a standard, not reversed, projection).
pub(super) fn depth_info(
    swapchain: xr::sys::Swapchain,
    layer: u32,
    rect: xr::Rect2Di,
    depth: &DepthOptions,
) -> xr::sys::CompositionLayerDepthInfoKHR {
    xr::sys::CompositionLayerDepthInfoKHR {
        ty: xr::sys::CompositionLayerDepthInfoKHR::TYPE,
        next: std::ptr::null(),
        sub_image: xr::sys::SwapchainSubImage {
            swapchain,
            image_rect: rect,
            image_array_index: layer,
        },
        min_depth: 0.0,
        max_depth: 1.0,
        near_z: depth.near_m,
        far_z: depth.far_m,
    }
}

/// Chains each view's depth info into its `next` (keeping whatever was chained before behind
/// it).
///
/// # Safety
/// `infos` must outlive every use of `views` (xrEndFrame), and must not move.
pub(super) unsafe fn chain_depth(
    views: &mut [xr::sys::CompositionLayerProjectionView],
    infos: &mut [xr::sys::CompositionLayerDepthInfoKHR],
) {
    for (view, info) in views.iter_mut().zip(infos.iter_mut()) {
        info.next = view.next;
        view.next = info as *const xr::sys::CompositionLayerDepthInfoKHR as *const _;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk;

    #[test]
    fn each_view_chains_its_depth_info() {
        let rect = xr::Rect2Di {
            offset: xr::Offset2Di { x: 0, y: 0 },
            extent: xr::Extent2Di {
                width: 320,
                height: 240,
            },
        };
        let options = DepthOptions {
            format: vk::Format::D32_SFLOAT,
            near_m: 0.02,
            far_m: 100.0,
        };
        let chain = <xr::sys::Swapchain as xr::sys::Handle>::from_raw(7);
        let mut infos: Vec<_> = (0..2)
            .map(|l| depth_info(chain, l, rect, &options))
            .collect();
        let view = *xr::CompositionLayerProjectionView::<xr::Vulkan>::new().as_raw();
        let mut views = [view, view];
        // SAFETY: `infos` lives, unmoved, until the end of this test, past every use of `views`.
        unsafe { chain_depth(&mut views, &mut infos) };
        for (eye, v) in views.iter().enumerate() {
            // SAFETY: `chain_depth` set `next` to an element of `infos`, still alive here.
            let info = unsafe { &*(v.next as *const xr::sys::CompositionLayerDepthInfoKHR) };
            assert_eq!(
                info.ty,
                xr::sys::StructureType::COMPOSITION_LAYER_DEPTH_INFO_KHR
            );
            assert!(info.next.is_null());
            assert_eq!(info.sub_image.swapchain, chain);
            assert_eq!(info.sub_image.image_array_index, eye as u32);
            assert_eq!(info.sub_image.image_rect.extent.width, 320);
            assert_eq!((info.min_depth, info.max_depth), (0.0, 1.0));
            assert_eq!((info.near_z, info.far_z), (0.02, 100.0));
        }
    }
}
