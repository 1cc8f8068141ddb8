//! Session-level calls: creating and destroying a session (its images shared with the wearer
//! view), and ending a frame: the submitted-frames record, the measurement of the submitted
//! images, Magic Leap 2's frame controls and blend-mode substitution. The spaces a session
//! creates are in [`spaces`](super::spaces).

use openxr::sys::{self, Handle};

use super::{SessionContext, chain};
use crate::blend;
use crate::config::Config;
use crate::faults;
use crate::faults::schedule::BadTime;
use crate::guard::{guard, report};
use crate::images::{AlphaLog, Reader, SessionImages, SharedImages, ViewImage, VulkanBinding};
use crate::registry::{SessionState, registry};
use crate::submitted::{FrameInfo, LayerInfo};
use std::sync::{Arc, Mutex};

/// `xrCreateSession`: passed on; the layer then makes its VIEW space in the new session.
///
/// # Safety
/// As `xrCreateSession`.
pub unsafe extern "system" fn create_session(
    instance: sys::Instance,
    info: *const sys::SessionCreateInfo,
    session: *mut sys::Session,
) -> sys::Result {
    guard("xrCreateSession", || {
        let Some(next) = super::instance_next(instance) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.create_session)(instance, info, session) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success `info` was valid and the new session was written.
        let (system, created, chain) = unsafe { ((*info).system_id, *session, (*info).next) };
        let config = registry()
            .instances
            .get(&instance.into_raw())
            .map(|i| i.config.clone());
        // SAFETY: the app's valid create info chain.
        let images = config.and_then(|c| unsafe { session_images(&c, chain) });
        let view_info = sys::ReferenceSpaceCreateInfo {
            ty: sys::ReferenceSpaceCreateInfo::TYPE,
            next: std::ptr::null(),
            reference_space_type: sys::ReferenceSpaceType::VIEW,
            pose_in_reference_space: sys::Posef::IDENTITY,
        };
        let mut view_space = sys::Space::NULL;
        // SAFETY: the new session is live; the create info and output are valid.
        let rv = unsafe { (next.create_reference_space)(created, &view_info, &mut view_space) };
        if rv.into_raw() < 0 {
            report(format!("creating the head (VIEW) space failed: {rv:?}"));
            // SAFETY: undoing the creation above; the session is not used afterwards.
            unsafe { (next.destroy_session)(created) };
            return sys::Result::ERROR_RUNTIME_FAILURE;
        }
        let mut reg = registry();
        let serial = reg.sessions_made;
        reg.sessions_made += 1;
        reg.sessions.insert(
            created.into_raw(),
            SessionState {
                instance: instance.into_raw(),
                system,
                view_space,
                first_display_ns: None,
                latest_display_ns: None,
                frames_ended: 0,
                serial,
                syncs_ns: (None, None),
                runtime_blend: None,
                attached: false,
                images,
            },
        );
        drop(reg);
        faults::with(|f| f.session_created(created.into_raw(), instance.into_raw()));
        r
    })
}

/// The record of what the app submits, when `config` asks for one (`VITREOUS_SIM_IMAGES`):
/// its `alpha.csv`, and a reader on the Vulkan device of the session's graphics binding (in
/// `chain`), if it has one.
///
/// # Safety
/// `chain` must be the app's valid `XrSessionCreateInfo` chain of a session just created.
unsafe fn session_images(config: &Config, chain: *const std::ffi::c_void) -> Option<SharedImages> {
    let dir = config.images.clone()?;
    let log = match AlphaLog::create(&dir) {
        Ok(log) => log,
        Err(e) => {
            report(format!(
                "{}: cannot write {}/alpha.csv: {e}",
                crate::config::IMAGES_VAR,
                dir.display()
            ));
            return None;
        }
    };
    // SAFETY: the caller's guarantee.
    let reader = match unsafe { vulkan_binding(chain) } {
        None => {
            report("the session has no Vulkan graphics binding: its images are not read back");
            None
        }
        // SAFETY: the binding the runtime just accepted for a live session: the app's live
        // Vulkan instance, physical device and device with that queue.
        Some(binding) => match unsafe { Reader::new(&binding) } {
            Ok(reader) => Some(reader),
            Err(e) => {
                report(format!("reading back the session's images: {e}"));
                None
            }
        },
    };
    Some(Arc::new(Mutex::new(SessionImages {
        reader,
        log,
        dir,
        last: Vec::new(),
        last_blend: sys::EnvironmentBlendMode::OPAQUE,
    })))
}

