//! PQ perturbation benchmarks (issue: speed targets of the conical paper).

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::{
    PqMode, PqOptions, SurfaceOfRevolution, catmull_clark, max_planarity, pq_perturb,
    principal_quad_mesh, skew_quad_grid, torus_centroid_dual,
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

/// As in the paper's Fig. 15 run: the finest level of Catmull-Clark + conical perturbation.
/// A principal 10 x 9 control mesh of the vase, two levels of subdivision with conical
/// perturbation, then one more subdivision: 81 x 73 = 5913 vertices to make conical.
fn subdivided_conical_vase() -> dupin_core::PolyMesh {
    let opts = PqOptions {
        mode: PqMode::Conical,
        ..PqOptions::default()
    };
    let mut m = principal_quad_mesh(&SurfaceOfRevolution::vase(), (0.0, 6.0), (-0.9, 0.9), 10, 9);
    for _ in 0..3 {
        let r = pq_perturb(&m, opts.clone()).unwrap();
        m = catmull_clark(&r.mesh).unwrap();
    }
    m
}

/// A principal mesh with seeded random noise of 2% of the grid spacing (a harder start).
fn noisy_vase(n: usize) -> dupin_core::PolyMesh {
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
    let vase = subdivided_conical_vase();
    let planar = PqOptions::default();
    let conical = PqOptions {
        mode: PqMode::Conical,
        ..PqOptions::default()
    };
    report("skew-grid-30x30", &grid, &planar);
    report("torus-centroid-dual-1152", &dual, &planar);
    report("conical-vase-subdivided", &vase, &conical);
    report("conical-vase-noisy-31x31", &noisy_vase(30), &conical);
    let mut g = c.benchmark_group("pq");
    g.sample_size(10);
    g.bench_function("planarize skew grid 30x30 on z=xy", |b| {
        b.iter(|| pq_perturb(black_box(&grid), planar.clone()).unwrap())
    });
    g.bench_function("planarize torus centroid dual 1152 hexagons", |b| {
        b.iter(|| pq_perturb(black_box(&dual), planar.clone()).unwrap())
    });
    g.bench_function("conical optimisation 5913 vertices (subdivided)", |b| {
        b.iter(|| pq_perturb(black_box(&vase), conical.clone()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
