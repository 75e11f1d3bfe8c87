//! The toolkit's key guarantees, run natively and on wasm32 (through wasm-bindgen-test): the
//! core must behave identically in the browser (P-Hex paper, sections 3 to 5.1; the sparse
//! Gauss-Newton engine of the conical paper's PQ perturbation).

#[cfg(target_arch = "wasm32")]
use wasm_bindgen_test::wasm_bindgen_test as test;

use dupin_core::phex::{
    DupinIndicatrix, TriangleStar, dupin_center, ideal_triangle, is_affine_quasi_regular_hexagon,
    is_affine_regular_hexagon,
};

use dupin_core::mesh::{MeshTopology, max_planarity};

use dupin_core::conical::{PqMode, PqOptions, conical_residual, pq_perturb, principal_quad_mesh};

use dupin_core::surface::{SurfaceOfRevolution, surface_by_name, surface_catalog};

use dupin_core::Vec2;

use dupin_core::scenes::benchmark_meshes::{skew_quad_grid, torus_centroid_dual};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn every_library_surface_has_finite_curvature() {
    for spec in surface_catalog() {
        let s = surface_by_name(spec.name, &[]).unwrap();
        let d = s.domain();
        let c = s
            .curvature(0.5 * (d.u.0 + d.u.1) + 0.1, 0.5 * (d.v.0 + d.v.1) + 0.1)
            .unwrap();
        assert!(
            c.k1.is_finite() && c.k2.is_finite() && c.k1 >= c.k2,
            "{}",
            spec.name
        );
    }
    let t = surface_by_name("torus", &[("R", 2.0), ("r", 0.5)]).unwrap();
    let c = t.curvature(0.0, 0.0).unwrap();
    assert!((c.k1 + 1.0 / 2.5).abs() < 1e-12 && (c.k2 + 2.0).abs() < 1e-12);
}

#[test]
fn propositions_4_and_5_conditions_agree() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for sign in [1.0, -1.0] {
        let mut n = 0;
        while n < 5_000 {
            let ind = DupinIndicatrix::new(
                rng.random_range(0.1..3.0),
                sign * rng.random_range(0.1..3.0),
            )
            .unwrap();
            let mut p = || Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let Ok(star) = TriangleStar::new(p(), p(), p()) else {
                continue;
            };
            n += 1;
            let [c1, c2, c3] = star.validity_conditions(&ind).unwrap();
            assert!(c1 == c2 && c1 == c3);
        }
    }
}

#[test]
fn ideal_triangles_are_ideal() {
    for (k1, k2) in [(1.3, 0.4), (1.3, -0.4)] {
        let ind = DupinIndicatrix::new(k1, k2).unwrap();
        let (a, b) = (Vec2::new(0.1, 0.2), Vec2::new(0.9, -0.1));
        let t = ideal_triangle(&ind, &a, &b).unwrap();
        let o = dupin_center(&ind, &t.a, &t.b, &t.c).unwrap();
        assert!((o - t.ideal_dupin_center(&ind)).norm() < 1e-12);
        let h = TriangleStar::new(a, b, t.c)
            .unwrap()
            .dupin_hexagon(&ind)
            .unwrap();
        if k2 > 0.0 {
            assert!(is_affine_regular_hexagon(&h.vertices, &a, 1e-9));
        } else {
            assert!(is_affine_quasi_regular_hexagon(&h.vertices, &a, 1e-9));
        }
    }
}

/// The block Gauss-Newton engine (plane elimination for quads, planes kept for hexagons,
/// second-order correction in the exact phase) reaches the exact constraints on wasm32 as
/// natively: planar quads and hexagons, and a conical mesh.
#[test]
fn pq_perturbation_reaches_the_exact_constraints() {
    for m in [
        skew_quad_grid(10, 30.0),
        torus_centroid_dual(16, 8, 3.0, 1.0),
    ] {
        assert!(max_planarity(&m) > 1e-3);
        let r = pq_perturb(&m, PqOptions::default()).unwrap();
        assert!(r.converged, "{:?}", r.reason);
        assert!(max_planarity(&r.mesh) <= 1e-10);
    }
    let mut m = principal_quad_mesh(&SurfaceOfRevolution::vase(), (0.0, 6.0), (-0.9, 0.9), 8, 8);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += 0.01 * (rng.random::<f64>() - 0.5);
        }
    }
    let conical = PqOptions {
        mode: PqMode::Conical,
        ..PqOptions::default()
    };
    let r = pq_perturb(&m, conical).unwrap();
    assert!(r.converged, "{:?}", r.reason);
    let topo = MeshTopology::new(&r.mesh).unwrap();
    assert!(max_planarity(&r.mesh) <= 1e-10);
    assert!(conical_residual(&r.mesh, &topo) <= 1e-10);
}

/// The sparse Cholesky factorisation on wasm32 (its own supernodal kernel there, faer's
/// natively) gives the same Newton steps: a noisy 40 x 40 quad grid planarised keeping the
/// design (face space) and the paper's way (vertices and planes) takes the same iterations
/// and factorisations on both targets, converging quadratically to the same planarity.
#[test]
fn the_factorisations_give_the_same_newton_steps_on_both_targets() {
    let n = 40;
    let mut rng = ChaCha8Rng::seed_from_u64(40);
    let positions: Vec<dupin_core::Vec3> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x, y) = (i as f64 * 0.05, j as f64 * 0.05);
            let z = 0.3 * ((x - 1.0).powi(2) - (y - 1.0).powi(2)) / 20.0;
            dupin_core::Vec3::new(x, y, z + 0.004 * (rng.random::<f64>() - 0.5))
        })
        .collect();
    let m = dupin_core::mesh::PolyMesh::quad_grid(positions, n, n).unwrap();
    for (keep_design, want) in [(true, (4, 4)), (false, (7, 5))] {
        let r = pq_perturb(
            &m,
            PqOptions {
                keep_design,
                ..PqOptions::default()
            },
        )
        .unwrap();
        assert!(r.converged, "{:?}", r.reason);
        assert!(
            max_planarity(&r.mesh) <= 1e-12,
            "{}",
            max_planarity(&r.mesh)
        );
        assert_eq!(
            (r.iterations, r.factorizations),
            want,
            "keep_design {keep_design}"
        );
    }
}
