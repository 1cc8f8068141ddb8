//! libFuzzer entry for [`vitreous_fuzz::gltf`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::gltf(data));
