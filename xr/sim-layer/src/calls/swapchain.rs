//! Swapchain calls, for reading back what the app submits (`VITREOUS_SIM_IMAGES`,
//! [`crate::images`]): in a session whose images the layer reads, each swapchain is made with
//! transfer-source usage too, its Vulkan images and acquired indices are kept, and the image
//! the app releases is copied before the runtime gets it. Elsewhere the calls pass straight on.

use std::collections::VecDeque;
use std::sync::Arc;

use ash::vk::Handle as _;
use openxr::sys::{self, Handle};

use crate::faults;
use crate::guard::{guard, report};
use crate::images::{SharedImages, TexelLayout};
use crate::next::NextTable;
use crate::registry::{SwapchainState, registry};

/// The next layer's functions for `session` and, when the layer reads its images, its record.
fn session_of(session: u64) -> Option<(Arc<NextTable>, Option<SharedImages>)> {
    let reg = registry();
    let (s, i) = reg.session(session)?;
    Some((i.next.clone(), s.images.clone()))
}

/// The next layer's functions for `swapchain`'s session (the only instance's for a swapchain
/// the layer does not keep).
fn next_of(swapchain: u64) -> Option<Arc<NextTable>> {
    let reg = registry();
    match reg.swapchains.get(&swapchain) {
        Some(c) => reg.session(c.session).map(|(_, i)| i.next.clone()),
        None => {
            let mut all = reg.instances.values();
            match (all.next(), all.next()) {
                (Some(only), None) => Some(only.next.clone()),
                _ => None,
            }
        }
    }
}

/// What a call on `swapchain` gets instead of going on, when the fault schedule says so (its
/// session lost, or the call scheduled to fail).
fn refused(call: &'static str, swapchain: sys::Swapchain) -> Option<sys::Result> {
    faults::with(|f| {
        f.swapchain_session(swapchain.into_raw())
            .and_then(|session| f.refuse(call, session))
    })
    .flatten()
}

