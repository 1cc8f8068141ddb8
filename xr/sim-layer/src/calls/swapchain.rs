//! Swapchain calls, for reading back what the app submits (`VITREOUS_SIM_IMAGES`,
//! [`crate::images`]): in a session whose images the layer reads, each swapchain is made with
//! transfer-source usage too, its Vulkan images and acquired indices are kept, and the image
//! the app releases is copied before the runtime gets it. With `VITREOUS_SIM_FORMATS`, the
//! formats are the simulated headset's: `xrEnumerateSwapchainFormats` lists only those of its
//! formats the runtime offers, and `xrCreateSwapchain` refuses the colour formats the variable
//! can name but does not list. Elsewhere the calls pass straight on.

use std::collections::VecDeque;
use std::sync::Arc;

use ash::vk::Handle as _;
use openxr::sys::{self, Handle};

use crate::config::{Config, FORMAT_NAMES};
use crate::faults;
use crate::guard::{guard, report};
use crate::images::{SharedImages, TexelLayout};
use crate::next::NextTable;
use crate::registry::{SwapchainState, registry};
use crate::two_call;

/// The next layer's functions for `session`, its record when the layer reads its images, and
/// its instance's configuration.
fn session_of(session: u64) -> Option<(Arc<NextTable>, Option<SharedImages>, Arc<Config>)> {
    let reg = registry();
    let (s, i) = reg.session(session)?;
    Some((i.next.clone(), s.images.clone(), i.config.clone()))
}

/// The formats the app is offered: those of `wanted` (the headset's 8-bit colour formats, in
/// its order of preference) that the runtime offers, then the runtime's formats the variable
/// cannot name (depth, float colour) in its order; its other 8-bit colour formats are left out.
pub fn offered(runtime: &[i64], wanted: &[i64]) -> Vec<i64> {
    let nameable = |f: &i64| FORMAT_NAMES.iter().any(|&(_, n)| n == *f);
    wanted
        .iter()
        .copied()
        .filter(|f| runtime.contains(f))
        .chain(runtime.iter().copied().filter(|f| !nameable(f)))
        .collect()
}

/// Whether a headset offering only `listed` refuses a swapchain of `format`: one of the colour
/// formats `VITREOUS_SIM_FORMATS` can name that it does not list. Every other format (depth,
/// and any the variable cannot name) is left to the runtime.
pub fn refuses(format: i64, listed: &[i64]) -> bool {
    FORMAT_NAMES.iter().any(|&(_, f)| f == format) && !listed.contains(&format)
}

