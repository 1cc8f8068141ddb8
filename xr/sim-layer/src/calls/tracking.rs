//! Lost head tracking ([`crate::faults`]): the frames whose head poses the fault schedule
//! takes the position (then the orientation too) from, or fills with numbers no pose can hold
//! while marking them valid, in `xrLocateViews` and in `xrLocateSpace` of the head (a VIEW
//! reference space) against the world (LOCAL or STAGE); and the frames whose views' fields of
//! view `xrLocateViews` answers as four zero angles. What a pose's flags say is not valid the
//! specification leaves undefined: the layer writes NaN there, so an app that reads it shows
//! it.

use openxr::sys::{self, Handle};

use super::SessionContext;
use crate::faults::{self, state::TrackingLoss};
use crate::guard::guard;
use crate::registry::{Registry, registry};

/// The flags a located pose keeps without its position.
fn without_position(flags: sys::SpaceLocationFlags) -> sys::SpaceLocationFlags {
    flags & !(sys::SpaceLocationFlags::POSITION_VALID | sys::SpaceLocationFlags::POSITION_TRACKED)
}

/// The flags a located pose keeps without position or orientation.
fn without_orientation(flags: sys::SpaceLocationFlags) -> sys::SpaceLocationFlags {
    without_position(flags)
        & !(sys::SpaceLocationFlags::ORIENTATION_VALID
            | sys::SpaceLocationFlags::ORIENTATION_TRACKED)
}

/// A pose as it is reported after `loss`: what is not valid is undefined (NaN); an unusable
/// pose has a position that is not a number and an all-zero quaternion.
fn lose(pose: &mut sys::Posef, loss: TrackingLoss) {
    let nan = sys::Vector3f {
        x: f32::NAN,
        y: f32::NAN,
        z: f32::NAN,
    };
    if loss == TrackingLoss::ZeroFov {
        return;
    }
    pose.position = nan;
    match loss {
        TrackingLoss::Position | TrackingLoss::ZeroFov => {}
        TrackingLoss::Orientation => {
            pose.orientation = sys::Quaternionf {
                x: f32::NAN,
                y: f32::NAN,
                z: f32::NAN,
                w: f32::NAN,
            }
        }
        TrackingLoss::Unusable => {
            pose.orientation = sys::Quaternionf {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 0.0,
            }
        }
    }
}

/// The flags a located pose keeps after `loss` (an unusable pose keeps them all).
fn kept_flags(flags: sys::SpaceLocationFlags, loss: TrackingLoss) -> sys::SpaceLocationFlags {
    match loss {
        TrackingLoss::Position => without_position(flags),
        TrackingLoss::Orientation => without_orientation(flags),
        TrackingLoss::Unusable | TrackingLoss::ZeroFov => flags,
    }
}

/// Takes from a located space what this frame's head tracking lacks.
pub fn lose_location(location: &mut sys::SpaceLocation, loss: TrackingLoss) {
    location.location_flags = kept_flags(location.location_flags, loss);
    lose(&mut location.pose, loss);
}

/// For `xrLocateSpace` of `space` in `base`: the session, and whether one is the head (a
/// VIEW reference space) and the other the world (LOCAL or STAGE), the pair lost tracking
/// shows in.
pub fn head_in_world(reg: &Registry, space: u64, base: u64) -> Option<(u64, bool)> {
    let a = reg.spaces.get(&space)?;
    let b = reg.spaces.get(&base);
    let world = |t: Option<sys::ReferenceSpaceType>| {
        t == Some(sys::ReferenceSpaceType::LOCAL) || t == Some(sys::ReferenceSpaceType::STAGE)
    };
    let view = |t: Option<sys::ReferenceSpaceType>| t == Some(sys::ReferenceSpaceType::VIEW);
    let (ta, tb) = (a.reference, b.and_then(|b| b.reference));
    Some((
        a.session,
        (view(ta) && world(tb)) || (world(ta) && view(tb)),
    ))
}

