//! `XR_ML_light_estimation`, answered from the configured light (`VITREOUS_SIM_LIGHT`): the
//! main light's direction, given in the frame of the head's level pose when the estimation is
//! made (as the planes are), its colour, a uniform ambient light, and a turn of the main light
//! at a set time. The estimate updates when the estimation is made and again when the light
//! turns (`lastUpdate`), on the display clock of the app's newest `xrWaitFrame`.
//!
//! An estimate holds the main light, the ambient light's spherical harmonics (a uniform
//! radiance `a` has only the l = 0 coefficient, `a` times the square root of 4 pi, in each
//! channel) and an HDR cube map of both (RGBA floats, faces +x, -x, +y, -y, +z, -z as Vulkan
//! orders them): the ambient everywhere, the main light's colour where a texel looks within
//! [`LIGHT_RADIUS_DEG`] of where the light comes from.

use glam::{Vec2, Vec3};
use openxr::sys;
use vitreous_xr::openxr::ml_light_estimation as ml;

use super::SessionContext;
use super::planes::level_head;
use crate::config::SimLight;
use crate::guard::guard;
use crate::registry::{EstimateState, EstimationState, registry};

/// The angular radius of the main light in the cube map, degrees.
pub const LIGHT_RADIUS_DEG: f32 = 5.0;

/// The context and configured light of an estimation the layer made, with its state.
fn estimation(
    handle: ml::LightEstimationML,
) -> Option<(SessionContext, SimLight, EstimationState)> {
    let reg = registry();
    let e = *reg.estimations.get(&handle.0)?;
    let ctx = SessionContext::of(&reg, e.session)?;
    let light = ctx.config.light?;
    Some((ctx, light, e))
}

/// The estimate of `handle`, with the light it was made from and its estimation's cube map
/// face side.
fn estimate(handle: ml::LightEstimationEstimateML) -> Option<(EstimateState, SimLight, u32)> {
    let reg = registry();
    let e = *reg.estimates.get(&handle.0)?;
    let estimation = reg.estimations.get(&e.estimation)?;
    let light = SessionContext::of(&reg, estimation.session)?.config.light?;
    Some((e, light, estimation.face_side))
}

/// Whether a structure the app passed has the extension's type `raw`.
fn typed(ty: sys::StructureType, raw: i32) -> bool {
    ty.into_raw() == raw
}

/// Seconds from `from_ns` to `to_ns`.
fn seconds(from_ns: i64, to_ns: i64) -> f64 {
    (to_ns - from_ns) as f64 * 1e-9
}

/// When the estimate last changed, as of display time `now_ns`: when the estimation was made,
/// or when the light turned once that has happened.
fn last_update_ns(light: &SimLight, e: &EstimationState, now_ns: i64) -> i64 {
    match light.turn {
        Some((_, at_s)) if seconds(e.made_ns, now_ns) >= at_s => {
            e.made_ns + (at_s * 1e9).round() as i64
        }
        _ => e.made_ns,
    }
}

