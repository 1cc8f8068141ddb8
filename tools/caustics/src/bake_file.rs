//! The bake file format. It lives in the `vitreous` app crate (`vitreous::caustics`), which
//! reads bakes for the renderer's overlay; this module re-exports it so the baker and the app
//! share one definition (the app cannot depend on this crate: this crate depends on it).

pub use vitreous::caustics::{
    Bake, BakeError, GAIN_CHANNEL, MAX_BAKE_BYTES, MAX_BAKE_SIDE_PX, PARAMS_ATTRIBUTE,
    SCENE_HASH_ATTRIBUTE, decode_bake, read_bake, read_bake_unchecked, write_bake,
};
