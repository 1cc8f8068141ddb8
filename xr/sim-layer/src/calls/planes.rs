//! `XR_EXT_plane_detection`, answered from the configured planes (`VITREOUS_SIM_PLANES`): each
//! a level rectangle facing up, placed in the frame the app's scene takes at its first head
//! pose (the head's position, turned to face where the head faces, level). A detection is
//! done as soon as it begins: at `xrBeginPlaneDetectionEXT` the layer notes the head's level
//! pose in the base space asked for, and every plane is given relative to it. Planes have no
//! polygon buffers (`polygonBufferCount` 0).

use glam::{Quat, Vec3};
use openxr::sys::{self, Handle};
use vitreous_trace::Pose;

use super::SessionContext;
use crate::eye_geometry::{compose, to_posef};
use crate::guard::guard;
use crate::registry::{DetectorState, registry};

/// The context of a detector the layer made, with its state.
fn detector(handle: sys::PlaneDetectorEXT) -> Option<(SessionContext, DetectorState)> {
    let reg = registry();
    let d = reg.detectors.get(&handle.into_raw())?.clone();
    Some((SessionContext::of(&reg, d.session)?, d))
}

/// `xrCreatePlaneDetectorEXT`.
///
/// # Safety
/// As `xrCreatePlaneDetectorEXT`.
pub unsafe extern "system" fn create_plane_detector(
    session: sys::Session,
    info: *const sys::PlaneDetectorCreateInfoEXT,
    out: *mut sys::PlaneDetectorEXT,
) -> sys::Result {
    guard("xrCreatePlaneDetectorEXT", || {
        // SAFETY: the app's structures, null or valid.
        let (Some(info), Some(out)) = (unsafe { info.as_ref() }, unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.ty != sys::PlaneDetectorCreateInfoEXT::TYPE {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(h) = registry().new_detector(session.into_raw()) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        *out = sys::PlaneDetectorEXT::from_raw(h);
        sys::Result::SUCCESS
    })
}

/// `xrDestroyPlaneDetectorEXT`.
///
/// # Safety
/// As `xrDestroyPlaneDetectorEXT`.
pub unsafe extern "system" fn destroy_plane_detector(handle: sys::PlaneDetectorEXT) -> sys::Result {
    guard("xrDestroyPlaneDetectorEXT", || {
        match registry().detectors.remove(&handle.into_raw()) {
            Some(_) => sys::Result::SUCCESS,
            None => sys::Result::ERROR_HANDLE_INVALID,
        }
    })
}

/// The head's level pose in `base` at `time`: its position, turned about `base`'s +y to face
/// where the head faces.
pub(crate) fn level_head(ctx: &SessionContext, base: sys::Space, time: sys::Time) -> Option<Pose> {
    let (head, _) = ctx.head_to_base(base, time)?;
    let f = head.orientation * Vec3::NEG_Z;
    let yaw = if f.x.abs() < 1e-6 && f.z.abs() < 1e-6 {
        Quat::IDENTITY
    } else {
        Quat::from_rotation_y((-f.x).atan2(-f.z))
    };
    Some(Pose {
        position: head.position,
        orientation: yaw,
    })
}

/// `xrBeginPlaneDetectionEXT`: the detection is done at once; only upward planes are
/// configured, so a filter without `HORIZONTAL_UPWARD` finds none.
///
/// # Safety
/// As `xrBeginPlaneDetectionEXT`.
pub unsafe extern "system" fn begin_plane_detection(
    handle: sys::PlaneDetectorEXT,
    info: *const sys::PlaneDetectorBeginInfoEXT,
) -> sys::Result {
    guard("xrBeginPlaneDetectionEXT", || {
        let Some((ctx, _)) = detector(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structure, null or valid.
        let Some(info) = (unsafe { info.as_ref() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.ty != sys::PlaneDetectorBeginInfoEXT::TYPE {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        if info.time.as_nanos() <= 0 {
            return sys::Result::ERROR_TIME_INVALID;
        }
        let orientations = if info.orientation_count == 0 || info.orientations.is_null() {
            &[][..]
        } else {
            // SAFETY: the app's array of `orientation_count` values.
            unsafe {
                std::slice::from_raw_parts(info.orientations, info.orientation_count as usize)
            }
        };
        let upward = orientations.is_empty()
            || orientations.contains(&sys::PlaneDetectorOrientationEXT::HORIZONTAL_UPWARD);
        let Some(anchor) = level_head(&ctx, info.base_space, info.time) else {
            return sys::Result::ERROR_SPACE_NOT_LOCATABLE_EXT;
        };
        let planes = if upward {
            ctx.config.planes.len().min(info.max_planes as usize)
        } else {
            0
        };
        if let Some(d) = registry().detectors.get_mut(&handle.into_raw()) {
            d.detection = Some((info.base_space, anchor, planes));
        }
        sys::Result::SUCCESS
    })
}

/// `xrGetPlaneDetectionStateEXT`: NONE before a detection began, DONE after.
///
/// # Safety
/// As `xrGetPlaneDetectionStateEXT`.
pub unsafe extern "system" fn get_plane_detection_state(
    handle: sys::PlaneDetectorEXT,
    state: *mut sys::PlaneDetectionStateEXT,
) -> sys::Result {
    guard("xrGetPlaneDetectionStateEXT", || {
        let Some((_, d)) = detector(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(state) = (unsafe { state.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        *state = if d.detection.is_some() {
            sys::PlaneDetectionStateEXT::DONE
        } else {
            sys::PlaneDetectionStateEXT::NONE
        };
        sys::Result::SUCCESS
    })
}

/// `xrGetPlaneDetectionsEXT`: the detected planes in `baseSpace` at `time` (two-call).
///
/// # Safety
/// As `xrGetPlaneDetectionsEXT`.
pub unsafe extern "system" fn get_plane_detections(
    handle: sys::PlaneDetectorEXT,
    info: *const sys::PlaneDetectorGetInfoEXT,
    locations: *mut sys::PlaneDetectorLocationsEXT,
) -> sys::Result {
    guard("xrGetPlaneDetectionsEXT", || {
        let Some((ctx, d)) = detector(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's structures, null or valid.
        let (Some(info), Some(out)) = (unsafe { info.as_ref() }, unsafe { locations.as_mut() })
        else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.ty != sys::PlaneDetectorGetInfoEXT::TYPE
            || out.ty != sys::PlaneDetectorLocationsEXT::TYPE
        {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some((begin_space, anchor, count)) = d.detection else {
            return sys::Result::ERROR_CALL_ORDER_INVALID;
        };
        out.plane_location_count_output = count as u32;
        if out.plane_location_capacity_input == 0 {
            return sys::Result::SUCCESS;
        }
        if (out.plane_location_capacity_input as usize) < count || out.plane_locations.is_null() {
            return sys::Result::ERROR_SIZE_INSUFFICIENT;
        }
        // The detection's base space in the one asked for now (the same space: identity).
        let Some(begin_in_base) = ctx.space_in(begin_space, info.base_space, info.time) else {
            return sys::Result::ERROR_SPACE_NOT_LOCATABLE_EXT;
        };
        let anchor_in_base = compose(&begin_in_base, &anchor);
        // SAFETY: the app's array holds at least `count` entries (checked above).
        let slots = unsafe { std::slice::from_raw_parts_mut(out.plane_locations, count) };
        for (i, (slot, plane)) in slots.iter_mut().zip(&ctx.config.planes).enumerate() {
            // The rectangle's +z (its normal) up: turned -90 degrees about x.
            let local = Pose {
                position: plane.center_m,
                orientation: Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            };
            slot.plane_id = i as u64 + 1;
            slot.location_flags = super::all_location_flags();
            slot.pose = to_posef(&compose(&anchor_in_base, &local));
            slot.extents = sys::Extent2Df {
                width: plane.size_m.x,
                height: plane.size_m.y,
            };
            slot.orientation = sys::PlaneDetectorOrientationEXT::HORIZONTAL_UPWARD;
            slot.semantic_type = sys::PlaneDetectorSemanticTypeEXT::PLATFORM;
            slot.polygon_buffer_count = 0;
        }
        sys::Result::SUCCESS
    })
}

/// `xrGetPlanePolygonBufferEXT`: the layer's planes have none.
///
/// # Safety
/// As `xrGetPlanePolygonBufferEXT`.
pub unsafe extern "system" fn get_plane_polygon_buffer(
    handle: sys::PlaneDetectorEXT,
    _plane_id: u64,
    _index: u32,
    _buffer: *mut sys::PlaneDetectorPolygonBufferEXT,
) -> sys::Result {
    guard("xrGetPlanePolygonBufferEXT", || match detector(handle) {
        Some(_) => sys::Result::ERROR_VALIDATION_FAILURE,
        None => sys::Result::ERROR_HANDLE_INVALID,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_geometry::{from_posef, inverse};

    #[test]
    fn an_upward_plane_turned_from_its_rectangle_faces_plus_y() {
        let q = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
        assert!((q * Vec3::Z - Vec3::Y).length() < 1e-6);
        // Its width stays along x, its height runs along -z (away from the viewer).
        assert!((q * Vec3::X - Vec3::X).length() < 1e-6);
        let p = from_posef(&to_posef(&Pose {
            position: Vec3::ONE,
            orientation: q,
        }));
        assert!((inverse(&p).transform_point(Vec3::ONE)).length() < 1e-6);
    }
}
