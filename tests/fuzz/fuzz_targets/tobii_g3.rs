//! libFuzzer entry for [`vitreous_fuzz::tobii_g3`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::tobii_g3(data));