/// `xrDestroySession`: the layer's head space is destroyed, then the session.
///
/// # Safety
/// As `xrDestroySession`.
pub unsafe extern "system" fn destroy_session(session: sys::Session) -> sys::Result {
    guard("xrDestroySession", || {
        let (ctx, state) = {
            let mut reg = registry();
            let Some(ctx) = SessionContext::of(&reg, session.into_raw()) else {
                return sys::Result::ERROR_HANDLE_INVALID;
            };
            (ctx, reg.remove_session(session.into_raw()))
        };
        faults::with(|f| f.session_destroyed(session.into_raw()));
        if let Some(state) = state {
            // SAFETY: the layer's own space of this live session.
            unsafe { (ctx.next.destroy_space)(state.view_space) };
            if let Some(images) = state.images {
                finish_images(&images, &ctx.config);
            }
        }
        // SAFETY: the next layer's function for its live session.
        unsafe { (ctx.next.destroy_session)(session) }
    })
}

/// The Vulkan graphics binding in a session create info's `next` chain, if there is one.
///
/// # Safety
/// `first` must be null or a valid chain of OpenXR structures.
unsafe fn vulkan_binding(first: *const std::ffi::c_void) -> Option<VulkanBinding> {
    // SAFETY: the caller's guarantee; the chain is only read.
    for p in unsafe { chain(first as *mut _) } {
        // SAFETY: every structure of a valid chain starts with its type.
        if unsafe { (*p).ty } == sys::StructureType::GRAPHICS_BINDING_VULKAN_KHR {
            // SAFETY: a structure of that type is an `XrGraphicsBindingVulkanKHR`.
            let b = unsafe { &*(p as *const sys::GraphicsBindingVulkanKHR) };
            return Some(VulkanBinding {
                instance: b.instance as u64,
                physical_device: b.physical_device as u64,
                device: b.device as u64,
                queue_family: b.queue_family_index,
                queue_index: b.queue_index,
            });
        }
    }
    None
}

/// At the end of a session whose images the layer read: the last frame as the wearer saw it
/// (with `VITREOUS_SIM_WORLD`), and the reader's Vulkan objects freed while the app's device
/// still lives.
fn finish_images(images: &Mutex<SessionImages>, config: &Config) {
    let mut record = images.lock().unwrap_or_else(|e| e.into_inner());
    // Freed here, while the app's device lives (the app destroys its session first).
    drop(record.reader.take());
    if let Some(world) = &config.world {
        if record.last.is_empty() {
            report("no submitted view was read back: no wearer's view written");
        } else if let Err(e) = crate::wearer::write_wearer_views(
            &record.dir,
            world,
            &record.last,
            record.last_blend,
            &config.panel,
            config.registration_deg,
        ) {
            report(format!("the wearer's view: {e}"));
        }
    }
}

