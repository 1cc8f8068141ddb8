//! libFuzzer entry for [`vitreous_fuzz::neon`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::neon(data));
