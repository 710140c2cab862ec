#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mlt_fuzz::targets::capi_scene(data));