/// `xrWaitSwapchainImage`: answered `XR_TIMEOUT_EXPIRED` (without waiting) when the fault
/// schedule has a timeout due and the app gave a finite timeout, refused when the session is
/// lost or the call scheduled to fail, else passed on.
///
/// # Safety
/// As `xrWaitSwapchainImage`.
pub unsafe extern "system" fn wait_swapchain_image(
    swapchain: sys::Swapchain,
    info: *const sys::SwapchainImageWaitInfo,
) -> sys::Result {
    guard("xrWaitSwapchainImage", || {
        let Some(next) = next_of(swapchain.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structure, null or valid.
        let Some(wait) = (unsafe { info.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let infinite = wait.timeout == sys::Duration::INFINITE;
        if let Some(Some(r)) = faults::with(|f| f.wait_image(swapchain.into_raw(), infinite)) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        unsafe { (next.wait_swapchain_image)(swapchain, info) }
    })
}

/// `xrCreateSwapchain`: with transfer-source usage added where the layer reads the images.
///
/// # Safety
/// As `xrCreateSwapchain`.
pub unsafe extern "system" fn create_swapchain(
    session: sys::Session,
    info: *const sys::SwapchainCreateInfo,
    swapchain: *mut sys::Swapchain,
) -> sys::Result {
    guard("xrCreateSwapchain", || {
        let Some((next, images)) = session_of(session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structure, null or valid.
        let Some(app) = (unsafe { info.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let mut asked = *app;
        if images.is_some() {
            asked.usage_flags |= sys::SwapchainUsageFlags::TRANSFER_SRC;
        }
        // SAFETY: a copy of the app's valid create info; the app's output pointer.
        let r = unsafe { (next.create_swapchain)(session, &asked, swapchain) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success the new handle was written.
        let created = unsafe { *swapchain };
        faults::with(|f| f.swapchain_created(created.into_raw(), session.into_raw()));
        if images.is_none() {
            return r;
        }
        registry().swapchains.insert(
            created.into_raw(),
            SwapchainState {
                session: session.into_raw(),
                layout: TexelLayout::of(app.format),
                size: (app.width, app.height),
                layers: app.array_size,
                images: Vec::new(),
                acquired: VecDeque::new(),
                released: None,
            },
        );
        r
    })
}

/// `xrDestroySwapchain`: forgotten, then passed on.
///
/// # Safety
/// As `xrDestroySwapchain`.
pub unsafe extern "system" fn destroy_swapchain(swapchain: sys::Swapchain) -> sys::Result {
    guard("xrDestroySwapchain", || {
        let Some(next) = next_of(swapchain.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        registry().swapchains.remove(&swapchain.into_raw());
        // SAFETY: the next layer's function with the app's argument.
        unsafe { (next.destroy_swapchain)(swapchain) }
    })
}

/// `xrEnumerateSwapchainImages`: passed on; the Vulkan images kept.
///
/// # Safety
/// As `xrEnumerateSwapchainImages`.
pub unsafe extern "system" fn enumerate_swapchain_images(
    swapchain: sys::Swapchain,
    capacity: u32,
    count: *mut u32,
    images: *mut sys::SwapchainImageBaseHeader,
) -> sys::Result {
    guard("xrEnumerateSwapchainImages", || {
        let Some(next) = next_of(swapchain.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.enumerate_swapchain_images)(swapchain, capacity, count, images) };
        if r.into_raw() < 0 || capacity == 0 || images.is_null() || count.is_null() {
            return r;
        }
        // SAFETY: on success `count` holds how many of the app's array were written.
        let written = unsafe { *count }.min(capacity) as usize;
        // SAFETY: the app's array of `capacity` image structures, each starting with its type.
        let vulkan = unsafe { (*images).ty } == sys::StructureType::SWAPCHAIN_IMAGE_VULKAN_KHR;
        if !vulkan {
            return r;
        }
        let array = images as *const sys::SwapchainImageVulkanKHR;
        // SAFETY: an array of `written` `XrSwapchainImageVulkanKHR` just filled in.
        let handles: Vec<u64> = (0..written)
            .map(|i| unsafe { (*array.add(i)).image })
            .collect();
        if let Some(c) = registry().swapchains.get_mut(&swapchain.into_raw()) {
            c.images = handles;
        }
        r
    })
}

/// `xrAcquireSwapchainImage`: passed on; the index kept.
///
/// # Safety
/// As `xrAcquireSwapchainImage`.
pub unsafe extern "system" fn acquire_swapchain_image(
    swapchain: sys::Swapchain,
    info: *const sys::SwapchainImageAcquireInfo,
    index: *mut u32,
) -> sys::Result {
    guard("xrAcquireSwapchainImage", || {
        let Some(next) = next_of(swapchain.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(r) = refused("xrAcquireSwapchainImage", swapchain) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.acquire_swapchain_image)(swapchain, info, index) };
        if r.into_raw() >= 0
            && !index.is_null()
            && let Some(c) = registry().swapchains.get_mut(&swapchain.into_raw())
        {
            // SAFETY: on success the index was written.
            c.acquired.push_back(unsafe { *index });
        }
        r
    })
}

/// `xrReleaseSwapchainImage`: the image read back (the oldest acquired one, which the app
/// releases), then passed on.
///
/// # Safety
/// As `xrReleaseSwapchainImage`.
pub unsafe extern "system" fn release_swapchain_image(
    swapchain: sys::Swapchain,
    info: *const sys::SwapchainImageReleaseInfo,
) -> sys::Result {
    guard("xrReleaseSwapchainImage", || {
        let Some(next) = next_of(swapchain.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(r) = refused("xrReleaseSwapchainImage", swapchain) {
            return r;
        }
        let found = {
            let mut reg = registry();
            let record = reg
                .swapchains
                .get(&swapchain.into_raw())
                .and_then(|c| reg.sessions.get(&c.session))
                .and_then(|s| s.images.clone());
            reg.swapchains
                .get_mut(&swapchain.into_raw())
                .and_then(|c| {
                    let index = c.acquired.pop_front()?;
                    let image = *c.images.get(index as usize)?;
                    c.layout?;
                    Some((image, c.size, c.layers))
                })
                .zip(record)
        };
        if let Some(((image, (w, h), layers), record)) = found {
            let mut record = record.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(reader) = record.reader.as_mut() {
                // SAFETY: one of this swapchain's images of the app's device, made with
                // transfer-source usage (added at creation), which the app hands back in
                // COLOR_ATTACHMENT_OPTIMAL with its writes submitted to the session's queue,
                // from this thread.
                match unsafe { reader.read(ash::vk::Image::from_raw(image), w, h, layers) } {
                    Ok(texels) => {
                        if let Some(c) = registry().swapchains.get_mut(&swapchain.into_raw()) {
                            c.released = Some(Arc::new(texels));
                        }
                    }
                    Err(e) => {
                        report(format!(
                            "reading back a released image failed ({e}); no more are read"
                        ));
                        record.reader = None;
                    }
                }
            }
        }
        // SAFETY: the next layer's function with the app's arguments.
        unsafe { (next.release_swapchain_image)(swapchain, info) }
    })
}
