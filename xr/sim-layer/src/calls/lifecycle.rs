//! The session's lifecycle and frame clock as the app sees them: beginning and ending the
//! session, asking it to exit, the events, the system, `xrWaitFrame` (which starts the trace
//! clock) and `xrBeginFrame`. Without a fault schedule every call passes on (the layer only
//! learns the blend modes and the clock); with one ([`crate::faults`]) the layer answers what a
//! misbehaving headset would: the states of a headset taken off or a menu, a lost session or
//! instance, frames not to render or late, and refusals for calls out of order.

use std::time::Instant;

use openxr::sys::{self, Handle};

use super::SessionContext;
use crate::faults::{self, state::Event, state::WaitPlan};
use crate::guard::{guard, report};
use crate::registry::registry;

/// `xrBeginSession`: answered by the layer when it walks the session (the headset back on),
/// else passed on; the layer then learns the runtime's blend modes for the session's view
/// configuration.
///
/// # Safety
/// As `xrBeginSession`.
pub unsafe extern "system" fn begin_session(
    session: sys::Session,
    info: *const sys::SessionBeginInfo,
) -> sys::Result {
    guard("xrBeginSession", || {
        let Some((ctx, system)) = ({
            let reg = registry();
            SessionContext::of(&reg, session.into_raw())
                .zip(reg.sessions.get(&session.into_raw()).map(|s| s.system))
        }) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = faults::with(|f| f.begin_session(session.into_raw())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (ctx.next.begin_session)(session, info) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success `info` was valid.
        let view = unsafe { (*info).primary_view_configuration_type };
        match ctx.next.runtime_blend_modes(ctx.instance, system, view) {
            Ok(modes) => {
                if let Some(s) = registry().sessions.get_mut(&session.into_raw()) {
                    s.runtime_blend = Some(modes);
                }
            }
            Err(e) => report(format!(
                "the runtime's blend modes could not be listed: {e:?}"
            )),
        }
        r
    })
}

/// `xrEndSession`: answered by the layer when it walks the session (the headset taken off),
/// else passed on.
///
/// # Safety
/// As `xrEndSession`.
pub unsafe extern "system" fn end_session(session: sys::Session) -> sys::Result {
    guard("xrEndSession", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = faults::with(|f| f.end_session(session.into_raw(), Instant::now())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's argument.
        unsafe { (ctx.next.end_session)(session) }
    })
}

/// `xrRequestExitSession`: refused while the app was shown a session that is not running,
/// else passed on.
///
/// # Safety
/// As `xrRequestExitSession`.
pub unsafe extern "system" fn request_exit_session(session: sys::Session) -> sys::Result {
    guard("xrRequestExitSession", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = faults::with(|f| f.request_exit(session.into_raw())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's argument.
        unsafe { (ctx.next.request_exit_session)(session) }
    })
}

/// `xrPollEvent`: the layer's own events first (the states it walks the session through, an
/// instance loss, a reference space change), then the runtime's; a session state the runtime
/// announces ends any walk of the layer's.
///
/// # Safety
/// As `xrPollEvent`.
pub unsafe extern "system" fn poll_event(
    instance: sys::Instance,
    buffer: *mut sys::EventDataBuffer,
) -> sys::Result {
    guard("xrPollEvent", || {
        let Some(next) = super::instance_next(instance) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if buffer.is_null() {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        if let Some(Some(event)) =
            faults::with(|f| f.next_event(instance.into_raw(), Instant::now()))
        {
            // SAFETY: the app's writable event buffer, large enough for any event.
            unsafe { write_event(buffer, &event) };
            return sys::Result::SUCCESS;
        }
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.poll_event)(instance, buffer) };
        // SAFETY: on success the runtime wrote an event, which starts with its type.
        let ty = unsafe { (*buffer).ty };
        if r == sys::Result::SUCCESS && ty == sys::StructureType::EVENT_DATA_SESSION_STATE_CHANGED {
            // SAFETY: an event of that type is an `XrEventDataSessionStateChanged`.
            let e = unsafe { &*(buffer as *const sys::EventDataSessionStateChanged) };
            faults::with(|f| f.runtime_state(e.session.into_raw(), e.state));
        }
        r
    })
}

/// Writes `event` into the app's event buffer.
///
/// # Safety
/// `buffer` must be a writable `XrEventDataBuffer`.
unsafe fn write_event(buffer: *mut sys::EventDataBuffer, event: &Event) {
    match *event {
        Event::State {
            session,
            state,
            time_ns,
        } => {
            let out = sys::EventDataSessionStateChanged {
                ty: sys::EventDataSessionStateChanged::TYPE,
                next: std::ptr::null(),
                session: sys::Session::from_raw(session),
                state,
                time: sys::Time::from_nanos(time_ns),
            };
            // SAFETY: the buffer (4 kB, 8-byte aligned) holds any event structure.
            unsafe {
                buffer
                    .cast::<sys::EventDataSessionStateChanged>()
                    .write(out)
            };
        }
        Event::InstanceLoss { loss_time_ns } => {
            let out = sys::EventDataInstanceLossPending {
                ty: sys::EventDataInstanceLossPending::TYPE,
                next: std::ptr::null(),
                loss_time: sys::Time::from_nanos(loss_time_ns),
            };
            // SAFETY: as above.
            unsafe {
                buffer
                    .cast::<sys::EventDataInstanceLossPending>()
                    .write(out)
            };
        }
        Event::SpaceChange {
            session,
            space,
            time_ns,
        } => {
            let out = sys::EventDataReferenceSpaceChangePending {
                ty: sys::EventDataReferenceSpaceChangePending::TYPE,
                next: std::ptr::null(),
                session: sys::Session::from_raw(session),
                reference_space_type: space,
                change_time: sys::Time::from_nanos(time_ns),
                pose_valid: sys::FALSE,
                pose_in_previous_space: sys::Posef::IDENTITY,
            };
            // SAFETY: as above.
            unsafe {
                buffer
                    .cast::<sys::EventDataReferenceSpaceChangePending>()
                    .write(out)
            };
        }
    }
}

