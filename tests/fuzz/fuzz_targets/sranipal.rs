//! libFuzzer entry for [`vitreous_fuzz::sranipal`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::sranipal(data));
