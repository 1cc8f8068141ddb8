//! The loader interface: `xrNegotiateLoaderApiLayerInterface` (the library's one exported
//! symbol), `xrCreateApiLayerInstance` and the layer's `xrGetInstanceProcAddr`.

use std::collections::{HashMap, HashSet};
use std::ffi::{CStr, c_char};
use std::sync::{Arc, Mutex};

use openxr::sys::{self, pfn};

use crate::bindings::{self, GazePaths};
use crate::config::{BUTTONS_VAR, Config, GazeExtension, TRACE_VAR};
use crate::controller::{ButtonScript, Buttons, HANDS};
use crate::extensions;
use crate::functions::{light_function, own_function, plane_function};
use crate::guard::{guard, report};
use crate::next::NextTable;
use crate::registry::{InstanceState, registry};
use crate::submitted::SubmittedLog;
use crate::timeline::GazeTimeline;

/// The layer's name, as its manifest gives it.
pub const LAYER_NAME: &CStr = c"XR_APILAYER_VITREOUS_simulated_ost";

/// The loader calls this first, to agree on the interface version and learn the layer's
/// `xrGetInstanceProcAddr` and `xrCreateApiLayerInstance`.
///
/// # Safety
/// `loader_info` and `request` must be null or point to valid structures of their types;
/// `layer_name` must be null or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "system" fn xrNegotiateLoaderApiLayerInterface(
    loader_info: *const sys::NegotiateLoaderInfo,
    layer_name: *const c_char,
    request: *mut sys::NegotiateApiLayerRequest,
) -> sys::Result {
    guard("xrNegotiateLoaderApiLayerInterface", || {
        // SAFETY: the caller guarantees both are null or valid.
        let (Some(info), Some(request)) =
            (unsafe { loader_info.as_ref() }, unsafe { request.as_mut() })
        else {
            return sys::Result::ERROR_INITIALIZATION_FAILED;
        };
        if !layer_name.is_null() {
            // SAFETY: the caller guarantees a NUL-terminated string.
            let name = unsafe { CStr::from_ptr(layer_name) };
            if name != LAYER_NAME {
                report(format!(
                    "asked to load as {:?}; this library is {:?}",
                    name, LAYER_NAME
                ));
                return sys::Result::ERROR_INITIALIZATION_FAILED;
            }
        }
        let interface = sys::CURRENT_LOADER_API_LAYER_VERSION as u32;
        if info.struct_type != sys::LoaderInterfaceStructs::LOADER_INFO
            || info.struct_version != sys::NegotiateLoaderInfo::VERSION
            || info.struct_size != std::mem::size_of::<sys::NegotiateLoaderInfo>()
            || request.struct_type != sys::LoaderInterfaceStructs::API_LAYER_REQUEST
            || request.struct_version != sys::NegotiateApiLayerRequest::VERSION
            || request.struct_size != std::mem::size_of::<sys::NegotiateApiLayerRequest>()
            || info.min_interface_version > interface
            || info.max_interface_version < interface
        {
            report("the loader's negotiation structures are not the version this layer knows");
            return sys::Result::ERROR_INITIALIZATION_FAILED;
        }
        request.layer_interface_version = interface;
        request.layer_api_version =
            if sys::CURRENT_API_VERSION.into_raw() <= info.max_api_version.into_raw() {
                sys::CURRENT_API_VERSION
            } else {
                info.max_api_version
            };
        request.get_instance_proc_addr = Some(get_instance_proc_addr);
        request.create_api_layer_instance = Some(create_api_layer_instance);
        sys::Result::SUCCESS
    })
}

/// What instance creation needs from the environment, or the message and result to fail with.
struct Prepared {
    /// The configuration.
    config: Config,
    /// The trace's eye data (when an eye extension is offered).
    timeline: Option<GazeTimeline>,
    /// The submitted-frames CSV (the process's).
    submitted: Option<Arc<Mutex<SubmittedLog>>>,
    /// The controller button script.
    buttons: Option<ButtonScript>,
}

