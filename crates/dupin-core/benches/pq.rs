//! PQ perturbation benchmarks (issue: speed targets of the conical paper).

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::{
    PqMode, PqOptions, SurfaceOfRevolution, max_planarity, pq_perturb, principal_quad_mesh,
    skew_quad_grid, torus_centroid_dual,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn report(name: &str, mesh: &dupin_core::PolyMesh, options: &PqOptions) {
    let t = std::time::Instant::now();
    let r = pq_perturb(mesh, options.clone()).unwrap();
    eprintln!(
        "{name}: vertices {} faces {} iterations {} converged {} max_planarity {:.3e} max_move {:.3e} conical {:?} time {:.4} s",
        mesh.num_vertices(),
        mesh.num_faces(),
        r.iterations,
        r.converged,
        max_planarity(&r.mesh),
        r.max_move,
        r.conical_residual,
        t.elapsed().as_secs_f64()
    );
}

fn perturbed_vase(n: usize) -> dupin_core::PolyMesh {
    let s = SurfaceOfRevolution::vase();
    let mut m = principal_quad_mesh(&s, (0.0, 6.0), (-0.9, 0.9), n, n);
    let h = 6.0 / n as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += 0.02 * h * (rng.random::<f64>() * 2.0 - 1.0);
        }
    }
    m
}

fn bench(c: &mut Criterion) {
    let grid = skew_quad_grid(30, 30.0);
    let dual = torus_centroid_dual(48, 24, 3.0, 1.0);
    let vase = perturbed_vase(77); // 78 x 78 = 6084 vertices
    let planar = PqOptions::default();
    let conical = PqOptions {
        mode: PqMode::Conical,
        ..PqOptions::default()
    };
    report("skew-grid-30x30", &grid, &planar);
    report("torus-centroid-dual-1152", &dual, &planar);
    report("conical-vase-6084", &vase, &conical);
    let mut g = c.benchmark_group("pq");
    g.sample_size(10);
    g.bench_function("planarize skew grid 30x30 on z=xy", |b| {
        b.iter(|| pq_perturb(black_box(&grid), planar.clone()).unwrap())
    });
    g.bench_function("planarize torus centroid dual 1152 hexagons", |b| {
        b.iter(|| pq_perturb(black_box(&dual), planar.clone()).unwrap())
    });
    g.bench_function("conical optimisation 6084 vertices", |b| {
        b.iter(|| pq_perturb(black_box(&vase), conical.clone()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
