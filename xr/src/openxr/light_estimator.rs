//! XR_ML_light_estimation in a session: one light estimation, made at the first frame (it
//! needs a time) in the app's space, asked every [`POLL_FRAMES`] frames whether it updated,
//! and when it did, one estimate read (the main light and the ambient harmonics) and freed.
//!
//! Call order in the types: [`LightEstimator::load`] with the instance (the functions),
//! [`LightEstimator::poll`] once per frame with that frame's display time (creates, asks,
//! reads), dropped (destroying the estimation) before the session.

use glam::Vec3;
use openxr as xr;
use openxr::sys;
use vitreous_trace::light::LightEstimate;

use super::ml_light_estimation as ml;
use super::ml_tracker::load;

/// Frames between two questions whether the estimate updated (Magic Leap's own samples ask
/// every 2 s; the runtime updates it about that often).
pub const POLL_FRAMES: u64 = 30;

/// The extension's functions.
#[derive(Clone, Copy)]
struct Functions {
    create: ml::CreateLightEstimationML,
    destroy: ml::DestroyLightEstimationML,
    get_state: ml::GetLightEstimationStateML,
    create_estimate: ml::CreateLightEstimationEstimateML,
    destroy_estimate: ml::DestroyLightEstimationEstimateML,
    get_timestamp: ml::GetLightEstimationTimestampML,
    get_main: ml::GetLightEstimationMainDirectionalLightML,
    get_harmonics: ml::GetLightEstimationSphericalHarmonicsML,
}

/// The session's light estimation; destroyed on drop.
pub struct LightEstimator {
    fns: Functions,
    /// The estimation, once made (`None` before the first frame, or after it was refused).
    handle: Option<ml::LightEstimationML>,
    /// The runtime refused to make one (logged): asked no more.
    refused: bool,
    /// Frames since the last question.
    since_poll: u64,
    /// The last update read.
    last_update: i64,
    /// Estimates read.
    pub estimates: u64,
    /// The first failure of a read has been logged.
    warned: bool,
}

/// A structure of the extension with its type set and the rest zero.
fn typed<T>(ty: i32, make: impl FnOnce(sys::StructureType) -> T) -> T {
    make(sys::StructureType::from_raw(ty))
}

impl LightEstimator {
    /// Loads the extension's functions (the instance must have it enabled); `None`, logged,
    /// when the runtime lacks one.
    pub fn load(instance: &xr::Instance) -> Option<LightEstimator> {
        // SAFETY: each name is the function whose pointer type is asked for.
        let fns = unsafe {
            (|| -> super::Result<Functions> {
                Ok(Functions {
                    create: load(instance, ml::names::CREATE)?,
                    destroy: load(instance, ml::names::DESTROY)?,
                    get_state: load(instance, ml::names::GET_STATE)?,
                    create_estimate: load(instance, ml::names::CREATE_ESTIMATE)?,
                    destroy_estimate: load(instance, ml::names::DESTROY_ESTIMATE)?,
                    get_timestamp: load(instance, ml::names::GET_TIMESTAMP)?,
                    get_main: load(instance, ml::names::GET_MAIN_DIRECTIONAL_LIGHT)?,
                    get_harmonics: load(instance, ml::names::GET_SPHERICAL_HARMONICS)?,
                })
            })()
        };
        match fns {
            Ok(fns) => Some(LightEstimator {
                fns,
                handle: None,
                refused: false,
                since_poll: POLL_FRAMES,
                last_update: 0,
                estimates: 0,
                warned: false,
            }),
            Err(e) => {
                tracing::warn!("XR_ML_light_estimation: {e}; the light is the scene file's");
                None
            }
        }
    }

    /// Moves the estimation on for a frame shown at `time`: makes it at the first frame (in
    /// `space`), and every [`POLL_FRAMES`] frames reads a newer estimate, in `space`'s axes.
    pub fn poll<G>(
        &mut self,
        session: &xr::Session<G>,
        space: &xr::Space,
        time: xr::Time,
    ) -> Option<LightEstimate> {
        if self.refused {
            return None;
        }
        let handle = match self.handle {
            Some(h) => h,
            None => {
                let h = self.create(session, space, time)?;
                self.handle = Some(h);
                h
            }
        };
        self.since_poll += 1;
        if self.since_poll < POLL_FRAMES {
            return None;
        }
        self.since_poll = 0;
        let mut state = typed(ml::structure_type::STATE, |ty| ml::LightEstimationStateML {
            ty,
            next: std::ptr::null_mut(),
            last_update: sys::Time::from_nanos(0),
        });
        // SAFETY: a live estimation and a writable state of the right type.
        let r = unsafe { (self.fns.get_state)(handle, &mut state) };
        if r.into_raw() < 0 {
            self.warn_once(format!("xrGetLightEstimationStateML: {r:?}"));
            return None;
        }
        let update = state.last_update.as_nanos();
        if update == 0 || update <= self.last_update {
            return None;
        }
        let estimate = self.read(handle)?;
        self.last_update = update;
        self.estimates += 1;
        Some(estimate)
    }