/// Reads the configuration, the trace and opens the CSV.
fn prepare() -> Result<Prepared, String> {
    let config = Config::from_env().map_err(|e| e.to_string())?;
    let timeline = if config.gaze.is_empty() {
        None
    } else {
        let Some(path) = &config.trace else {
            return Err(format!(
                "{TRACE_VAR} is not set: it must name the trace (v1) the eye data comes from"
            ));
        };
        let samples =
            vitreous_trace::read_trace(path).map_err(|e| format!("reading {TRACE_VAR}: {e}"))?;
        let timeline = GazeTimeline::new(&samples)
            .ok_or_else(|| format!("{TRACE_VAR}: {} has no samples", path.display()))?;
        Some(if config.trace_loop {
            timeline.looped()
        } else {
            timeline
        })
    };
    let submitted = match &config.submitted {
        None => None,
        Some(path) => Some(SubmittedLog::shared(path).map_err(|e| {
            format!(
                "{}: creating {}: {e}",
                crate::config::SUBMITTED_VAR,
                path.display()
            )
        })?),
    };
    crate::faults::install(config.faults.as_deref(), config.fault_log.as_deref())?;
    let buttons = match &config.buttons {
        None => None,
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("{BUTTONS_VAR}: reading {}: {e}", path.display()))?;
            Some(
                ButtonScript::parse(&text)
                    .map_err(|e| format!("{BUTTONS_VAR}: {}: {e}", path.display()))?,
            )
        }
    };
    Ok(Prepared {
        config,
        timeline,
        submitted,
        buttons,
    })
}

/// The instance-creation call of the layer chain: removes the layer's extensions from the
/// create info, creates the instance below, and sets up the layer's state for it.
///
/// # Safety
/// The pointers must be valid as the loader interface defines them.
unsafe extern "system" fn create_api_layer_instance(
    info: *const sys::InstanceCreateInfo,
    layer_info: *const sys::ApiLayerCreateInfo,
    instance: *mut sys::Instance,
) -> sys::Result {
    guard("xrCreateApiLayerInstance", || {
        // SAFETY: the loader passes valid structures or null.
        let (Some(info), Some(layer_info)) =
            (unsafe { info.as_ref() }, unsafe { layer_info.as_ref() })
        else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        // SAFETY: as above; `next_info` is this layer's entry in the chain.
        let Some(next_info) = (unsafe { layer_info.next_info.as_ref() }) else {
            return sys::Result::ERROR_INITIALIZATION_FAILED;
        };
        let (Some(next_gipa), Some(next_create)) = (
            next_info.next_get_instance_proc_addr,
            next_info.next_create_api_layer_instance,
        ) else {
            return sys::Result::ERROR_INITIALIZATION_FAILED;
        };

        // The runtime away after an instance loss (the fault schedule's outage).
        if let Some(Some(r)) = crate::faults::with(|f| f.create_instance(std::time::Instant::now()))
        {
            return r;
        }
        let prepared = match prepare() {
            Ok(p) => p,
            Err(message) => {
                report(message);
                return sys::Result::ERROR_INITIALIZATION_FAILED;
            }
        };

        let names: Vec<&CStr> = (0..info.enabled_extension_count as usize)
            .filter_map(|i| {
                // SAFETY: the app's array holds `enabled_extension_count` pointers to
                // NUL-terminated names (xrCreateInstance's valid usage).
                let p = unsafe { *info.enabled_extension_names.add(i) };
                // SAFETY: as above.
                (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) })
            })
            .collect();
        let split = extensions::split(
            &names,
            &prepared.config.gaze,
            prepared.config.ml_frame,
            !prepared.config.planes.is_empty(),
            prepared.config.light.is_some(),
        );
        // The layer's extensions it does not offer go on to the runtime, which may have them
        // (Monado lists XR_EXT_eye_gaze_interaction) or refuses them.
        let forwarded: Vec<*const c_char> = split.forwarded.iter().map(|n| n.as_ptr()).collect();
        let mut next_create_info = *info;
        next_create_info.enabled_extension_count = forwarded.len() as u32;
        next_create_info.enabled_extension_names = if forwarded.is_empty() {
            std::ptr::null()
        } else {
            forwarded.as_ptr()
        };
        let mut next_layer_info = *layer_info;
        next_layer_info.next_info = next_info.next;

        // SAFETY: the create infos are valid copies of the app's with a shorter extension
        // list that lives across the call; `instance` is the app's output pointer.
        let r = unsafe { next_create(&next_create_info, &next_layer_info, instance) };
        if r.into_raw() < 0 {
            return r;
        }
        // SAFETY: on success the next layer wrote the new instance.
        let created = unsafe { *instance };
        // SAFETY: `next_gipa` is the next layer's and `created` is live.
        let next = match unsafe { NextTable::load(next_gipa, created) } {
            Ok(n) => n,
            Err(message) => {
                report(message);
                // SAFETY: undoing the creation above: the next layer's own destroy function.
                let destroy = unsafe { lookup_destroy(next_gipa, created) };
                if let Some(destroy) = destroy {
                    // SAFETY: `created` is live and not used afterwards.
                    unsafe { destroy(created) };
                }
                return sys::Result::ERROR_INITIALIZATION_FAILED;
            }
        };
        let gaze_paths = if split.owned.contains(&GazeExtension::Ext) {
            match gaze_paths(&next, created) {
                Ok(p) => Some(p),
                Err(r) => {
                    report(format!(
                        "xrStringToPath for the eye-gaze profile failed: {r:?}"
                    ));
                    // SAFETY: `created` is live and not used afterwards.
                    unsafe { (next.destroy_instance)(created) };
                    return sys::Result::ERROR_INITIALIZATION_FAILED;
                }
            }
        } else {
            None
        };
        let buttons = match prepared.buttons.map(|s| buttons(&next, created, s)) {
            None => None,
            Some(Ok(b)) => Some(Arc::new(b)),
            Some(Err(message)) => {
                report(message);
                // SAFETY: `created` is live and not used afterwards.
                unsafe { (next.destroy_instance)(created) };
                return sys::Result::ERROR_INITIALIZATION_FAILED;
            }
        };
        let state = InstanceState {
            next: Arc::new(next),
            config: Arc::new(prepared.config),
            owned: split.owned,
            timeline: prepared.timeline.map(Arc::new),
            gaze_paths,
            gaze_actions: HashSet::new(),
            submitted: prepared.submitted,
            buttons,
            button_actions: HashMap::new(),
            attached: false,
            planes: split.planes,
            light: split.light,
        };
        registry()
            .instances
            .insert(sys::Handle::into_raw(created), state);
        r
    })
}

