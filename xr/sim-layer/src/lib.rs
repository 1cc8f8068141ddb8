//! `XR_APILAYER_VITREOUS_simulated_ost`: an OpenXR API layer that turns any runtime into a
//! simulated eye-tracked optical see-through headset.
//!
//! On top of the runtime below it, the layer provides `XR_EXT_eye_gaze_interaction`,
//! `XR_FB_eye_tracking_social` and `XR_ML_eye_tracker`, answered from the eye rays of a
//! vitreous trace (v1) composed with the runtime's head pose, and lists the ADDITIVE and
//! ALPHA_BLEND environment blend modes before the runtime's own, composing such frames with
//! a mode the runtime has and recording what each submitted frame asked for (and, with
//! `VITREOUS_SIM_IMAGES`, the submitted images themselves: [`images`]). See
//! `docs/sim-layer.md` for how to enable it and what it approximates.
//!
//! The loader finds the layer through its manifest (`xr/sim-layer/manifest/`, written by
//! `tools/sim-layer`) and calls the one exported symbol,
//! [`entry::xrNegotiateLoaderApiLayerInterface`].

pub mod behaviour;
pub mod bindings;
pub mod blend;
pub mod calls;
pub mod config;
pub mod controller;
pub mod entry;
pub mod extensions;
pub mod eye_geometry;
pub mod faults;
pub mod functions;
pub mod guard;
pub mod images;
pub mod next;
pub mod readback;
pub mod registry;
pub mod submitted;
pub mod timeline;
pub mod two_call;
pub mod views;
pub mod wearer;
