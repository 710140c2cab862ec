#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mlt_fuzz::targets::ray_queries(data));
