//! Vulkan renderer for vitreous.
//!
//! Renders the per-eye layers of virtual glass for an additive (optical see-through) display:
//! linear light on black, each eye into its own layer of a 2-layer array image with the same
//! pipeline and the eye index in a push constant. Multiview is not used: lavapipe, the CPU
//! driver CI runs on, gets it wrong.
//!
//! # Synchronisation
//! Work is recorded into one of [`renderer::PIPELINE_DEPTH`] frame slots, each with its own
//! command buffer, fence and timestamp queries. [`Renderer::submit`] first waits for the slot's
//! previous use to finish, so at most `PIPELINE_DEPTH` frames are in flight. All frames render
//! into the same target image on one queue; pipeline barriers inside each command buffer order
//! the accesses across submissions (colour writes, then the transfer to the readback buffer).
//! Readback results of a slot are valid once its fence has signalled, which
//! [`Renderer::submit`] (for the frame `PIPELINE_DEPTH` earlier) and [`Renderer::flush`] wait
//! for. Every fence wait gives up after [`context::FENCE_TIMEOUT`] (on a CPU device
//! [`context::CPU_FENCE_TIMEOUT`]) with
//! [`RenderError::Timeout`]; a lost device is [`RenderError::DeviceLost`] wherever it shows.
//!
//! # Resources
//! Every GPU object is owned by a value that frees it on drop (`owned.rs`, `memory.rs`), so
//! a failed constructor gives back what it made by returning early; the context, which owns
//! the device, is dropped after all of them.
//!
//! Besides the eye images, [`present`] puts finished pictures in a window's swapchain
//! (`vitreous view`, on a context of its own), given a surface the caller made: this crate
//! knows no windowing library.
//!
//! Knows nothing about OpenXR: device creation is an injected step ([`context::DeviceCreator`]).
//! The optics it draws and tests against on the CPU (refraction, the tracers, the radial map,
//! the eye's camera, the dimmer's panel) are `vitreous-optics`'.

mod blur_blend;
mod compensation;
pub mod context;
pub mod coverage;
mod descriptors;
pub mod dimmer;
pub mod error;
pub mod floor;
mod footprint;
mod glass;
pub mod look;
mod memory;
mod owned;
mod parallel;
mod pipeline;
pub mod pose;
pub mod present;
pub mod renderer;
pub mod ripmap;
pub mod scene;
mod shaders;
pub(crate) mod statistics;
mod target;
mod validation;
pub mod work;
mod world;

pub use context::{ContextOptions, DeviceCreator, GpuContext, PlainVulkan};
pub use error::{RenderError, Result};
/// The floor passes under their earlier name.
pub use floor as inducer;
pub use floor::InducerFields;
pub use look::{Defocus, FrameParams, Look, Reflection};
pub use memory::{Image, color_copy_region, layout_barrier, subresource_range};
pub use pose::ScenePose;
pub use present::{PresentWindow, Presented, Presenter};
pub use renderer::{Composition, FrameResult, FrameTiming, Readback, Renderer, Want};
pub use scene::{
    BlurStackDesc, CausticsDesc, InducerDesc, LightDesc, MeshRef, PlaneDesc, SceneDesc, TexelData,
    TextureDesc,
};
pub use work::{
    FrameWork, GlassPositions, Invocations, MeshSearch, PassInvocations, PhotonWork, RecordedWork,
    ShaderCost,
};
