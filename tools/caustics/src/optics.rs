//! Interface optics of a smooth dielectric: Snell refraction, mirror reflection and the exact
//! Fresnel reflectance for unpolarised light (shared with the renderer's CPU tracers).

pub use vitreous_render::optics::{fresnel_reflectance, reflect, refract};
