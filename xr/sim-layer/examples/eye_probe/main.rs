//! Drives the simulated headset's three eye extensions through the OpenXR loader in a headless
//! session (`XR_MND_headless`, which Monado offers), without Vulkan, and prints what each
//! answers: the calls `tools/monado/sim-headset` does not reach through `vitreous run`. Frames
//! are only waited for (Monado refuses `xrBeginFrame` in a headless session), so the blend
//! substitution and the submitted-frames CSV are not exercised here.
//!
//! ```sh
//! VITREOUS_SIM_TRACE=gaze.trace cargo run -p vitreous-sim-layer --example eye_probe -- 30
//! ```
//!
//! The argument is the number of frames (default 30). Exits with status 1, naming the call,
//! when a call fails or an answer is not what the layer promises. When the layer offers
//! XR_ML_light_estimation (`VITREOUS_SIM_LIGHT`), its calls are probed too ([`light`]).

mod light;
mod spec;

use std::ffi::c_void;
use std::process::ExitCode;

use openxr as xr;
use xr::sys;
use xr::sys::Handle;

use vitreous_xr::openxr::ml_eye_tracker as ml;

/// A failed check: what and why.
type Probe<T> = Result<T, String>;

/// Turns an OpenXR result into a probe result naming the call.
fn check(call: &str, r: sys::Result) -> Probe<()> {
    if r.into_raw() < 0 {
        Err(format!("{call}: {r:?}"))
    } else {
        Ok(())
    }
}

/// Looks up an extension function.
///
/// # Safety
/// `T` must be the function pointer type OpenXR defines for `name`.
unsafe fn function<T>(instance: &xr::Instance, name: &std::ffi::CStr) -> Probe<T> {
    let mut f: Option<sys::pfn::VoidFunction> = None;
    // SAFETY: the instance is live; `name` is NUL-terminated; `f` is writable.
    let r = unsafe {
        (instance.entry().fp().get_instance_proc_addr)(instance.as_raw(), name.as_ptr(), &mut f)
    };
    check(
        &format!("xrGetInstanceProcAddr({})", name.to_string_lossy()),
        r,
    )?;
    let f = f.ok_or_else(|| format!("{} is null", name.to_string_lossy()))?;
    // SAFETY: guaranteed by the caller: `T` is this function's pointer type.
    Ok(unsafe { std::mem::transmute_copy::<sys::pfn::VoidFunction, T>(&f) })
}

fn main() -> ExitCode {
    let frames: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(30);
    match probe(frames) {
        Ok(()) => {
            println!("eye_probe: PASS");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("eye_probe: FAIL: {e}");
            ExitCode::FAILURE
        }
    }
}

