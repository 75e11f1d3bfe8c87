//! The free mode's optimisation weights: `PhexConfig::lambda` and `mu` (P-Hex paper, section 7)
//! reach the planarity optimisation, and bad values are typed errors.

use dupin_core::phex::{Initialisation, LayerRule, PhexConfig, PhexError, PhexPipeline, phex_run};

use dupin_core::scenes::phex_scene;

fn small() -> PhexConfig {
    // About 1k hexagons that need Gauss-Newton iterations (BENCHMARKS.md's 1k size).
    let mut c = phex_scene("torus-bound").unwrap().config;
    c.size = Some(0.49);
    // Dupin-duality initialisation starts non-planar, so the optimisation has work to do.
    c.initialisation = Initialisation::DupinDuality;
    c
}

fn max_diff(a: &dupin_core::mesh::PolyMesh, b: &dupin_core::mesh::PolyMesh) -> f64 {
    a.positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

#[test]
fn lambda_and_mu_change_the_optimised_mesh() {
    let base = phex_run(small()).unwrap();
    assert!(base.report.iterations >= 1, "the base run must optimise");
    for (lambda, mu) in [(1e-3, small().mu), (small().lambda, 1e-2)] {
        let mut c = small();
        c.lambda = lambda;
        c.mu = mu;
        let r = phex_run(c).unwrap();
        assert_eq!(r.mesh.num_vertices(), base.mesh.num_vertices());
        assert!(
            max_diff(&r.mesh, &base.mesh) > 1e-9,
            "lambda {lambda}, mu {mu} left the mesh unchanged"
        );
        assert!(r.report.max_planarity <= 1e-10);
    }
}

#[test]
fn bad_weights_and_bounds_are_errors() {
    for (lambda, mu) in [
        (-1.0, 0.0),
        (f64::NAN, 0.0),
        (0.0, -1e-9),
        (0.0, f64::INFINITY),
    ] {
        let mut c = small();
        c.lambda = lambda;
        c.mu = mu;
        let e = PhexPipeline::new(c).err();
        assert!(
            matches!(e, Some(PhexError::BadParameter(_))),
            "{lambda} {mu}: {e:?}"
        );
    }
    for b in [-0.1, 1.5, f64::NAN] {
        let mut c = small();
        c.rule = LayerRule::Ideal { bound: b };
        let e = PhexPipeline::new(c).err();
        assert!(
            matches!(e, Some(PhexError::BadParameter(_))),
            "b = {b}: {e:?}"
        );
    }
}
