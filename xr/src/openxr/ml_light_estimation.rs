//! Raw definitions of Magic Leap 2's `XR_ML_light_estimation` extension (experimental, not in
//! the Khronos registry, so not in the `openxr` crate): structure types, handles, the per-call
//! structs and the function pointer types, laid out as Magic Leap's OpenXR documentation and
//! its Unity SDK's bindings declare them (C layout, extension number 482: `XrStructureType`
//! values 1000481000-1000481004).
//!
//! The extension bundles one estimate of the room's light in three forms: the main light's
//! direction and colour, 9 spherical-harmonic coefficients per colour channel of the ambient
//! light, and an HDR cube map. The app reads the first two ([`super::light_estimator`]); the
//! simulated headset layer (`vitreous-sim-layer`) answers all of them.
//!
//! Conventions this module assumes, which the documentation does not spell out and no device
//! has confirmed here: the main light's `direction` is the way its light travels (from the
//! light into the room), in the base space the estimation was created with; the 27
//! coefficients are 9 RGB triples in the usual real spherical-harmonic order (l = 0; l = 1:
//! m = -1, 0, 1; l = 2: m = -2..2), projections of the ambient radiance.

use std::ffi::c_void;

use openxr::sys;

/// The extension's name.
pub const EXTENSION_NAME: &str = "XR_ML_light_estimation";

/// `XrObjectType` of a light estimation handle.
pub const OBJECT_TYPE_LIGHT_ESTIMATION_ML: i32 = 1_000_481_000;
/// `XrObjectType` of a light estimation estimate handle.
pub const OBJECT_TYPE_LIGHT_ESTIMATION_ESTIMATE_ML: i32 = 1_000_481_001;

/// Spherical-harmonic coefficients per estimate: 9 per colour channel.
pub const HARMONICS_COEFFICIENTS: usize = 27;

/// `XrStructureType` values of the extension, raw.
pub mod structure_type {
    /// `XrLightEstimationCreateInfoML`.
    pub const CREATE_INFO: i32 = 1_000_481_000;
    /// `XrLightEstimationStateML`.
    pub const STATE: i32 = 1_000_481_001;
    /// `XrLightEstimationHDRCubemapML`.
    pub const HDR_CUBEMAP: i32 = 1_000_481_002;
    /// `XrLightEstimationMainDirectionalLightML`.
    pub const MAIN_DIRECTIONAL_LIGHT: i32 = 1_000_481_003;
    /// `XrLightEstimationSphericalHarmonicsML`.
    pub const SPHERICAL_HARMONICS: i32 = 1_000_481_004;
}

/// `XrLightEstimationML`: a light estimation handle.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightEstimationML(pub u64);

/// `XrLightEstimationEstimateML`: one estimate's handle.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightEstimationEstimateML(pub u64);

/// `XrLightEstimationHDRCubemapFaceResolutionML`.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CubemapFaceResolutionML(pub i32);

impl CubemapFaceResolutionML {
    /// 64 x 64 texels a face.
    pub const R64: CubemapFaceResolutionML = CubemapFaceResolutionML(0);
    /// 128 x 128 texels a face.
    pub const R128: CubemapFaceResolutionML = CubemapFaceResolutionML(1);
    /// 256 x 256 texels a face.
    pub const R256: CubemapFaceResolutionML = CubemapFaceResolutionML(2);

    /// A face's side, texels (`None` for a value the extension does not define).
    pub fn side(self) -> Option<u32> {
        match self.0 {
            0 => Some(64),
            1 => Some(128),
            2 => Some(256),
            _ => None,
        }
    }
}

/// `XrLightEstimationCreateInfoML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct LightEstimationCreateInfoML {
    /// [`structure_type::CREATE_INFO`].
    pub ty: sys::StructureType,
    /// Chain.
    pub next: *const c_void,
    /// The space the estimates' directions are in.
    pub base_space: sys::Space,
    /// When that space is taken.
    pub time: sys::Time,
    /// The cube map's face size.
    pub cubemap_face_resolution: CubemapFaceResolutionML,
}

/// `XrLightEstimationStateML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct LightEstimationStateML {
    /// [`structure_type::STATE`].
    pub ty: sys::StructureType,
    /// Chain.
    pub next: *mut c_void,
    /// When the estimate was last updated (0: not yet).
    pub last_update: sys::Time,
}

/// `XrLightEstimationHDRCubemapML` (two-call idiom over `pixels`: RGBA floats, six faces).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct LightEstimationHdrCubemapML {
    /// [`structure_type::HDR_CUBEMAP`].
    pub ty: sys::StructureType,
    /// Chain.
    pub next: *mut c_void,
    /// Floats `pixels` holds (0: asking for the count).
    pub pixel_count_input: u32,
    /// Floats the cube map has.
    pub pixel_count_output: u32,
    /// Where they go.
    pub pixels: *mut f32,
    /// A face's side, texels.
    pub face_dim: u32,
}