/// The next layer's `xrDestroyInstance`, to undo a creation the layer cannot finish.
///
/// # Safety
/// As [`NextTable::load`].
unsafe fn lookup_destroy(
    gipa: pfn::GetInstanceProcAddr,
    instance: sys::Instance,
) -> Option<pfn::DestroyInstance> {
    let mut f: Option<pfn::VoidFunction> = None;
    // SAFETY: guaranteed by the caller.
    unsafe { gipa(instance, c"xrDestroyInstance".as_ptr(), &mut f) };
    // SAFETY: the function of that name has that signature.
    f.map(|f| unsafe { std::mem::transmute::<pfn::VoidFunction, pfn::DestroyInstance>(f) })
}

/// `s` as a path of `instance`.
fn string_to_path(
    next: &NextTable,
    instance: sys::Instance,
    s: &CStr,
) -> Result<sys::Path, sys::Result> {
    let mut p = sys::Path::NULL;
    // SAFETY: `instance` is live; `s` is NUL-terminated; `p` is writable.
    let r = unsafe { (next.string_to_path)(instance, s.as_ptr(), &mut p) };
    if r == sys::Result::SUCCESS {
        Ok(p)
    } else {
        Err(r)
    }
}

/// The eye-gaze profile's paths in a new instance.
fn gaze_paths(next: &NextTable, instance: sys::Instance) -> Result<GazePaths, sys::Result> {
    Ok(GazePaths {
        profile: string_to_path(next, instance, bindings::PROFILE)?,
        pose: string_to_path(next, instance, bindings::POSE)?,
        user: string_to_path(next, instance, bindings::USER)?,
    })
}

