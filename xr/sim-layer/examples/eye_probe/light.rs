//! XR_ML_light_estimation as the layer answers it, where `vitreous run` does not call it: the
//! HDR cube map through the two-call idiom, refused structures and times, and handles used
//! after they were destroyed. Each check prints a `light: ` line.

use glam::{Vec2, Vec3};
use openxr as xr;
use xr::sys;

use super::{Probe, check, function};
use vitreous_xr::openxr::ml_light_estimation as ml;

/// The square root of 4 pi: the l = 0 coefficient of a uniform radiance of 1.
const SQRT_4PI: f32 = 3.544_908;

/// Expects `r` to be `want`.
fn expect(call: &str, r: sys::Result, want: sys::Result) -> Probe<()> {
    if r == want {
        Ok(())
    } else {
        Err(format!("{call}: {r:?}, expected {want:?}"))
    }
}

/// The direction a texel of cube face `face` (+x, -x, +y, -y, +z, -z) looks, at `uv` across
/// it: the Vulkan specification's cube map face selection, inverted.
fn texel_direction(face: usize, uv: Vec2) -> Vec3 {
    let (sc, tc) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    // (major axis, sc, tc) per face: sc = -z, tc = -y on +x; sc = +z, tc = -y on -x;
    // sc = +x, tc = +z on +y; sc = +x, tc = -z on -y; sc = +x, tc = -y on +z; sc = -x,
    // tc = -y on -z.
    match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    }
    .normalize()
}

