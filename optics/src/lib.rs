//! The optics of vitreous on the CPU, with no device behind them: how light meets the glass
//! and how the eye sees it, in plain Rust over `glam`.
//!
//! - [`optics`]: one surface: the paper's refraction (eq. 7-8), the empirical and the exact
//!   Fresnel reflectance, Snell refraction and mirror reflection, where a ray meets a sphere or
//!   a registered photo's plane; most of them the CPU twin of a shader function;
//! - [`two_surface`]: the path in and out through both surfaces, with total internal
//!   reflection, through an analytic ball or a closed mesh; [`refraction`]: which of the two
//!   models the glass uses;
//! - [`solid`] (with its BVH, [`solid::bvh`]): closed triangle meshes the mesh tracers and the
//!   caustics baker trace through; [`convex`]: whether a mesh bounds one convex body, the facet
//!   planes of a cut gem and where a ray inside leaves them, convex hulls in the plane;
//! - [`absorption`]: Beer-Lambert inside a tinted glass; [`floor`]: the floor's equations
//!   (eq. 2-5: the inducer's ramp, gain and light, the exact distance to the shadow's edge);
//! - [`camera`]: an eye's camera: its view, its projection from an OpenXR field of view, the
//!   rays through its pixels;
//! - [`display`]: what the display takes away from the glass's light, and the segmented
//!   dimmer's panel as the eye meets it; [`srgb`]: the sRGB transfer function;
//! - [`live_caustics`]: the settings of the caustic gain map computed per pose, and their
//!   limits;
//! - [`sphere_check`]: the sphere check, what each pixel of an eye image samples from the
//!   background through an analytic sphere, which the GPU's refraction layer is tested against.
//!
//! The renderer (`vitreous-render`) draws with these and tests its GPU output against them; the
//! scene loader, the physical reference and the caustics baker use them without Vulkan.

pub mod absorption;
pub mod camera;
pub mod convex;
pub mod display;
pub mod floor;
pub mod live_caustics;
pub mod optics;
pub mod refraction;
pub mod solid;
pub mod sphere_check;
pub mod srgb;
pub mod two_surface;