/// `xrEndFrame`: the frame is recorded to the submitted-frames CSV, then passed on with a
/// blend mode the runtime offers in place of one only the layer offered.
///
/// # Safety
/// As `xrEndFrame`.
pub unsafe extern "system" fn end_frame(
    session: sys::Session,
    info: *const sys::FrameEndInfo,
) -> sys::Result {
    guard("xrEndFrame", || {
        let found = {
            let mut reg = registry();
            let added = SessionContext::of(&reg, session.into_raw())
                .map(|c| (c.next.clone(), (c.config.blend.clone(), c.config.ml_frame)));
            let instance_log = reg
                .session(session.into_raw())
                .and_then(|(_, i)| i.submitted.clone());
            reg.sessions.get_mut(&session.into_raw()).and_then(|s| {
                let frame = s.frames_ended;
                s.frames_ended += 1;
                added.map(|(next, added)| {
                    (
                        next,
                        added,
                        s.runtime_blend.clone(),
                        (frame, s.serial),
                        instance_log,
                    )
                })
            })
        };
        let Some((next, (added, ml_frame), runtime_blend, (frame, serial), log)) = found else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structure, null or valid.
        let Some(app) = (unsafe { info.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let raw = session.into_raw();
        let layer_count = if app.layers.is_null() {
            0
        } else {
            app.layer_count
        };
        if let Some(Some(r)) = faults::with(|f| {
            f.frame_call("xrEndFrame", raw)
                .or_else(|| f.refuse("xrEndFrame", raw))
                .or_else(|| {
                    f.submitted(raw, layer_count);
                    None
                })
        }) {
            return r;
        }
        let controls = if ml_frame {
            // SAFETY: the app's `next` chain: null or valid structures (xrEndFrame's valid
            // usage).
            unsafe { ml_frame_controls(app.next) }
        } else {
            MlFrameControls {
                rest: app.next,
                ..MlFrameControls::default()
            }
        };
        let runtime_mode = blend::for_runtime(
            app.environment_blend_mode,
            &added,
            runtime_blend
                .as_deref()
                .unwrap_or(&[sys::EnvironmentBlendMode::OPAQUE]),
        );
        if let Some(log) = log {
            let count = if app.layers.is_null() {
                0
            } else {
                app.layer_count as usize
            };
            let layers: Vec<LayerInfo> = (0..count)
                .filter_map(|i| {
                    // SAFETY: the app's non-null array of `layer_count` layer pointers.
                    let p = unsafe { *app.layers.add(i) };
                    // SAFETY: each non-null entry is a valid composition layer header.
                    unsafe { p.as_ref() }.map(|l| LayerInfo {
                        ty: l.ty,
                        flags: l.layer_flags.into_raw(),
                    })
                })
                .collect();
            let frame_info = FrameInfo {
                frame,
                display_time_ns: app.display_time.as_nanos(),
                blend: app.environment_blend_mode,
                runtime_blend: runtime_mode,
                layers,
                focus_distance_m: controls.focus_distance_m,
                global_dimmer: controls.global_dimmer,
                session: serial,
            };
            let mut log = log.lock().unwrap_or_else(|e| e.into_inner());
            if let Err(e) = log.write(&frame_info) {
                report(format!("writing the submitted-frames CSV: {e}"));
            }
        }
        let record = registry()
            .sessions
            .get(&session.into_raw())
            .and_then(|s| s.images.clone());
        if let Some(record) = record {
            // SAFETY: the app's valid frame end info.
            unsafe { measure_views(app, frame, &record) };
        }
        let mut forwarded = *app;
        forwarded.environment_blend_mode = runtime_mode;
        forwarded.next = controls.rest;
        // A frame shown a bad display time ends at its true one underneath; a negative one is
        // refused as a runtime refuses it.
        let bad = faults::with(|f| f.end_time(app.display_time.as_nanos())).flatten();
        if let Some((truth, _)) = bad {
            forwarded.display_time = sys::Time::from_nanos(truth);
        }
        // SAFETY: a copy of the app's valid structure, pointing at the app's layers.
        let r = unsafe { (next.end_frame)(session, &forwarded) };
        match bad {
            Some((_, BadTime::Negative)) if r.into_raw() >= 0 => sys::Result::ERROR_TIME_INVALID,
            _ => r,
        }
    })
}

/// Each view of the frame's projection layers, cut from the image its swapchain released
/// last: its alpha written to `alpha.csv`, and kept as the session's last frame.
///
/// # Safety
/// `app` must be the app's valid `XrFrameEndInfo`.
unsafe fn measure_views(app: &sys::FrameEndInfo, frame: u64, record: &Mutex<SessionImages>) {
    let count = if app.layers.is_null() {
        0
    } else {
        app.layer_count as usize
    };
    let mut views = Vec::new();
    for i in 0..count {
        // SAFETY: the app's non-null array of `layer_count` layer pointers.
        let p = unsafe { *app.layers.add(i) };
        // SAFETY: each non-null entry is a valid composition layer header.
        let Some(header) = (unsafe { p.as_ref() }) else {
            continue;
        };
        if header.ty != sys::StructureType::COMPOSITION_LAYER_PROJECTION {
            continue;
        }
        // SAFETY: a layer of that type is an `XrCompositionLayerProjection`.
        let projection = unsafe { &*(p as *const sys::CompositionLayerProjection) };
        for v in 0..projection.view_count as usize {
            // SAFETY: its array of `view_count` views.
            let view = unsafe { &*projection.views.add(v) };
            let sub = view.sub_image;
            let cut = {
                let reg = registry();
                reg.swapchains.get(&sub.swapchain.into_raw()).and_then(|c| {
                    let layer = c.released.as_ref()?.get(sub.image_array_index as usize)?;
                    ViewImage::cut(layer, c.size.0, sub.image_rect, c.layout?, view.fov)
                })
            };
            views.extend(cut);
        }
    }
    let mut record = record.lock().unwrap_or_else(|e| e.into_inner());
    for (v, view) in views.iter().enumerate() {
        let stats = view.alpha();
        if let Err(e) = record
            .log
            .write(frame, v, view.size, app.environment_blend_mode, &stats)
        {
            report(format!("writing alpha.csv: {e}"));
        }
    }
    if !views.is_empty() {
        record.last = views;
        record.last_blend = app.environment_blend_mode;
    }
}

/// What an `XrFrameEndInfo` chain asks of Magic Leap 2's frame controls.
#[derive(Clone, Copy, Debug)]
struct MlFrameControls {
    /// `XrFrameEndInfoML::focusDistance`, metres.
    focus_distance_m: Option<f32>,
    /// `XrGlobalDimmerFrameEndInfoML::dimmerValue`, when its ENABLED flag is set.
    global_dimmer: Option<f32>,
    /// The chain after the leading run of these structures: what goes on to the runtime.
    rest: *const std::ffi::c_void,
}

impl Default for MlFrameControls {
    fn default() -> Self {
        MlFrameControls {
            focus_distance_m: None,
            global_dimmer: None,
            rest: std::ptr::null(),
        }
    }
}

/// Reads the frame controls at the head of `chain` and steps past them (structures of these
/// types further down, behind one the layer does not know, stay: the app's structures cannot be
/// relinked, and a runtime ignores structures it does not know).
///
/// # Safety
/// `chain` is null or a valid OpenXR structure chain.
unsafe fn ml_frame_controls(mut chain: *const std::ffi::c_void) -> MlFrameControls {
    let mut out = MlFrameControls::default();
    // `chain` is null or a valid structure, which starts with the base header.
    let header_of =
        // SAFETY: the function's contract; each `next` of a valid chain is null or valid too.
        |p: *const std::ffi::c_void| unsafe { (p as *const sys::BaseInStructure).as_ref() };
    while let Some(header) = header_of(chain) {
        match header.ty {
            sys::StructureType::FRAME_END_INFO_ML => {
                // SAFETY: the header says the structure is an XrFrameEndInfoML.
                let info = unsafe { &*(chain as *const sys::FrameEndInfoML) };
                out.focus_distance_m = Some(info.focus_distance);
            }
            sys::StructureType::GLOBAL_DIMMER_FRAME_END_INFO_ML => {
                // SAFETY: the header says the structure is an XrGlobalDimmerFrameEndInfoML.
                let info = unsafe { &*(chain as *const sys::GlobalDimmerFrameEndInfoML) };
                if info
                    .flags
                    .contains(sys::GlobalDimmerFrameEndInfoFlagsML::ENABLED)
                {
                    out.global_dimmer = Some(info.dimmer_value);
                }
            }
            _ => break,
        }
        chain = header.next as *const std::ffi::c_void;
    }
    out.rest = chain;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_controls_at_the_head_of_the_chain_are_read_and_stepped_past() {
        let other = sys::FrameEndInfo {
            ty: sys::StructureType::FRAME_END_INFO,
            next: std::ptr::null(),
            display_time: sys::Time::from_nanos(0),
            environment_blend_mode: sys::EnvironmentBlendMode::ADDITIVE,
            layer_count: 0,
            layers: std::ptr::null(),
        };
        let dimmer = sys::GlobalDimmerFrameEndInfoML {
            ty: sys::GlobalDimmerFrameEndInfoML::TYPE,
            next: &other as *const sys::FrameEndInfo as *const _,
            dimmer_value: 0.4,
            flags: sys::GlobalDimmerFrameEndInfoFlagsML::ENABLED,
        };
        let focus = sys::FrameEndInfoML {
            ty: sys::FrameEndInfoML::TYPE,
            next: &dimmer as *const sys::GlobalDimmerFrameEndInfoML as *const _,
            focus_distance: 1.5,
            flags: sys::FrameEndInfoFlagsML::EMPTY,
        };
        // SAFETY: a valid chain of three structures on the stack.
        let c = unsafe { ml_frame_controls(&focus as *const sys::FrameEndInfoML as *const _) };
        assert_eq!(c.focus_distance_m, Some(1.5));
        assert_eq!(c.global_dimmer, Some(0.4));
        assert_eq!(c.rest, &other as *const sys::FrameEndInfo as *const _);
        // A dimmer not enabled asks for nothing.
        let off = sys::GlobalDimmerFrameEndInfoML {
            flags: sys::GlobalDimmerFrameEndInfoFlagsML::EMPTY,
            next: std::ptr::null(),
            ..dimmer
        };
        // SAFETY: one valid structure.
        let c = unsafe {
            ml_frame_controls(&off as *const sys::GlobalDimmerFrameEndInfoML as *const _)
        };
        assert_eq!(c.global_dimmer, None);
        assert!(c.rest.is_null());
    }
}