/// `xrGetSystem`: refused with `XR_ERROR_FORM_FACTOR_UNAVAILABLE` while the headset is gone
/// after a session loss, else passed on.
///
/// # Safety
/// As `xrGetSystem`.
pub unsafe extern "system" fn get_system(
    instance: sys::Instance,
    info: *const sys::SystemGetInfo,
    system: *mut sys::SystemId,
) -> sys::Result {
    guard("xrGetSystem", || {
        let Some(next) = super::instance_next(instance) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = faults::with(|f| f.get_system(Instant::now())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        unsafe { (next.get_system)(instance, info, system) }
    })
}

/// `xrWaitFrame`: the frames a late app missed are waited for and ended first, then the app's
/// is passed on; the first predicted display time starts the trace clock, and the frame is
/// counted, told not to render and shown a bad display time where the faults say so (the
/// layer keeps the true one).
///
/// # Safety
/// As `xrWaitFrame`.
pub unsafe extern "system" fn wait_frame(
    session: sys::Session,
    info: *const sys::FrameWaitInfo,
    state: *mut sys::FrameState,
) -> sys::Result {
    guard("xrWaitFrame", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        match faults::with(|f| f.before_wait(session.into_raw())) {
            Some(WaitPlan::Refuse(r)) => return r,
            Some(WaitPlan::Go { late }) => {
                for _ in 0..late {
                    // SAFETY: the session is running (the app is about to wait for a frame).
                    match unsafe { skip_frame(&ctx) } {
                        Ok(display) => {
                            faults::with(|f| f.skipped(display));
                        }
                        Err(r) => {
                            report(format!("waiting for a late frame failed: {r:?}"));
                            break;
                        }
                    }
                }
            }
            None => {}
        }
        // SAFETY: the next layer's function with the app's arguments (the lock is not held:
        // this call blocks).
        let r = unsafe { (ctx.next.wait_frame)(session, info, state) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success the runtime filled `state`.
        let frame = unsafe { &mut *state };
        let display = frame.predicted_display_time.as_nanos();
        if let Some(s) = registry().sessions.get_mut(&session.into_raw()) {
            s.first_display_ns.get_or_insert(display);
            s.latest_display_ns = Some(display);
        }
        let asked = frame.should_render == sys::TRUE;
        if let Some((render, shown)) = faults::with(|f| {
            let render = f.after_wait(session.into_raw(), display, asked, Instant::now());
            (render, f.shown_display())
        }) {
            frame.should_render = if render { sys::TRUE } else { sys::FALSE };
            if let Some(shown) = shown {
                frame.predicted_display_time = sys::Time::from_nanos(shown);
            }
        }
        r
    })
}

/// Waits for, begins and ends one frame of `ctx`'s session with no layers (a frame the app is
/// too late for); its predicted display time.
///
/// # Safety
/// The session must be running, with no frame of the app's begun.
unsafe fn skip_frame(ctx: &SessionContext) -> Result<i64, sys::Result> {
    let wait = sys::FrameWaitInfo {
        ty: sys::FrameWaitInfo::TYPE,
        next: std::ptr::null(),
    };
    let mut state = sys::FrameState {
        ty: sys::FrameState::TYPE,
        next: std::ptr::null_mut(),
        predicted_display_time: sys::Time::from_nanos(0),
        predicted_display_period: sys::Duration::from_nanos(0),
        should_render: sys::FALSE,
    };
    let check = |r: sys::Result| if r.into_raw() < 0 { Err(r) } else { Ok(()) };
    // SAFETY: the caller's guarantee; valid structures on the stack.
    check(unsafe { (ctx.next.wait_frame)(ctx.session, &wait, &mut state) })?;
    let begin = sys::FrameBeginInfo {
        ty: sys::FrameBeginInfo::TYPE,
        next: std::ptr::null(),
    };
    // SAFETY: as above: the frame just waited for is begun.
    check(unsafe { (ctx.next.begin_frame)(ctx.session, &begin) })?;
    let mode = registry()
        .sessions
        .get(&ctx.session.into_raw())
        .and_then(|s| s.runtime_blend.as_ref().and_then(|m| m.first().copied()))
        .unwrap_or(sys::EnvironmentBlendMode::OPAQUE);
    let end = sys::FrameEndInfo {
        ty: sys::FrameEndInfo::TYPE,
        next: std::ptr::null(),
        display_time: state.predicted_display_time,
        environment_blend_mode: mode,
        layer_count: 0,
        layers: std::ptr::null(),
    };
    // SAFETY: as above: the begun frame ends with no layers in a mode the runtime offers.
    check(unsafe { (ctx.next.end_frame)(ctx.session, &end) })?;
    Ok(state.predicted_display_time.as_nanos())
}

/// `xrBeginFrame`: refused when the session is lost or the app was shown it not running, else
/// passed on.
///
/// # Safety
/// As `xrBeginFrame`.
pub unsafe extern "system" fn begin_frame(
    session: sys::Session,
    info: *const sys::FrameBeginInfo,
) -> sys::Result {
    guard("xrBeginFrame", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = faults::with(|f| f.frame_call("xrBeginFrame", session.into_raw())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        unsafe { (ctx.next.begin_frame)(session, info) }
    })
}
