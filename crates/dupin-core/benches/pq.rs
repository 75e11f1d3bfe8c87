//! PQ perturbation benchmarks: the speeds the conical paper reports are the yardstick.

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::conical::{
    PqMode, PqOptions, StripRule, developable_subdivision, pq_perturb, principal_quad_mesh,
    trefoil_moebius,
};
use dupin_core::mesh::{catmull_clark, max_planarity};
use dupin_core::scenes::benchmark_meshes::{noisy_vase, skew_quad_grid, torus_centroid_dual};
use dupin_core::surface::SurfaceOfRevolution;
use std::hint::black_box;

/// CPU time of this thread in seconds (Linux `schedstat`), to separate our own work from the
/// waiting caused by other processes on a shared machine; `None` elsewhere.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn report(name: &str, mesh: &dupin_core::mesh::PolyMesh, options: &PqOptions) {
    let t = std::time::Instant::now();
    let c0 = thread_cpu_seconds();
    let r = pq_perturb(mesh, options.clone()).unwrap();
    let cpu = c0.and_then(|c| Some(thread_cpu_seconds()? - c));
    eprintln!(
        "{name}: cpu {cpu:.4?} s, vertices {} faces {} iterations {} factorizations {} converged {} max_planarity {:.3e} max_move {:.3e} conical {:?} time {:.4} s",
        mesh.num_vertices(),
        mesh.num_faces(),
        r.iterations,
        r.factorizations,
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
fn subdivided_conical_vase() -> dupin_core::mesh::PolyMesh {
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
    // Trefoil Moebius band (Fig. 9): the PQ strip at 168 quads, one more cubic
    // Lane-Riesenfeld round gives the 336-quad strip that is planarised.
    let (levels, _, _) = developable_subdivision(
        &trefoil_moebius(42, 0.35),
        StripRule::LaneRiesenfeldCubic,
        2,
        &planar,
    )
    .unwrap();
    let trefoil = levels
        .last()
        .unwrap()
        .subdivide(StripRule::LaneRiesenfeldCubic);
    {
        let t = std::time::Instant::now();
        let c0 = thread_cpu_seconds();
        let (s, r) = trefoil.perturb(planar.clone()).unwrap();
        let cpu = c0.and_then(|c| Some(thread_cpu_seconds()? - c));
        eprintln!(
            "trefoil-336: cpu {cpu:.4?} s, quads {} iterations {} converged {} max_planarity {:.3e} max_det {:.3e} max_move {:.3e} time {:.4} s",
            s.num_quads(),
            r.iterations,
            r.converged,
            r.max_planarity,
            s.max_determinant(),
            r.max_move,
            t.elapsed().as_secs_f64()
        );
    }
    let mut g = c.benchmark_group("pq");
    g.bench_function("planarize trefoil Moebius band 336 quads", |b| {
        b.iter(|| black_box(&trefoil).perturb(planar.clone()).unwrap())
    });
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