    /// Makes the estimation, or logs why not and asks no more.
    fn create<G>(
        &mut self,
        session: &xr::Session<G>,
        space: &xr::Space,
        time: xr::Time,
    ) -> Option<ml::LightEstimationML> {
        let info = typed(ml::structure_type::CREATE_INFO, |ty| {
            ml::LightEstimationCreateInfoML {
                ty,
                next: std::ptr::null(),
                base_space: space.as_raw(),
                time,
                cubemap_face_resolution: ml::CubemapFaceResolutionML::R64,
            }
        });
        let mut handle = ml::LightEstimationML::default();
        // SAFETY: the live session and space, a valid create info and a writable handle.
        let r = unsafe { (self.fns.create)(session.as_raw(), &info, &mut handle) };
        if r.into_raw() < 0 {
            self.refused = true;
            tracing::warn!(
                "XR_ML_light_estimation: creating the estimation failed ({r:?}); the light is \
                 the scene file's"
            );
            return None;
        }
        tracing::info!("XR_ML_light_estimation: the light follows the headset's estimate");
        Some(handle)
    }

    /// Reads one estimate: the main light and the ambient harmonics; the estimate handle is
    /// freed before returning.
    fn read(&mut self, handle: ml::LightEstimationML) -> Option<LightEstimate> {
        let mut estimate = ml::LightEstimationEstimateML::default();
        // SAFETY: a live estimation and a writable handle.
        let r = unsafe { (self.fns.create_estimate)(handle, &mut estimate) };
        if r.into_raw() < 0 {
            self.warn_once(format!("xrCreateLightEstimationEstimateML: {r:?}"));
            return None;
        }
        let mut main = typed(ml::structure_type::MAIN_DIRECTIONAL_LIGHT, |ty| {
            ml::LightEstimationMainDirectionalLightML {
                ty,
                next: std::ptr::null_mut(),
                direction: sys::Vector3f::default(),
                color: sys::Color4f::default(),
            }
        });
        let mut sh = typed(ml::structure_type::SPHERICAL_HARMONICS, |ty| {
            ml::LightEstimationSphericalHarmonicsML {
                ty,
                next: std::ptr::null_mut(),
                harmonics_coefficients: [0.0; ml::HARMONICS_COEFFICIENTS],
            }
        });
        let mut when = sys::Time::from_nanos(0);
        // SAFETY: a live estimate and writable outputs of the right types.
        let results = unsafe {
            [
                (
                    "xrGetLightEstimationMainDirectionalLightML",
                    (self.fns.get_main)(estimate, &mut main),
                ),
                (
                    "xrGetLightEstimationSphericalHarmonicsML",
                    (self.fns.get_harmonics)(estimate, &mut sh),
                ),
                (
                    "xrGetLightEstimationTimestampML",
                    (self.fns.get_timestamp)(estimate, &mut when),
                ),
            ]
        };
        // SAFETY: the estimate made above, freed once.
        let freed = unsafe { (self.fns.destroy_estimate)(estimate) };
        if freed.into_raw() < 0 {
            self.warn_once(format!("xrDestroyLightEstimationEstimateML: {freed:?}"));
        }
        if let Some((call, r)) = results.iter().find(|(_, r)| r.into_raw() < 0) {
            self.warn_once(format!("{call}: {r:?}"));
            return None;
        }
        let c = &sh.harmonics_coefficients;
        let read = LightEstimate {
            direction: Vec3::new(main.direction.x, main.direction.y, main.direction.z)
                .normalize_or_zero(),
            color: Vec3::new(main.color.r, main.color.g, main.color.b),
            ambient_sh: std::array::from_fn(|i| Vec3::new(c[3 * i], c[3 * i + 1], c[3 * i + 2])),
            time_ns: when.as_nanos(),
        };
        if !read.is_usable() {
            self.warn_once(format!(
                "an estimate with direction {} and colour {} is not used",
                read.direction, read.color
            ));
            return None;
        }
        Some(read)
    }

    /// Logs a failed read once per session.
    fn warn_once(&mut self, message: String) {
        if !self.warned {
            self.warned = true;
            tracing::warn!("XR_ML_light_estimation: {message}; the light stays where it is");
        }
    }
}

impl Drop for LightEstimator {
    fn drop(&mut self) {
        if let Some(h) = self.handle.take() {
            // SAFETY: the estimation made by this value, destroyed once, before the session
            // (this value is dropped first).
            let r = unsafe { (self.fns.destroy)(h) };
            if r.into_raw() < 0 {
                tracing::warn!("xrDestroyLightEstimationML: {r:?}");
            }
        }
    }
}
