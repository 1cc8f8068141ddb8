//! vitreous-reference: what a real glass object would look like in a scene, from a CPU ray
//! tracer; the physical reference the display's images are judged against (`vitreous
//! reference` and `replay --compare-reference` write its frames, then `vitreous compare`
//! measures against them).
//!
//! The real world is the scene's registration: the floor and background photos are the
//! radiances the eye receives from the real floor and wall without the object (what the
//! see-through preview shows), and the environment map stands for the rest of the room where a
//! ray leaving the glass meets neither. A real glass object placed there changes two things:
//!
//! - where the eye looks at it, the light it refracts and reflects ([`World::radiance`]): both
//!   surfaces refract by Snell's law, every interface splits the light by the exact Fresnel
//!   reflectance for unpolarised light into a reflected and a transmitted branch, both followed
//!   (total internal reflection included), and Beer-Lambert absorption acts along each path
//!   inside;
//! - on the floor, the part of the floor's light that comes from the scene's point light (its
//!   share `s`, `[light] share`) is shadowed and focused by the object: the floor's radiance is
//!   the photo's times `(1 - s) + s T`, with `T` the ratio of the floor's irradiance from the
//!   light with the object to that without it, found by tracing photons from the light
//!   ([`FloorLight`]).
//!
//! The images are linear RGB; what the eye sees with nothing drawn is the same tracer's image of
//! the world without the object ([`World::without_object`]).
//!
//! Not modelled: the point light's own image in the glass (a point has none), the object's
//! shadow on the wall and its occlusion of the room's ambient light, dispersion and
//! polarisation.
//!
//! The optics it traces with (Snell, Fresnel, the ball and closed-mesh bodies, absorption, the
//! eye's camera) are `vitreous-optics`': no device is involved.
//!
//! | module | what it is |
//! |---|---|
//! | [`world`] | the real world: photos on their planes, the environment, the glass object |
//! | [`trace`] | radiance along a ray, through the glass |
//! | [`floor_light`] | the floor's light traced from the point light: the object's shadow and caustic |
//! | [`light_map`] | that light as a map over the floor |
//! | [`eye`] | an eye image: pixels supersampled over a stratified grid |
//! | [`frame`] | one frame: the floor's light, then each eye's real and seen images |
//! | [`report`] | `reference.json`: the frames' eye cameras, placements and files |

pub mod eye;
pub mod floor_light;
pub mod frame;
pub mod light_map;
pub mod report;
pub mod trace;
pub mod world;

pub use eye::{EyeImage, NearObject, Sampling, Window, render_eye};
pub use floor_light::PhotonParams;
pub use frame::{
    NotClosed, OBJECT_SAMPLES_PER_SIDE, ReferenceFrame, ReferenceSettings, render_reference,
    srgb_rgba,
};
pub use light_map::FloorLight;
pub use report::{EyeRecord, FrameReport, Report};
pub use world::{Glass, Picture, Surface, World};