fn probe(frames: u32) -> Probe<()> {
    // SAFETY: loading the system's OpenXR loader library.
    let entry = unsafe { xr::Entry::load(&()) }.map_err(|e| format!("loading the loader: {e}"))?;
    let mut exts = xr::ExtensionSet::default();
    exts.mnd_headless = true;
    // "Now" as an XrTime: Monado's headless session leaves xrWaitFrame's predicted display time
    // unwritten (below).
    exts.khr_convert_timespec_time = true;
    exts.fb_eye_tracking_social = true;
    exts.ext_eye_gaze_interaction = true;
    // `other` names go to the loader as they are: NUL-terminated.
    let nul = |name: &str| [name.as_bytes(), &[0]].concat();
    exts.other = vec![nul(ml::EXTENSION_NAME)];
    let light_name = vitreous_xr::openxr::ml_light_estimation::EXTENSION_NAME;
    let offered = entry
        .enumerate_extensions()
        .map_err(|e| format!("xrEnumerateInstanceExtensionProperties: {e}"))?;
    let light_config = match std::env::var("VITREOUS_SIM_LIGHT") {
        Ok(v) if !v.trim().is_empty() => {
            Some(vitreous_sim_layer::config::parse_light(&v).map_err(|e| e.to_string())?)
        }
        _ => None,
    };
    let probe_light = light_config.is_some()
        && offered
            .other
            .iter()
            .any(|n| n.strip_suffix(&[0]).unwrap_or(n) == light_name.as_bytes());
    if probe_light {
        exts.other.push(nul(light_name));
    }
    let instance = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "eye_probe",
                application_version: 1,
                engine_name: "vitreous",
                engine_version: 1,
                api_version: xr::Version::new(1, 0, 0),
            },
            &exts,
            &[],
            &(),
        )
        .map_err(|e| format!("xrCreateInstance: {e}"))?;
    let system = instance
        .system(xr::FormFactor::HEAD_MOUNTED_DISPLAY)
        .map_err(|e| format!("xrGetSystem: {e}"))?;

    // System properties with all three structures chained.
    let mut ml_props = ml::SystemEyeTrackerPropertiesML {
        ty: sys::StructureType::from_raw(ml::structure_type::SYSTEM_PROPERTIES),
        next: std::ptr::null_mut(),
        supports_eye_tracking: sys::FALSE,
    };
    let mut fb_props = sys::SystemEyeTrackingPropertiesFB {
        ty: sys::SystemEyeTrackingPropertiesFB::TYPE,
        next: &mut ml_props as *mut _ as *mut c_void,
        supports_eye_tracking: sys::FALSE,
    };
    let mut ext_props = sys::SystemEyeGazeInteractionPropertiesEXT {
        ty: sys::SystemEyeGazeInteractionPropertiesEXT::TYPE,
        next: &mut fb_props as *mut _ as *mut c_void,
        supports_eye_gaze_interaction: sys::FALSE,
    };
    // SAFETY: SystemProperties is plain data; zeroed then typed is a valid output state.
    let mut props: sys::SystemProperties = unsafe { std::mem::zeroed() };
    props.ty = sys::SystemProperties::TYPE;
    props.next = &mut ext_props as *mut _ as *mut c_void;
    // SAFETY: the chain of valid output structures lives across the call.
    let r = unsafe { (instance.fp().get_system_properties)(instance.as_raw(), system, &mut props) };
    check("xrGetSystemProperties", r)?;
    println!(
        "system properties: EXT supportsEyeGazeInteraction={} FB supportsEyeTracking={} ML supportsEyeTracking={}",
        ext_props.supports_eye_gaze_interaction.into_raw(),
        fb_props.supports_eye_tracking.into_raw(),
        ml_props.supports_eye_tracking.into_raw()
    );
    if [
        ext_props.supports_eye_gaze_interaction,
        fb_props.supports_eye_tracking,
        ml_props.supports_eye_tracking,
    ] != [sys::TRUE; 3]
    {
        return Err("a system property does not say the system has eye tracking".into());
    }
    let modes = instance
        .enumerate_environment_blend_modes(system, xr::ViewConfigurationType::PRIMARY_STEREO)
        .map_err(|e| format!("xrEnumerateEnvironmentBlendModes: {e}"))?;
    println!("blend modes: {modes:?}");

    // SAFETY: a headless session needs no graphics binding.
    // Monado refuses xrBeginFrame in a headless session, so the probe only waits for frames.
    let (session, _waiter, _stream) = unsafe {
        instance.create_session::<xr::Headless>(system, &xr::headless::SessionCreateInfo {})
    }
    .map_err(|e| format!("xrCreateSession: {e}"))?;
    let view = session
        .create_reference_space(xr::ReferenceSpaceType::VIEW, xr::Posef::IDENTITY)
        .map_err(|e| format!("xrCreateReferenceSpace: {e}"))?;
    let local = session
        .create_reference_space(xr::ReferenceSpaceType::LOCAL, xr::Posef::IDENTITY)
        .map_err(|e| format!("xrCreateReferenceSpace: {e}"))?;

    // SAFETY: the function types are the ML extension's, as declared in `ml`.
    let (create_ml, destroy_ml, static_ml, poses_ml, pupil_ml, geometric_ml, behavior_ml) = unsafe {
        (
            function::<ml::CreateEyeTrackerML>(&instance, c"xrCreateEyeTrackerML")?,
            function::<ml::DestroyEyeTrackerML>(&instance, c"xrDestroyEyeTrackerML")?,
            function::<ml::GetEyeTrackerStaticDataML>(&instance, c"xrGetEyeTrackerStaticDataML")?,
            function::<ml::GetEyeTrackerPosesML>(&instance, c"xrGetEyeTrackerPosesML")?,
            function::<ml::GetEyeTrackerPupilDataML>(&instance, c"xrGetEyeTrackerPupilDataML")?,
            function::<ml::GetEyeTrackerGeometricDataML>(
                &instance,
                c"xrGetEyeTrackerGeometricDataML",
            )?,
            function::<ml::GetEyeTrackerGazeBehaviorML>(
                &instance,
                c"xrGetEyeTrackerGazeBehaviorML",
            )?,
        )
    };
    let fb = instance
        .exts()
        .fb_eye_tracking_social
        .ok_or("XR_FB_eye_tracking_social functions missing")?;

    let create_info = ml::EyeTrackerCreateInfoML {
        ty: sys::StructureType::from_raw(ml::structure_type::CREATE_INFO),
        next: std::ptr::null(),
    };
    let mut ml_tracker = ml::EyeTrackerML::NULL;
    // SAFETY: live session, valid create info and output.
    check("xrCreateEyeTrackerML", unsafe {
        create_ml(session.as_raw(), &create_info, &mut ml_tracker)
    })?;
    let fb_info = sys::EyeTrackerCreateInfoFB {
        ty: sys::EyeTrackerCreateInfoFB::TYPE,
        next: std::ptr::null(),
    };
    let mut fb_tracker = sys::EyeTrackerFB::NULL;
    // SAFETY: live session, valid create info and output.
    check("xrCreateEyeTrackerFB", unsafe {
        (fb.create_eye_tracker)(session.as_raw(), &fb_info, &mut fb_tracker)
    })?;
    println!(
        "trackers: ML {:#x}, FB {:#x}",
        ml_tracker.0,
        fb_tracker.into_raw()
    );
    let gaze = spec::before_frames(&instance, session.as_raw())?;
    let mut located = false;
    let mut static_data = ml::EyeTrackerStaticDataML {
        ty: sys::StructureType::from_raw(ml::structure_type::STATIC_DATA),
        next: std::ptr::null_mut(),
        eye_width_max: 0.0,
        eye_height_max: 0.0,
    };
    let static_info = ml::EyeTrackerGetInfoML {
        ty: sys::StructureType::from_raw(ml::structure_type::STATIC_DATA_GET_INFO),
        next: std::ptr::null(),
    };
    // SAFETY: live tracker, valid structures.
    check("xrGetEyeTrackerStaticDataML", unsafe {
        static_ml(ml_tracker, &static_info, &mut static_data)
    })?;

    let mut running = false;
    let mut ended = 0u32;
    let mut buffer = xr::EventDataBuffer::new();
    let mut fixation_seen = 0u32;
    let mut last_time = None;
    while ended < frames {
        while let Some(event) = instance
            .poll_event(&mut buffer)
            .map_err(|e| format!("xrPollEvent: {e}"))?
        {
            if let xr::Event::SessionStateChanged(e) = event {
                match e.state() {
                    xr::SessionState::READY => {
                        session
                            .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
                            .map_err(|e| format!("xrBeginSession: {e}"))?;
                        running = true;
                    }
                    xr::SessionState::STOPPING | xr::SessionState::EXITING => {
                        return Err(format!("the session stopped early ({:?})", e.state()));
                    }
                    _ => {}
                }
            }
        }
        if !running {
            std::thread::sleep(std::time::Duration::from_millis(10));
            continue;
        }
        // Monado's headless session returns from xrWaitFrame without writing the predicted
        // display time: the state starts at "now", so the layer (which records the time the
        // runtime hands back) and the probe see a real time rather than whatever the memory
        // held.
        let mut state = sys::FrameState {
            ty: sys::FrameState::TYPE,
            next: std::ptr::null_mut(),
            predicted_display_time: instance
                .now()
                .map_err(|e| format!("xrConvertTimespecTimeToTimeKHR: {e}"))?,
            predicted_display_period: sys::Duration::from_nanos(0),
            should_render: sys::FALSE,
        };
        // SAFETY: the live session, no wait info, a valid output structure.
        check("xrWaitFrame", unsafe {
            (instance.fp().wait_frame)(session.as_raw(), std::ptr::null(), &mut state)
        })?;
        let t = state.predicted_display_time;
        last_time = Some(t);
        if !located {
            spec::locate(&instance, &gaze, local.as_raw(), t)?;
            located = true;
        }

        // ML poses in LOCAL.
        let get = ml::EyeTrackerPosesGetInfoML {
            ty: sys::StructureType::from_raw(ml::structure_type::POSES_GET_INFO),
            next: std::ptr::null(),
            base_space: local.as_raw(),
            time: t,
            pose_flags: ml::pose_flags::ALL,
        };
        let mut poses = ml::EyeTrackerPosesML::empty();
        // SAFETY: live tracker, valid structures.
        check("xrGetEyeTrackerPosesML", unsafe {
            poses_ml(ml_tracker, &get, &mut poses)
        })?;
        // Pupils (two calls).
        let pupil_info = ml::EyeTrackerGetInfoML {
            ty: sys::StructureType::from_raw(ml::structure_type::PUPIL_DATA_GET_INFO),
            next: std::ptr::null(),
        };
        let mut n = 0u32;
        // SAFETY: capacity 0 with a null array asks for the count.
        check("xrGetEyeTrackerPupilDataML", unsafe {
            pupil_ml(ml_tracker, &pupil_info, 0, &mut n, std::ptr::null_mut())
        })?;
        let mut pupils = vec![ml::EyeTrackerPupilDataML::empty(); n as usize];
        // SAFETY: `pupils` holds `n` typed elements.
        check("xrGetEyeTrackerPupilDataML", unsafe {
            pupil_ml(ml_tracker, &pupil_info, n, &mut n, pupils.as_mut_ptr())
        })?;
        let geo_info = ml::EyeTrackerGetInfoML {
            ty: sys::StructureType::from_raw(ml::structure_type::GEOMETRIC_DATA_GET_INFO),
            next: std::ptr::null(),
        };
        let mut geo = [ml::EyeTrackerGeometricDataML {
            ty: sys::StructureType::from_raw(ml::structure_type::GEOMETRIC_DATA),
            next: std::ptr::null_mut(),
            eye: ml::EyeML::LEFT,
            time: sys::Time::from_nanos(0),
            valid: sys::FALSE,
            eye_openness: -1.0,
            eye_in_skull_position: sys::Vector2f { x: 0.0, y: 0.0 },
        }; 2];
        let mut g = 0u32;
        // SAFETY: `geo` holds 2 typed elements.
        check("xrGetEyeTrackerGeometricDataML", unsafe {
            geometric_ml(ml_tracker, &geo_info, 2, &mut g, geo.as_mut_ptr())
        })?;
        let behavior_info = ml::EyeTrackerGetInfoML {
            ty: sys::StructureType::from_raw(ml::structure_type::GAZE_BEHAVIOR_GET_INFO),
            next: std::ptr::null(),
        };
        let mut behavior = ml::EyeTrackerGazeBehaviorML {
            ty: sys::StructureType::from_raw(ml::structure_type::GAZE_BEHAVIOR),
            next: std::ptr::null_mut(),
            time: sys::Time::from_nanos(0),
            valid: sys::TRUE,
            gaze_behavior_type: ml::GazeBehaviorTypeML::FIXATION,
            onset_time: sys::Time::from_nanos(0),
            duration: 0,
        };
        // SAFETY: live tracker, valid structures.
        check("xrGetEyeTrackerGazeBehaviorML", unsafe {
            behavior_ml(ml_tracker, &behavior_info, &mut behavior)
        })?;
        // FB gazes in VIEW.
        let fb_get = sys::EyeGazesInfoFB {
            ty: sys::EyeGazesInfoFB::TYPE,
            next: std::ptr::null(),
            base_space: view.as_raw(),
            time: t,
        };
        // SAFETY: EyeGazesFB is plain data; zeroed then typed is a valid output state.
        let mut gazes: sys::EyeGazesFB = unsafe { std::mem::zeroed() };
        gazes.ty = sys::EyeGazesFB::TYPE;
        // SAFETY: live tracker, valid structures.
        check("xrGetEyeGazesFB", unsafe {
            (fb.get_eye_gazes)(fb_tracker, &fb_get, &mut gazes)
        })?;

        let p = poses.fixation_pose;
        if p.valid == sys::TRUE {
            fixation_seen += 1;
        }
        if ended.is_multiple_of(10) {
            println!(
                "frame {ended}: ML gaze valid={} conf={}; left valid={}; fixation valid={} conf={} at ({:.3}, {:.3}, {:.3}) m in LOCAL; pupils {}: {:?}; openness {:.0}/{:.0}; behaviour valid={}; FB left valid={} conf={}",
                poses.gaze_pose.valid.into_raw(),
                poses.gaze_pose.confidence.0,
                poses.left_pose.valid.into_raw(),
                p.valid.into_raw(),
                p.confidence.0,
                p.pose.position.x,
                p.pose.position.y,
                p.pose.position.z,
                n,
                pupils
                    .iter()
                    .map(|d| (d.eye.0, d.valid.into_raw(), d.pupil_diameter))
                    .collect::<Vec<_>>(),
                geo[0].eye_openness,
                geo[1].eye_openness,
                behavior.valid.into_raw(),
                gazes.gaze[0].is_valid.into_raw(),
                gazes.gaze[0].gaze_confidence,
            );
        }
        if n != 2 || g != 2 || behavior.valid != sys::TRUE {
            return Err(
                "pupil/geometric counts or behaviour validity are not as documented".into(),
            );
        }
        ended += 1;
    }
    // SAFETY: the trackers are live and not used afterwards.
    unsafe {
        check("xrDestroyEyeTrackerML", destroy_ml(ml_tracker))?;
        check(
            "xrDestroyEyeTrackerFB",
            (fb.destroy_eye_tracker)(fb_tracker),
        )?;
    }
    println!("fixation valid in {fixation_seen} of {ended} frames");
    match (light_config, last_time) {
        (Some(l), Some(t)) if probe_light => light::checks(
            &instance,
            session.as_raw(),
            local.as_raw(),
            t,
            l.color,
            l.ambient,
        )?,
        (Some(_), _) => {
            return Err(
                "VITREOUS_SIM_LIGHT is set but the layer offers no XR_ML_light_estimation".into(),
            );
        }
        _ => println!("XR_ML_light_estimation not offered (no VITREOUS_SIM_LIGHT): not probed"),
    }
    session
        .request_exit()
        .map_err(|e| format!("xrRequestExitSession: {e}"))?;
    Ok(())
}