/// `xrCreateLightEstimationML`.
///
/// # Safety
/// As `xrCreateLightEstimationML`.
pub unsafe extern "system" fn create_light_estimation(
    session: sys::Session,
    info: *const ml::LightEstimationCreateInfoML,
    out: *mut ml::LightEstimationML,
) -> sys::Result {
    guard("xrCreateLightEstimationML", || {
        // SAFETY: the app's structures, null or valid.
        let (Some(info), Some(out)) = (unsafe { info.as_ref() }, unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !typed(info.ty, ml::structure_type::CREATE_INFO) {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let Some(face_side) = info.cubemap_face_resolution.side() else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if info.time.as_nanos() <= 0 {
            return sys::Result::ERROR_TIME_INVALID;
        }
        let ctx = {
            let reg = registry();
            SessionContext::of(&reg, sys::Handle::into_raw(session))
        };
        let Some(ctx) = ctx else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        let Some(anchor) = level_head(&ctx, info.base_space, info.time) else {
            // The head cannot be placed in the base space yet: no estimate can be given in it.
            return sys::Result::ERROR_RUNTIME_FAILURE;
        };
        let mut reg = registry();
        let h = reg.new_handle();
        reg.estimations.insert(
            h,
            EstimationState {
                session: sys::Handle::into_raw(session),
                base_space: info.base_space,
                anchor,
                made_ns: info.time.as_nanos(),
                face_side,
            },
        );
        *out = ml::LightEstimationML(h);
        sys::Result::SUCCESS
    })
}

/// `xrDestroyLightEstimationML`: its estimates go with it.
///
/// # Safety
/// As `xrDestroyLightEstimationML`.
pub unsafe extern "system" fn destroy_light_estimation(
    handle: ml::LightEstimationML,
) -> sys::Result {
    guard("xrDestroyLightEstimationML", || {
        let mut reg = registry();
        if reg.estimations.remove(&handle.0).is_none() {
            return sys::Result::ERROR_HANDLE_INVALID;
        }
        reg.estimates.retain(|_, e| e.estimation != handle.0);
        sys::Result::SUCCESS
    })
}

/// `xrGetLightEstimationStateML`: the last update as of the newest frame.
///
/// # Safety
/// As `xrGetLightEstimationStateML`.
pub unsafe extern "system" fn get_light_estimation_state(
    handle: ml::LightEstimationML,
    state: *mut ml::LightEstimationStateML,
) -> sys::Result {
    guard("xrGetLightEstimationStateML", || {
        let Some((ctx, light, e)) = estimation(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(state) = (unsafe { state.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !typed(state.ty, ml::structure_type::STATE) {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let now = ctx.latest_display_ns.unwrap_or(e.made_ns);
        state.last_update = sys::Time::from_nanos(last_update_ns(&light, &e, now));
        sys::Result::SUCCESS
    })
}

/// `xrCreateLightEstimationEstimateML`: the light as of the newest frame, in the
/// estimation's base space.
///
/// # Safety
/// As `xrCreateLightEstimationEstimateML`.
pub unsafe extern "system" fn create_light_estimation_estimate(
    handle: ml::LightEstimationML,
    out: *mut ml::LightEstimationEstimateML,
) -> sys::Result {
    guard("xrCreateLightEstimationEstimateML", || {
        let Some((ctx, light, e)) = estimation(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        let now = ctx.latest_display_ns.unwrap_or(e.made_ns);
        let direction = e.anchor.orientation * light.direction_at(seconds(e.made_ns, now));
        let mut reg = registry();
        let h = reg.new_handle();
        reg.estimates.insert(
            h,
            EstimateState {
                estimation: handle.0,
                direction,
                time_ns: last_update_ns(&light, &e, now),
            },
        );
        *out = ml::LightEstimationEstimateML(h);
        sys::Result::SUCCESS
    })
}

/// `xrDestroyLightEstimationEstimateML`.
///
/// # Safety
/// As `xrDestroyLightEstimationEstimateML`.
pub unsafe extern "system" fn destroy_light_estimation_estimate(
    handle: ml::LightEstimationEstimateML,
) -> sys::Result {
    guard("xrDestroyLightEstimationEstimateML", || {
        match registry().estimates.remove(&handle.0) {
            Some(_) => sys::Result::SUCCESS,
            None => sys::Result::ERROR_HANDLE_INVALID,
        }
    })
}

/// `xrGetLightEstimationTimestampML`.
///
/// # Safety
/// As `xrGetLightEstimationTimestampML`.
pub unsafe extern "system" fn get_light_estimation_timestamp(
    handle: ml::LightEstimationEstimateML,
    out: *mut sys::Time,
) -> sys::Result {
    guard("xrGetLightEstimationTimestampML", || {
        let Some((e, _, _)) = estimate(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        *out = sys::Time::from_nanos(e.time_ns);
        sys::Result::SUCCESS
    })
}

/// `xrGetLightEstimationMainDirectionalLightML`.
///
/// # Safety
/// As `xrGetLightEstimationMainDirectionalLightML`.
pub unsafe extern "system" fn get_main_directional_light(
    handle: ml::LightEstimationEstimateML,
    out: *mut ml::LightEstimationMainDirectionalLightML,
) -> sys::Result {
    guard("xrGetLightEstimationMainDirectionalLightML", || {
        let Some((e, light, _)) = estimate(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !typed(out.ty, ml::structure_type::MAIN_DIRECTIONAL_LIGHT) {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        out.direction = sys::Vector3f {
            x: e.direction.x,
            y: e.direction.y,
            z: e.direction.z,
        };
        out.color = sys::Color4f {
            r: light.color.x,
            g: light.color.y,
            b: light.color.z,
            a: 1.0,
        };
        sys::Result::SUCCESS
    })
}

/// The l = 0 coefficient of a uniform radiance of 1.
const UNIFORM_SH0: f32 = 3.544_908; // sqrt(4 pi)

/// `xrGetLightEstimationSphericalHarmonicsML`: the uniform ambient light.
///
/// # Safety
/// As `xrGetLightEstimationSphericalHarmonicsML`.
pub unsafe extern "system" fn get_spherical_harmonics(
    handle: ml::LightEstimationEstimateML,
    out: *mut ml::LightEstimationSphericalHarmonicsML,
) -> sys::Result {
    guard("xrGetLightEstimationSphericalHarmonicsML", || {
        let Some((_, light, _)) = estimate(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !typed(out.ty, ml::structure_type::SPHERICAL_HARMONICS) {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        out.harmonics_coefficients = [0.0; ml::HARMONICS_COEFFICIENTS];
        out.harmonics_coefficients[..3].fill(light.ambient * UNIFORM_SH0);
        sys::Result::SUCCESS
    })
}

/// The direction a cube map texel looks: face `face` (+x, -x, +y, -y, +z, -z), at `uv` in
/// 0..1 across it (u right, v down, as Vulkan lays the faces out).
pub fn cube_direction(face: usize, uv: Vec2) -> Vec3 {
    let (s, t) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    match face {
        0 => Vec3::new(1.0, -t, -s),
        1 => Vec3::new(-1.0, -t, s),
        2 => Vec3::new(s, 1.0, t),
        3 => Vec3::new(s, -1.0, -t),
        4 => Vec3::new(s, -t, 1.0),
        _ => Vec3::new(-s, -t, -1.0),
    }
    .normalize()
}

/// The cube map of `light` with its main light travelling along `direction`: RGBA floats,
/// `side` texels a face.
pub fn cube_map(light: &SimLight, direction: Vec3, side: u32) -> Vec<f32> {
    let toward = -direction.normalize();
    let cos_radius = LIGHT_RADIUS_DEG.to_radians().cos();
    let mut out = Vec::with_capacity(6 * (side * side) as usize * 4);
    for face in 0..6 {
        for y in 0..side {
            for x in 0..side {
                let uv = Vec2::new(
                    (x as f32 + 0.5) / side as f32,
                    (y as f32 + 0.5) / side as f32,
                );
                let mut c = Vec3::splat(light.ambient);
                if cube_direction(face, uv).dot(toward) >= cos_radius {
                    c += light.color;
                }
                out.extend_from_slice(&[c.x, c.y, c.z, 1.0]);
            }
        }
    }
    out
}

/// `xrGetLightEstimationHDRCubemapML` (two-call idiom over the floats).
///
/// # Safety
/// As `xrGetLightEstimationHDRCubemapML`.
pub unsafe extern "system" fn get_hdr_cubemap(
    handle: ml::LightEstimationEstimateML,
    out: *mut ml::LightEstimationHdrCubemapML,
) -> sys::Result {
    guard("xrGetLightEstimationHDRCubemapML", || {
        let Some((e, light, side)) = estimate(handle) else {
            return sys::Result::ERROR_HANDLE_INVALID;
        };
        // SAFETY: the app's output, null or writable.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        if !typed(out.ty, ml::structure_type::HDR_CUBEMAP) {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let count = 6 * side * side * 4;
        out.pixel_count_output = count;
        out.face_dim = side;
        if out.pixel_count_input == 0 {
            return sys::Result::SUCCESS;
        }
        if out.pixel_count_input < count {
            return sys::Result::ERROR_SIZE_INSUFFICIENT;
        }
        if out.pixels.is_null() {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        let map = cube_map(&light, e.direction, side);
        // SAFETY: the app's array of at least `pixel_count_input` >= `count` floats.
        unsafe { std::ptr::copy_nonoverlapping(map.as_ptr(), out.pixels, map.len()) };
        sys::Result::SUCCESS
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use openxr::sys::Handle;

    fn light() -> SimLight {
        SimLight {
            direction: Vec3::new(0.0, -1.0, -1.0).normalize(),
            color: Vec3::new(4.0, 3.0, 2.0),
            ambient: 0.5,
            turn: Some((30.0, 2.0)),
        }
    }

    #[test]
    fn the_estimate_updates_when_made_and_when_the_light_turns() {
        let e = EstimationState {
            session: 1,
            base_space: sys::Space::NULL,
            anchor: vitreous_trace::Pose::IDENTITY,
            made_ns: 1_000,
            face_side: 64,
        };
        assert_eq!(last_update_ns(&light(), &e, 1_000), 1_000);
        assert_eq!(last_update_ns(&light(), &e, 1_999_999_999), 1_000);
        assert_eq!(last_update_ns(&light(), &e, 2_000_001_000), 2_000_001_000);
        assert_eq!(last_update_ns(&light(), &e, 9_000_000_000), 2_000_001_000);
    }

    #[test]
    fn the_cube_faces_cover_the_sphere_and_the_light_shows_where_it_comes_from() {
        // Each face's centre looks along its axis.
        let axes = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        for (face, axis) in axes.iter().enumerate() {
            let d = cube_direction(face, Vec2::splat(0.5));
            assert!((d - *axis).length() < 1e-6, "face {face}: {d}");
        }
        let l = light();
        let side = 32;
        let map = cube_map(&l, l.direction, side);
        assert_eq!(map.len(), (6 * side * side * 4) as usize);
        // The brightest texels look back along the light; the rest are the ambient.
        let texel = |i: usize| Vec3::new(map[4 * i], map[4 * i + 1], map[4 * i + 2]);
        let n = (side * side) as usize;
        let mut lit = Vec3::ZERO;
        let mut count = 0;
        for i in 0..6 * n {
            let (face, j) = (i / n, i % n);
            let uv = Vec2::new(
                ((j as u32 % side) as f32 + 0.5) / side as f32,
                ((j as u32 / side) as f32 + 0.5) / side as f32,
            );
            if texel(i).x > 1.0 {
                lit += cube_direction(face, uv);
                count += 1;
            } else {
                assert_eq!(texel(i), Vec3::splat(0.5));
            }
        }
        assert!(count > 0);
        let mean = lit.normalize();
        assert!(
            mean.angle_between(-l.direction).to_degrees() < 1.0,
            "{mean}"
        );
    }
}
