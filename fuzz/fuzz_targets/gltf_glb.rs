#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| mlt_fuzz::targets::gltf_glb(data));
