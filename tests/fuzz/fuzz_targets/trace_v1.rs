//! libFuzzer entry for [`vitreous_fuzz::trace_v1`].
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vitreous_fuzz::trace_v1(data));
