//! The PQ perturbation's workload for the wasm-against-native comparison in BENCHMARKS.md: the
//! centroid dual of a regular torus triangulation (1152 hexagons) planarised five times, run
//! natively (`cargo test --release -p dupin-core --test pq_wasm`) and on wasm32 in Node
//! (`CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner cargo test --release
//! -p dupin-core --target wasm32-unknown-unknown --test pq_wasm`); same iterations and result.

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;

use dupin_core::conical::{PqOptions, pq_perturb};

use dupin_core::mesh::max_planarity;

use dupin_core::scenes::benchmark_meshes::torus_centroid_dual;

#[test]
fn torus_dual_1152_hexagons_five_runs() {
    let m = torus_centroid_dual(48, 24, 3.0, 1.0);
    for _ in 0..5 {
        let r = pq_perturb(&m, PqOptions::default()).unwrap();
        assert!(r.converged, "{:?}", r.reason);
        assert_eq!((r.iterations, r.factorizations), (6, 3));
        assert!(max_planarity(&r.mesh) <= 1e-10);
    }
}
