//! The P-Hex pipeline runs natively and on wasm32 (through wasm-bindgen-test) with the same
//! result; also the workload timed for BENCHMARKS.md (10k faces, five runs).

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;

use dupin_core::phex::phex_run;

use dupin_core::scenes::phex_scene;

#[test]
fn torus_bound_10k_faces_five_runs() {
    for _ in 0..5 {
        let mut c = phex_scene("torus-bound").unwrap().config;
        c.size = Some(0.155);
        let r = phex_run(c).unwrap();
        assert!(r.report.faces > 9000 && r.report.faces < 11000);
        assert_eq!(r.report.invalid_faces, 0);
        assert!(r.report.max_planarity <= 1e-10);
    }
}
