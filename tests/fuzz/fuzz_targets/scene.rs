//! libFuzzer entry for [`vitreous_fuzz::scene`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::scene(data));
