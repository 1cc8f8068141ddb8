//! Simulated controller buttons (`VITREOUS_SIM_BUTTONS`, [`crate::controller`]): each
//! `xrSyncActions` is stamped with the session's newest predicted display time, and
//! `xrGetActionStateBoolean` for an action bound to a scripted input answers from the script
//! at that time.

use openxr::sys::{self, Handle};

use crate::guard::guard;
use crate::registry::registry;

/// Nanoseconds per second.
const NS_PER_S: f64 = 1e9;

/// `xrSyncActions`: passed on; on success the sync is stamped with the newest predicted
/// display time (the clock the button script runs on).
///
/// # Safety
/// As `xrSyncActions`.
pub unsafe extern "system" fn sync_actions(
    session: sys::Session,
    info: *const sys::ActionsSyncInfo,
) -> sys::Result {
    guard("xrSyncActions", || {
        let Some(next) = registry()
            .session(session.into_raw())
            .map(|(_, i)| i.next.clone())
        else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        if let Some(Some(r)) = crate::faults::with(|f| f.sync_actions(session.into_raw())) {
            return r;
        }
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.sync_actions)(session, info) };
        if r.into_raw() >= 0
            && let Some(s) = registry().sessions.get_mut(&session.into_raw())
        {
            s.syncs_ns = (s.syncs_ns.1, s.latest_display_ns);
        }
        r
    })
}

/// `xrGetActionStateBoolean`: passed on; for an action bound to a scripted input of the hand
/// asked for (or of either hand), the state is then the script's at the last sync: active,
/// down or up, changed since the sync before, and when it last changed (runtime time).
///
/// # Safety
/// As `xrGetActionStateBoolean`.
pub unsafe extern "system" fn get_action_state_boolean(
    session: sys::Session,
    info: *const sys::ActionStateGetInfo,
    state: *mut sys::ActionStateBoolean,
) -> sys::Result {
    guard("xrGetActionStateBoolean", || {
        // SAFETY: the app's structure, null or valid.
        let action = unsafe { info.as_ref() }.map(|get| get.action.into_raw());
        let found = {
            let reg = registry();
            reg.session(session.into_raw()).map(|(s, i)| {
                (
                    i.next.clone(),
                    i.buttons.clone(),
                    s.first_display_ns,
                    s.syncs_ns,
                    // The scripted inputs of this action only: the call comes several times a
                    // frame.
                    action.and_then(|a| i.button_actions.get(&a).cloned()),
                )
            })
        };
        let Some((next, buttons, first_ns, (previous_ns, now_ns), inputs)) = found else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (next.get_action_state_boolean)(session, info, state) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: the app's structures, valid on success of the call above.
        let (Some(get), Some(out)) = (unsafe { info.as_ref() }, unsafe { state.as_mut() }) else {
            return r;
        };
        let (Some(buttons), Some(first_ns), Some(now_ns)) = (buttons, first_ns, now_ns) else {
            return r;
        };
        let Some(input) = inputs.and_then(|inputs| buttons.input_for(&inputs, get.subaction_path))
        else {
            return r;
        };
        let seconds = |ns: i64| (ns - first_ns) as f64 / NS_PER_S;
        let (down, changed, since) =
            buttons
                .script
                .boolean_state(input, seconds(now_ns), previous_ns.map(seconds));
        out.is_active = sys::TRUE;
        out.current_state = down.into();
        out.changed_since_last_sync = changed.into();
        out.last_change_time =
            sys::Time::from_nanos(since.map_or(0, |s| first_ns + (s * NS_PER_S).round() as i64));
        r
    })
}
