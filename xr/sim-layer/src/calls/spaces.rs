//! Space calls: the spaces the layer notes per session (reference spaces, the eye-gaze
//! action's space, whose location the layer answers itself), locating them, and the gaze
//! action's pose state.

use openxr::sys::{self, Handle};

use super::{SessionContext, all_location_flags, chain, tracking};
use crate::eye_geometry::{combined_ray, compose, from_posef, ray_pose, relative, to_posef};
use crate::faults;
use crate::guard::guard;
use crate::registry::{SpaceState, registry};
use vitreous_trace::Pose;

/// `xrCreateReferenceSpace`: passed on; the layer notes the space's session.
///
/// # Safety
/// As `xrCreateReferenceSpace`.
pub unsafe extern "system" fn create_reference_space(
    session: sys::Session,
    info: *const sys::ReferenceSpaceCreateInfo,
    space: *mut sys::Space,
) -> sys::Result {
    guard("xrCreateReferenceSpace", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (ctx.next.create_reference_space)(session, info, space) };
        if r.into_raw() >= 0 {
            // SAFETY: on success the new space was written.
            let created = unsafe { *space };
            // SAFETY: on success `info` was valid.
            let reference = unsafe { (*info).reference_space_type };
            registry().spaces.insert(
                created.into_raw(),
                SpaceState {
                    session: session.into_raw(),
                    action: None,
                    reference: Some(reference),
                },
            );
            faults::with(|f| f.space_created(session.into_raw(), reference));
        }
        r
    })
}

/// `xrCreateActionSpace`: created in the runtime (so the handle is real); for an eye-gaze
/// action the layer remembers it and answers its location itself.
///
/// # Safety
/// As `xrCreateActionSpace`.
pub unsafe extern "system" fn create_action_space(
    session: sys::Session,
    info: *const sys::ActionSpaceCreateInfo,
    space: *mut sys::Space,
) -> sys::Result {
    guard("xrCreateActionSpace", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (ctx.next.create_action_space)(session, info, space) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success `info` was valid and the new space was written.
        let (action, offset, created) =
            unsafe { ((*info).action, (*info).pose_in_action_space, *space) };
        registry().spaces.insert(
            created.into_raw(),
            SpaceState {
                session: session.into_raw(),
                action: Some((action.into_raw(), from_posef(&offset))),
                reference: None,
            },
        );
        r
    })
}

/// `xrDestroySpace`: passed on; the layer forgets the space.
///
/// # Safety
/// As `xrDestroySpace`.
pub unsafe extern "system" fn destroy_space(space: sys::Space) -> sys::Result {
    guard("xrDestroySpace", || {
        let next = {
            let mut reg = registry();
            let next = reg.next_for_space(space.into_raw());
            reg.spaces.remove(&space.into_raw());
            next
        };
        let Some(next) = next else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the next layer's function with the app's live space.
        unsafe { (next.destroy_space)(space) }
    })
}

/// Where a space is in the head frame at `time`: the gaze pose for an eye-gaze action space
/// (`None` flags when the gaze is invalid), else as the runtime locates it.
fn in_view(
    ctx: &SessionContext,
    space: sys::Space,
    gaze_offset: Option<Pose>,
    time: sys::Time,
) -> Option<(Pose, sys::SpaceLocationFlags)> {
    match gaze_offset {
        Some(offset) => {
            let ray = combined_ray(&ctx.gaze_at(time.as_nanos())?);
            if !ray.valid {
                return Some((Pose::IDENTITY, sys::SpaceLocationFlags::EMPTY));
            }
            Some((compose(&ray_pose(&ray), &offset), all_location_flags()))
        }
        None => ctx.runtime_space_in_view(space, time),
    }
}