/// Runs the checks in `base` at `time`; `light` is what `VITREOUS_SIM_LIGHT` configured
/// (direction in the head's level frame, colour, ambient).
pub fn checks(
    instance: &xr::Instance,
    session: sys::Session,
    base: sys::Space,
    time: sys::Time,
    colour: Vec3,
    ambient: f32,
) -> Probe<()> {
    // SAFETY: the function types are the extension's, as declared in `ml`.
    let (
        create,
        destroy,
        state_fn,
        create_estimate,
        destroy_estimate,
        timestamp,
        main_fn,
        sh_fn,
        cube_fn,
    ) = unsafe {
        (
            function::<ml::CreateLightEstimationML>(instance, ml::names::CREATE)?,
            function::<ml::DestroyLightEstimationML>(instance, ml::names::DESTROY)?,
            function::<ml::GetLightEstimationStateML>(instance, ml::names::GET_STATE)?,
            function::<ml::CreateLightEstimationEstimateML>(instance, ml::names::CREATE_ESTIMATE)?,
            function::<ml::DestroyLightEstimationEstimateML>(
                instance,
                ml::names::DESTROY_ESTIMATE,
            )?,
            function::<ml::GetLightEstimationTimestampML>(instance, ml::names::GET_TIMESTAMP)?,
            function::<ml::GetLightEstimationMainDirectionalLightML>(
                instance,
                ml::names::GET_MAIN_DIRECTIONAL_LIGHT,
            )?,
            function::<ml::GetLightEstimationSphericalHarmonicsML>(
                instance,
                ml::names::GET_SPHERICAL_HARMONICS,
            )?,
            function::<ml::GetLightEstimationHdrCubemapML>(instance, ml::names::GET_HDR_CUBEMAP)?,
        )
    };
    let info = |ty: i32, t: sys::Time, resolution: i32| ml::LightEstimationCreateInfoML {
        ty: sys::StructureType::from_raw(ty),
        next: std::ptr::null(),
        base_space: base,
        time: t,
        cubemap_face_resolution: ml::CubemapFaceResolutionML(resolution),
    };
    let ok = ml::structure_type::CREATE_INFO;
    let mut handle = ml::LightEstimationML::default();
    // SAFETY: the live session and space, structures the probe owns for the call's length,
    // writable outputs (so for every call below).
    unsafe {
        expect(
            "xrCreateLightEstimationML with another structure type",
            create(
                session,
                &info(ml::structure_type::STATE, time, 0),
                &mut handle,
            ),
            sys::Result::ERROR_VALIDATION_FAILURE,
        )?;
        expect(
            "xrCreateLightEstimationML at time 0",
            create(session, &info(ok, sys::Time::from_nanos(0), 0), &mut handle),
            sys::Result::ERROR_TIME_INVALID,
        )?;
        expect(
            "xrCreateLightEstimationML with face resolution 7",
            create(session, &info(ok, time, 7), &mut handle),
            sys::Result::ERROR_VALIDATION_FAILURE,
        )?;
    }
    println!("light: a create info of another type, at time 0 or of an unknown face size refused");
    // SAFETY: as above.
    check("xrCreateLightEstimationML", unsafe {
        create(
            session,
            &info(ok, time, ml::CubemapFaceResolutionML::R128.0),
            &mut handle,
        )
    })?;
    let mut state = ml::LightEstimationStateML {
        ty: sys::StructureType::from_raw(ml::structure_type::STATE),
        next: std::ptr::null_mut(),
        last_update: sys::Time::from_nanos(0),
    };
    // SAFETY: as above.
    check("xrGetLightEstimationStateML", unsafe {
        state_fn(handle, &mut state)
    })?;
    if state.last_update.as_nanos() != time.as_nanos() {
        return Err(format!(
            "the estimate's last update is {} ns, expected its making at {} ns",
            state.last_update.as_nanos(),
            time.as_nanos()
        ));
    }
    let mut estimate = ml::LightEstimationEstimateML::default();
    // SAFETY: as above.
    check("xrCreateLightEstimationEstimateML", unsafe {
        create_estimate(handle, &mut estimate)
    })?;
    let mut main = ml::LightEstimationMainDirectionalLightML {
        ty: sys::StructureType::from_raw(ml::structure_type::MAIN_DIRECTIONAL_LIGHT),
        next: std::ptr::null_mut(),
        direction: sys::Vector3f::default(),
        color: sys::Color4f::default(),
    };
    let mut sh = ml::LightEstimationSphericalHarmonicsML {
        ty: sys::StructureType::from_raw(ml::structure_type::SPHERICAL_HARMONICS),
        next: std::ptr::null_mut(),
        harmonics_coefficients: [f32::NAN; ml::HARMONICS_COEFFICIENTS],
    };
    let mut when = sys::Time::from_nanos(0);
    // SAFETY: as above.
    unsafe {
        check(
            "xrGetLightEstimationMainDirectionalLightML",
            main_fn(estimate, &mut main),
        )?;
        check(
            "xrGetLightEstimationSphericalHarmonicsML",
            sh_fn(estimate, &mut sh),
        )?;
        check(
            "xrGetLightEstimationTimestampML",
            timestamp(estimate, &mut when),
        )?;
    }
    let direction = Vec3::new(main.direction.x, main.direction.y, main.direction.z);
    let got_colour = Vec3::new(main.color.r, main.color.g, main.color.b);
    let c = &sh.harmonics_coefficients;
    if (direction.length() - 1.0).abs() > 1e-5
        || (got_colour - colour).abs().max_element() > 1e-6
        || c[..3].iter().any(|v| (v - ambient * SQRT_4PI).abs() > 1e-5)
        || c[3..].iter().any(|v| *v != 0.0)
        || when.as_nanos() != time.as_nanos()
    {
        return Err(format!(
            "the estimate: direction {direction} (unit?), colour {got_colour} (configured \
             {colour}), harmonics {c:?} (a uniform {ambient} has only the first three), time \
             {} ns",
            when.as_nanos()
        ));
    }
    println!(
        "light: the estimate's main light travels along ({:.3}, {:.3}, {:.3}), colour and \
         uniform ambient as configured",
        direction.x, direction.y, direction.z
    );

    // The cube map, two calls: the count, then the floats (a short array refused).
    let mut cube = ml::LightEstimationHdrCubemapML {
        ty: sys::StructureType::from_raw(ml::structure_type::HDR_CUBEMAP),
        next: std::ptr::null_mut(),
        pixel_count_input: 0,
        pixel_count_output: 0,
        pixels: std::ptr::null_mut(),
        face_dim: 0,
    };
    // SAFETY: capacity 0 with a null array asks for the count.
    check("xrGetLightEstimationHDRCubemapML", unsafe {
        cube_fn(estimate, &mut cube)
    })?;
    let side = cube.face_dim;
    let count = cube.pixel_count_output;
    if side != 128 || count != 6 * 128 * 128 * 4 {
        return Err(format!(
            "the cube map is {count} floats of faces {side} texels, expected 6 x 128 x 128 RGBA"
        ));
    }
    let mut floats = vec![f32::NAN; count as usize];
    cube.pixel_count_input = count - 1;
    cube.pixels = floats.as_mut_ptr();
    // SAFETY: `floats` holds more than `pixel_count_input` floats.
    let short = unsafe { cube_fn(estimate, &mut cube) };
    expect(
        "xrGetLightEstimationHDRCubemapML with one float too few",
        short,
        sys::Result::ERROR_SIZE_INSUFFICIENT,
    )?;
    cube.pixel_count_input = count;
    // SAFETY: `floats` holds `count` floats.
    check("xrGetLightEstimationHDRCubemapML", unsafe {
        cube_fn(estimate, &mut cube)
    })?;
    // The texels brighter than the ambient look back towards the light.
    let n = (side * side) as usize;
    let mut towards = Vec3::ZERO;
    for i in 0..6 * n {
        let (face, j) = (i / n, i % n);
        let rgb = Vec3::new(floats[4 * i], floats[4 * i + 1], floats[4 * i + 2]);
        if !rgb.is_finite() || rgb.min_element() < ambient - 1e-6 {
            return Err(format!(
                "cube map texel {i} is {rgb}, below the ambient {ambient}"
            ));
        }
        if rgb.x > ambient + 1e-6 {
            let uv = Vec2::new(
                ((j as u32 % side) as f32 + 0.5) / side as f32,
                ((j as u32 / side) as f32 + 0.5) / side as f32,
            );
            towards += texel_direction(face, uv);
        }
    }
    let off = towards
        .normalize_or_zero()
        .angle_between(-direction)
        .to_degrees();
    if off.is_nan() || off >= 1.0 {
        return Err(format!(
            "the cube map's light is {off:.2} degrees from where the main light comes from"
        ));
    }
    println!(
        "light: the cube map ({count} floats, faces {side}) through two calls, one float short \
         refused; its light {off:.2} degrees from the main light's"
    );

    // Destroyed handles are refused; the estimation takes its estimates with it.
    // SAFETY: the handles the probe made, used once more after destruction on purpose (the
    // layer answers for its own handles).
    unsafe {
        check(
            "xrDestroyLightEstimationEstimateML",
            destroy_estimate(estimate),
        )?;
        expect(
            "xrGetLightEstimationTimestampML on a destroyed estimate",
            timestamp(estimate, &mut when),
            sys::Result::ERROR_HANDLE_INVALID,
        )?;
        let mut second = ml::LightEstimationEstimateML::default();
        check(
            "xrCreateLightEstimationEstimateML",
            create_estimate(handle, &mut second),
        )?;
        check("xrDestroyLightEstimationML", destroy(handle))?;
        expect(
            "xrGetLightEstimationMainDirectionalLightML on an estimate of a destroyed estimation",
            main_fn(second, &mut main),
            sys::Result::ERROR_HANDLE_INVALID,
        )?;
        expect(
            "xrGetLightEstimationStateML on a destroyed estimation",
            state_fn(handle, &mut state),
            sys::Result::ERROR_HANDLE_INVALID,
        )?;
    }
    println!(
        "light: destroyed estimations and estimates refused, an estimation's estimates gone with it"
    );
    Ok(())
}