/// `xrLocateViews`: refused when the session is lost (or the call is scheduled to fail), else
/// passed on, the eyes then moved and turned as the newest `eyes` fault or `VITREOUS_SIM_VIEWS`
/// asks ([`crate::views`]) and the views' flags and poses losing what this frame's head tracking
/// lacks.
///
/// # Safety
/// As `xrLocateViews`.
pub unsafe extern "system" fn locate_views(
    session: sys::Session,
    info: *const sys::ViewLocateInfo,
    state: *mut sys::ViewState,
    capacity: u32,
    count: *mut u32,
    views: *mut sys::View,
) -> sys::Result {
    guard("xrLocateViews", || {
        let Some(ctx) = SessionContext::of(&registry(), session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let faulted = faults::with(|f| {
            (
                f.refuse("xrLocateViews", session.into_raw()),
                f.tracking(),
                f.eyes(),
            )
        });
        if let Some((Some(refused), ..)) = faulted {
            return refused;
        }
        // SAFETY: the next layer's function with the app's arguments.
        let r = unsafe { (ctx.next.locate_views)(session, info, state, capacity, count, views) };
        if r.into_raw() < 0 {
            return r;
        }
        let written = if capacity == 0 || views.is_null() || count.is_null() {
            0
        } else {
            // SAFETY: on success `count` says how many of the app's views were written.
            unsafe { *count }.min(capacity) as usize
        };
        let asked = faulted.and_then(|(_, _, eyes)| eyes).or(ctx.config.views);
        if let Some(asked) = asked
            && written == 2
        {
            // SAFETY: the app's array of `capacity` views, these two filled.
            let (left, right) = unsafe { (&mut *views, &mut *views.add(1)) };
            [left.pose, right.pose] = crate::views::respaced([left.pose, right.pose], asked);
        }
        let Some((None, Some(loss), _)) = faulted else {
            return r;
        };
        if state.is_null() {
            return r;
        }
        // SAFETY: on success the runtime filled the app's view state.
        let state = unsafe { &mut *state };
        let flags = sys::SpaceLocationFlags::from_raw(state.view_state_flags.into_raw());
        let kept = kept_flags(flags, loss);
        state.view_state_flags = sys::ViewStateFlags::from_raw(kept.into_raw());
        for i in 0..written {
            // SAFETY: the app's array of `capacity` views, `written` of them filled.
            let view = unsafe { &mut *views.add(i) };
            lose(&mut view.pose, loss);
            if loss == TrackingLoss::ZeroFov {
                view.fov = sys::Fovf {
                    angle_left: 0.0,
                    angle_right: 0.0,
                    angle_up: 0.0,
                    angle_down: 0.0,
                };
            }
        }
        r
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sys::SpaceLocationFlags as F;

    #[test]
    fn a_lost_position_keeps_the_orientation_and_a_lost_orientation_keeps_nothing() {
        let all =
            F::POSITION_VALID | F::POSITION_TRACKED | F::ORIENTATION_VALID | F::ORIENTATION_TRACKED;
        let mut loc = sys::SpaceLocation {
            ty: sys::SpaceLocation::TYPE,
            next: std::ptr::null_mut(),
            location_flags: all,
            pose: sys::Posef {
                orientation: sys::Quaternionf {
                    x: 0.0,
                    y: 0.6,
                    z: 0.0,
                    w: 0.8,
                },
                position: sys::Vector3f {
                    x: 1.0,
                    y: 1.6,
                    z: -2.0,
                },
            },
        };
        let mut position_lost = loc;
        lose_location(&mut position_lost, TrackingLoss::Position);
        assert_eq!(
            position_lost.location_flags,
            F::ORIENTATION_VALID | F::ORIENTATION_TRACKED
        );
        assert_eq!(position_lost.pose.orientation.y, 0.6);
        assert!(position_lost.pose.position.y.is_nan());
        let mut unusable = loc;
        lose_location(&mut unusable, TrackingLoss::Unusable);
        assert_eq!(unusable.location_flags, all, "still marked valid");
        assert!(unusable.pose.position.x.is_nan());
        assert_eq!(unusable.pose.orientation.w, 0.0);
        lose_location(&mut loc, TrackingLoss::Orientation);
        assert_eq!(loc.location_flags, F::EMPTY);
        assert!(loc.pose.orientation.w.is_nan());
    }
}