/// `xrLocateSpace`: an eye-gaze action space is located from the trace's combined gaze at
/// `time` composed with the runtime's head pose; other spaces go to the runtime.
///
/// # Safety
/// As `xrLocateSpace`.
pub unsafe extern "system" fn locate_space(
    space: sys::Space,
    base: sys::Space,
    time: sys::Time,
    location: *mut sys::SpaceLocation,
) -> sys::Result {
    guard("xrLocateSpace", || {
        let (next, gaze, head) = {
            let reg = registry();
            let a = reg.gaze_space(space.into_raw());
            let b = reg.gaze_space(base.into_raw());
            let ctx = a.or(b).and_then(|(s, _)| SessionContext::of(&reg, s));
            (
                reg.next_for_space(space.into_raw()),
                ctx.map(|c| (c, a.map(|(_, o)| o), b.map(|(_, o)| o))),
                tracking::head_in_world(&reg, space.into_raw(), base.into_raw()),
            )
        };
        let Some((ctx, a_offset, b_offset)) = gaze else {
            let Some(next) = next else {
                return sys::Result::ERROR_HANDLE_INVALID;
            };
            let (refused, loss) = head
                .and_then(|(session, head_in_world)| {
                    faults::with(|f| {
                        let refused = f.refuse("xrLocateSpace", session);
                        (refused, f.tracking().filter(|_| head_in_world))
                    })
                })
                .unwrap_or((None, None));
            if let Some(r) = refused {
                return r;
            }
            // SAFETY: the next layer's function with the app's arguments.
            let r = unsafe { (next.locate_space)(space, base, time, location) };
            if let Some(loss) = loss.filter(|_| r.into_raw() >= 0) {
                // SAFETY: on success the runtime filled the app's location (null or valid).
                if let Some(loc) = unsafe { location.as_mut() } {
                    tracking::lose_location(loc, loss);
                }
            }
            return r;
        };
        // SAFETY: the app's output structure, null or valid.
        let Some(loc) = (unsafe { location.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if time.as_nanos() <= 0 {
            return sys::Result::ERROR_TIME_INVALID;
        }
        let (Some((a, fa)), Some((b, fb))) = (
            in_view(&ctx, space, a_offset, time),
            in_view(&ctx, base, b_offset, time),
        ) else {
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        let flags = gaze_location_flags(if fa.is_empty() || fb.is_empty() {
            sys::SpaceLocationFlags::EMPTY
        } else {
            fa & fb
        });
        loc.location_flags = flags;
        loc.pose = if flags.is_empty() {
            sys::Posef::IDENTITY
        } else {
            to_posef(&relative(&a, &b))
        };
        let sample_time = ctx
            .gaze_at(time.as_nanos())
            .map_or(time.as_nanos(), |g| g.sample_time_ns);
        // SAFETY: the app's chain of valid output structures.
        for n in unsafe { chain(loc.next) } {
            // SAFETY: `n` is a valid structure; it is written only as the type it declares.
            unsafe {
                if (*n).ty == sys::EyeGazeSampleTimeEXT::TYPE {
                    (*(n as *mut sys::EyeGazeSampleTimeEXT)).time =
                        sys::Time::from_nanos(sample_time);
                } else if (*n).ty == sys::SpaceVelocity::TYPE {
                    (*(n as *mut sys::SpaceVelocity)).velocity_flags =
                        sys::SpaceVelocityFlags::EMPTY;
                }
            }
        }
        sys::Result::SUCCESS
    })
}

/// A gaze space's location flags: XR_EXT_eye_gaze_interaction has position and orientation
/// tracked together or neither (the head's flags, mixed in, may track only the orientation);
/// the valid bits stay as they were.
pub fn gaze_location_flags(flags: sys::SpaceLocationFlags) -> sys::SpaceLocationFlags {
    let tracked =
        sys::SpaceLocationFlags::POSITION_TRACKED | sys::SpaceLocationFlags::ORIENTATION_TRACKED;
    if flags.contains(tracked) {
        flags
    } else {
        flags & !tracked
    }
}

/// `xrGetActionStatePose`: an eye-gaze action is active (the simulated tracker is always
/// on); other actions go to the runtime.
///
/// # Safety
/// As `xrGetActionStatePose`.
pub unsafe extern "system" fn get_action_state_pose(
    session: sys::Session,
    info: *const sys::ActionStateGetInfo,
    state: *mut sys::ActionStatePose,
) -> sys::Result {
    guard("xrGetActionStatePose", || {
        let found = {
            let reg = registry();
            SessionContext::of(&reg, session.into_raw()).map(|c| {
                let gaze = reg
                    .instances
                    .get(&c.instance.into_raw())
                    .map(|i| i.gaze_actions.clone())
                    .unwrap_or_default();
                let attached = reg
                    .sessions
                    .get(&session.into_raw())
                    .is_some_and(|s| s.attached);
                (c, gaze, attached)
            })
        };
        let Some((ctx, gaze_actions, attached)) = found else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structures, null or valid.
        let (Some(get), Some(out)) = (unsafe { info.as_ref() }, unsafe { state.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if gaze_actions.contains(&get.action.into_raw()) {
            if !attached {
                return sys::Result::ERROR_ACTIONSET_NOT_ATTACHED;
            }
            out.is_active = sys::TRUE;
            return sys::Result::SUCCESS;
        }
        // SAFETY: the next layer's function with the app's arguments.
        unsafe { (ctx.next.get_action_state_pose)(session, info, state) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sys::SpaceLocationFlags as F;

    #[test]
    fn a_gaze_space_tracks_position_and_orientation_together_or_neither() {
        let valid = F::POSITION_VALID | F::ORIENTATION_VALID;
        let all = valid | F::POSITION_TRACKED | F::ORIENTATION_TRACKED;
        assert_eq!(gaze_location_flags(all), all);
        // The head tracks its orientation only: neither is tracked, both stay valid.
        assert_eq!(gaze_location_flags(valid | F::ORIENTATION_TRACKED), valid);
        assert_eq!(gaze_location_flags(valid | F::POSITION_TRACKED), valid);
        assert_eq!(gaze_location_flags(F::EMPTY), F::EMPTY);
    }
}
