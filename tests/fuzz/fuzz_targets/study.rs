//! libFuzzer entry for [`vitreous_fuzz::study`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::study(data));