/// The button script's paths in a new instance.
fn buttons(
    next: &NextTable,
    instance: sys::Instance,
    script: ButtonScript,
) -> Result<Buttons, String> {
    let path = |s: &str| {
        let c = std::ffi::CString::new(s).map_err(|_| format!("{BUTTONS_VAR}: a NUL in {s:?}"))?;
        string_to_path(next, instance, &c)
            .map_err(|r| format!("{BUTTONS_VAR}: xrStringToPath({s:?}) failed: {r:?}"))
    };
    Ok(Buttons {
        profile: path(&script.profile)?,
        inputs: script
            .inputs
            .iter()
            .map(|s| path(s))
            .collect::<Result<_, _>>()?,
        hands: [path(HANDS[0])?, path(HANDS[1])?],
        script,
    })
}

/// The layer's `xrGetInstanceProcAddr`: its own functions (extension functions only when the
/// app enabled the extension), everything else from the next layer.
///
/// # Safety
/// `name` must be a NUL-terminated string and `function` null or writable.
unsafe extern "system" fn get_instance_proc_addr(
    instance: sys::Instance,
    name: *const c_char,
    function: *mut Option<pfn::VoidFunction>,
) -> sys::Result {
    guard("xrGetInstanceProcAddr", || {
        // SAFETY: the caller guarantees `function` is null or writable.
        let Some(function) = (unsafe { function.as_mut() }) else {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        };
        *function = None;
        if name.is_null() {
            return sys::Result::ERROR_VALIDATION_FAILURE;
        }
        // SAFETY: the caller guarantees a NUL-terminated string.
        let name_c = unsafe { CStr::from_ptr(name) };
        let name_bytes = name_c.to_bytes();
        if name_bytes == b"xrGetInstanceProcAddr" {
            let own: pfn::GetInstanceProcAddr = get_instance_proc_addr;
            // SAFETY: function pointers have one size; the caller casts it back to
            // `PFN_xrGetInstanceProcAddr`, the type of the name it asked for.
            *function = Some(unsafe {
                std::mem::transmute::<pfn::GetInstanceProcAddr, pfn::VoidFunction>(own)
            });
            return sys::Result::SUCCESS;
        }
        // Per instance: the eye extensions the app enabled from the layer and those it offers,
        // whether the app enabled (and the layer offers) plane detection and light estimation,
        // and the next layer.
        let (owned, offered, planes, light, next) = {
            let reg = registry();
            match reg.instances.get(&sys::Handle::into_raw(instance)) {
                Some(i) => (
                    i.owned.clone(),
                    i.config.gaze.clone(),
                    (i.planes, !i.config.planes.is_empty()),
                    (i.light, i.config.light.is_some()),
                    Some(i.next.get_instance_proc_addr),
                ),
                None => (Vec::new(), Vec::new(), (false, false), (false, false), None),
            }
        };
        // XR_EXT_plane_detection's and XR_ML_light_estimation's functions: the layer's when
        // the app enabled the extension from it; refused when the layer offers it and the app
        // did not enable it; else the runtime's.
        for (f, (enabled, offers)) in [
            (plane_function(name_bytes), planes),
            (light_function(name_bytes), light),
        ] {
            let Some(f) = f else { continue };
            if enabled {
                *function = f;
                return sys::Result::SUCCESS;
            }
            if offers || next.is_none() {
                return sys::Result::ERROR_FUNCTION_UNSUPPORTED;
            }
        }
        if let Some((needs, f)) = own_function(name_bytes) {
            match needs {
                None => {
                    *function = f;
                    return sys::Result::SUCCESS;
                }
                Some(ext) if owned.contains(&ext) => {
                    *function = f;
                    return sys::Result::SUCCESS;
                }
                // Offered by the layer but not enabled by the app; or no instance yet.
                Some(ext) if offered.contains(&ext) || next.is_none() => {
                    return sys::Result::ERROR_FUNCTION_UNSUPPORTED;
                }
                // Not offered by the layer: the runtime may have the extension itself.
                Some(_) => {}
            }
        }
        match next {
            // SAFETY: the next layer's gipa with the caller's valid arguments.
            Some(next) => unsafe { next(instance, name, function) },
            None if sys::Handle::into_raw(instance) == 0 => sys::Result::ERROR_FUNCTION_UNSUPPORTED,
            None => sys::Result::ERROR_HANDLE_INVALID,
        }
    })
}
