//! The bake file format. It lives in the scene crate (`vitreous_scene::caustics`), where a
//! scene's bake is read for the renderer's overlay; this module re-exports it so the baker and
//! the application share one definition.

pub use vitreous_scene::caustics::{
    Bake, BakeError, GAIN_CHANNEL, MAX_BAKE_BYTES, MAX_BAKE_SIDE_PX, PARAMS_ATTRIBUTE,
    SCENE_HASH_ATTRIBUTE, decode_bake, read_bake, read_bake_unchecked, write_bake,
};
