//! libFuzzer entry for [`vitreous_fuzz::bake`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::bake(data));
