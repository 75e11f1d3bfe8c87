#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| dupin_fuzz::mesh_fit(data));