/// `xrEnumerateSwapchainFormats`: with `VITREOUS_SIM_FORMATS`, the listed formats the runtime
/// offers, in the listed order, then its formats the variable cannot name ([`offered`]);
/// unset, the runtime's.
///
/// # Safety
/// As `xrEnumerateSwapchainFormats`.
pub unsafe extern "system" fn enumerate_swapchain_formats(
    session: sys::Session,
    capacity: u32,
    count: *mut u32,
    formats: *mut i64,
) -> sys::Result {
    guard("xrEnumerateSwapchainFormats", || {
        let Some((next, _, config)) = session_of(session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let Some(wanted) = &config.formats else {
            // SAFETY: the next layer's function with the app's arguments.
            return unsafe {
                (next.enumerate_swapchain_formats)(session, capacity, count, formats)
            };
        };
        let runtime = match next.runtime_swapchain_formats(session) {
            Ok(f) => f,
            Err(r) => return r,
        };
        let list = offered(&runtime, wanted);
        // SAFETY: the app's pointers, valid as the call defines them.
        unsafe { two_call::answer_raw(&list, capacity, count, formats) }
    })
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

/// `xrCreateSwapchain`: `XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED` for a colour format
/// `VITREOUS_SIM_FORMATS` can name but does not list (when it is set), else passed on with
/// transfer-source usage added where the layer reads the images.
///
/// # Safety
/// As `xrCreateSwapchain`.
pub unsafe extern "system" fn create_swapchain(
    session: sys::Session,
    info: *const sys::SwapchainCreateInfo,
    swapchain: *mut sys::Swapchain,
) -> sys::Result {
    guard("xrCreateSwapchain", || {
        let Some((next, images, config)) = session_of(session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structure, null or valid.
        let Some(app) = (unsafe { info.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if let Some(listed) = &config.formats
            && refuses(app.format, listed)
        {
            return sys::Result::ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `VK_FORMAT_R8G8B8A8_UNORM`.
    const RGBA_UNORM: i64 = 37;
    /// `VK_FORMAT_R8G8B8A8_SRGB`.
    const RGBA_SRGB: i64 = 43;
    /// `VK_FORMAT_B8G8R8A8_UNORM`.
    const BGRA_UNORM: i64 = 44;
    /// `VK_FORMAT_B8G8R8A8_SRGB`.
    const BGRA_SRGB: i64 = 50;
    /// `VK_FORMAT_D32_SFLOAT`.
    const D32: i64 = 126;
    /// `VK_FORMAT_R16G16B16A16_SFLOAT`.
    const RGBA16F: i64 = 97;

    #[test]
    fn the_headsets_formats_the_runtime_offers_are_listed_in_the_headsets_order() {
        let runtime = [RGBA_SRGB, BGRA_SRGB, RGBA_UNORM, BGRA_UNORM, RGBA16F, D32];
        // The runtime's depth and float formats stay, after the listed colour formats.
        assert_eq!(
            offered(&runtime, &[BGRA_SRGB, BGRA_UNORM]),
            vec![BGRA_SRGB, BGRA_UNORM, RGBA16F, D32]
        );
        assert_eq!(
            offered(&runtime, &[BGRA_UNORM, RGBA_SRGB]),
            vec![BGRA_UNORM, RGBA_SRGB, RGBA16F, D32],
            "the headset's order, not the runtime's"
        );
        // A listed format the runtime does not offer is left out; none left: no 8-bit colour.
        assert_eq!(
            offered(&[RGBA_SRGB, D32], &[BGRA_SRGB, RGBA_SRGB]),
            vec![RGBA_SRGB, D32]
        );
        assert_eq!(offered(&[RGBA_SRGB, D32], &[BGRA_UNORM]), vec![D32]);
        assert!(offered(&[], &[BGRA_SRGB]).is_empty());
    }

    #[test]
    fn only_unlisted_eight_bit_colour_formats_are_refused() {
        let listed = [BGRA_SRGB, BGRA_UNORM];
        assert!(!refuses(BGRA_SRGB, &listed));
        assert!(!refuses(BGRA_UNORM, &listed));
        assert!(refuses(RGBA_SRGB, &listed));
        assert!(refuses(RGBA_UNORM, &listed));
        // Depth and formats the variable cannot name are the runtime's to decide.
        assert!(!refuses(D32, &listed));
        assert!(!refuses(RGBA16F, &listed));
        assert!(!refuses(0, &listed));
    }

    #[test]
    fn the_answer_follows_the_two_call_idiom() {
        let list = offered(&[RGBA_SRGB, BGRA_SRGB], &[BGRA_SRGB, RGBA_SRGB]);
        let mut n = 0u32;
        // SAFETY: `n` is writable; a null array with capacity 0 asks for the count.
        let r = unsafe { two_call::answer_raw(&list, 0, &mut n, std::ptr::null_mut()) };
        assert_eq!((r, n), (sys::Result::SUCCESS, 2));
        let mut out = [0i64; 1];
        // SAFETY: `out` holds one writable element.
        let r = unsafe { two_call::answer_raw(&list, 1, &mut n, out.as_mut_ptr()) };
        assert_eq!((r, n), (sys::Result::ERROR_SIZE_INSUFFICIENT, 2));
        let mut out = [0i64; 3];
        // SAFETY: `out` holds three writable elements.
        let r = unsafe { two_call::answer_raw(&list, 3, &mut n, out.as_mut_ptr()) };
        assert_eq!(
            (r, n, out),
            (sys::Result::SUCCESS, 2, [BGRA_SRGB, RGBA_SRGB, 0])
        );
    }
}
