//! The P-Hex pipeline runs natively and on wasm32 (through wasm-bindgen-test) with the same
//! result; also the workloads timed for BENCHMARKS.md (the torus at 10k faces, five runs; the
//! NURBS roof at 10k faces, one run).

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

/// The import path's workload (issue: P-Hex on an imported NURBS surface, 10k panels end to
/// end): the NURBS roof of the benchmarks (20 m x 15 m, K > 0 and K < 0 with a parabolic
/// line) at about 10k faces, one run, timed by the harness side by side with the native run.
#[test]
fn nurbs_roof_10k_faces() {
    use dupin_core::phex::{PhexConfig, TriangulationMethod};
    use dupin_core::scenes::benchmark_meshes::nurbs_roof;
    use dupin_core::surface::NurbsSurface;
    let surface = NurbsSurface::try_from(nurbs_roof()).unwrap();
    let mut c = PhexConfig::for_nurbs("roof", surface, Some(0.22));
    c.method = TriangulationMethod::Prescribed;
    let r = phex_run(c).unwrap();
    assert_eq!(r.report.faces, 10_203);
    assert_eq!(r.report.invalid_faces, 0);
    assert!(r.report.max_planarity <= 1e-10);
    assert!(r.report.max_surface_distance <= 0.005 * r.report.bbox_diagonal);
}
