//! The room's light in `vitreous run`: when the runtime estimates it (XR_ML_light_estimation,
//! Magic Leap 2; `RunSink::follow_room_light` in `sink.rs`), the scene's point light turns about the object, at its distance, to shine
//! the way the room's main light does, so the shadow inducer, the caustics and the dimmed
//! shadow follow the real light, and the light's share of the floor's light (`[light] share`)
//! becomes the estimate's: the main light's irradiance on the floor over all the light's. Each
//! change is an edit of the recording (`light-estimate`, carrying the share), which a replay
//! repeats.
//!
//! With `--readback-check` the run also reads back, at its end, where the shadow and the
//! caustic lie on the floor (`vitreous_frames::readback_check::FloorCentroids`), for a check
//! against an independent computation of both.

use serde::Serialize;

/// What the room's light estimates did in a session.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RoomLight {
    /// Estimates the app received.
    pub estimates: u64,
    /// Times the scene's light moved or its share changed to follow one (the rest were within
    /// `vitreous_trace::light::MIN_TURN_DEG` of where it shone, and within
    /// `MIN_SHARE_STEP` of its share).
    pub light_moves: u64,
    /// The way the newest estimate's main light travels, in the scene frame.
    pub direction: Option<[f32; 3]>,
    /// The newest estimate's share of the floor's light: the main light's irradiance on the
    /// floor over all the light's (ambient spherical harmonics included), by luminance.
    pub floor_share: Option<f32>,
    /// The share the renderer uses after the newest estimate (to a thousandth).
    pub light_share: Option<f32>,
}