/// `XrLightEstimationMainDirectionalLightML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct LightEstimationMainDirectionalLightML {
    /// [`structure_type::MAIN_DIRECTIONAL_LIGHT`].
    pub ty: sys::StructureType,
    /// Chain.
    pub next: *mut c_void,
    /// The way the main light travels, in the estimation's base space.
    pub direction: sys::Vector3f,
    /// Its colour (linear RGB; alpha unused).
    pub color: sys::Color4f,
}

/// `XrLightEstimationSphericalHarmonicsML`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct LightEstimationSphericalHarmonicsML {
    /// [`structure_type::SPHERICAL_HARMONICS`].
    pub ty: sys::StructureType,
    /// Chain.
    pub next: *mut c_void,
    /// 9 RGB triples (see the module's conventions).
    pub harmonics_coefficients: [f32; HARMONICS_COEFFICIENTS],
}

/// `xrCreateLightEstimationML`.
pub type CreateLightEstimationML = unsafe extern "system" fn(
    sys::Session,
    *const LightEstimationCreateInfoML,
    *mut LightEstimationML,
) -> sys::Result;
/// `xrDestroyLightEstimationML`.
pub type DestroyLightEstimationML = unsafe extern "system" fn(LightEstimationML) -> sys::Result;
/// `xrGetLightEstimationStateML`.
pub type GetLightEstimationStateML =
    unsafe extern "system" fn(LightEstimationML, *mut LightEstimationStateML) -> sys::Result;
/// `xrCreateLightEstimationEstimateML`.
pub type CreateLightEstimationEstimateML =
    unsafe extern "system" fn(LightEstimationML, *mut LightEstimationEstimateML) -> sys::Result;
/// `xrDestroyLightEstimationEstimateML`.
pub type DestroyLightEstimationEstimateML =
    unsafe extern "system" fn(LightEstimationEstimateML) -> sys::Result;
/// `xrGetLightEstimationTimestampML`.
pub type GetLightEstimationTimestampML =
    unsafe extern "system" fn(LightEstimationEstimateML, *mut sys::Time) -> sys::Result;
/// `xrGetLightEstimationHDRCubemapML`.
pub type GetLightEstimationHdrCubemapML = unsafe extern "system" fn(
    LightEstimationEstimateML,
    *mut LightEstimationHdrCubemapML,
) -> sys::Result;
/// `xrGetLightEstimationMainDirectionalLightML`.
pub type GetLightEstimationMainDirectionalLightML = unsafe extern "system" fn(
    LightEstimationEstimateML,
    *mut LightEstimationMainDirectionalLightML,
) -> sys::Result;
/// `xrGetLightEstimationSphericalHarmonicsML`.
pub type GetLightEstimationSphericalHarmonicsML = unsafe extern "system" fn(
    LightEstimationEstimateML,
    *mut LightEstimationSphericalHarmonicsML,
) -> sys::Result;

/// The functions' names, as `xrGetInstanceProcAddr` takes them.
pub mod names {
    use std::ffi::CStr;

    /// `xrCreateLightEstimationML`.
    pub const CREATE: &CStr = c"xrCreateLightEstimationML";
    /// `xrDestroyLightEstimationML`.
    pub const DESTROY: &CStr = c"xrDestroyLightEstimationML";
    /// `xrGetLightEstimationStateML`.
    pub const GET_STATE: &CStr = c"xrGetLightEstimationStateML";
    /// `xrCreateLightEstimationEstimateML`.
    pub const CREATE_ESTIMATE: &CStr = c"xrCreateLightEstimationEstimateML";
    /// `xrDestroyLightEstimationEstimateML`.
    pub const DESTROY_ESTIMATE: &CStr = c"xrDestroyLightEstimationEstimateML";
    /// `xrGetLightEstimationTimestampML`.
    pub const GET_TIMESTAMP: &CStr = c"xrGetLightEstimationTimestampML";
    /// `xrGetLightEstimationHDRCubemapML`.
    pub const GET_HDR_CUBEMAP: &CStr = c"xrGetLightEstimationHDRCubemapML";
    /// `xrGetLightEstimationMainDirectionalLightML`.
    pub const GET_MAIN_DIRECTIONAL_LIGHT: &CStr = c"xrGetLightEstimationMainDirectionalLightML";
    /// `xrGetLightEstimationSphericalHarmonicsML`.
    pub const GET_SPHERICAL_HARMONICS: &CStr = c"xrGetLightEstimationSphericalHarmonicsML";
}
