//! PQ perturbation benchmarks: the speeds the conical paper reports are the yardstick.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use dupin_core::conical::{
    MeshRule, PqMode, PqOptions, PqSceneStepper, StripRule, developable_subdivision, pq_perturb,
    principal_quad_mesh, trefoil_moebius,
};
use dupin_core::mesh::{catmull_clark, max_planarity};
use dupin_core::scenes::benchmark_meshes::{noisy_vase, skew_quad_grid, torus_centroid_dual};
use dupin_core::surface::SurfaceOfRevolution;
use dupin_core::{Stepper, Vec3};
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

/// The page's drag benchmark (`tests/e2e/bench-drag.mjs`) natively: an n x n quad grid of
/// edge 2 with +-1e-3 of height noise (the same generator), planarised keeping the design
/// and committed; returns the stepper and its middle vertex.
fn committed_grid(n: usize) -> (PqSceneStepper, usize) {
    let mut seed: u64 = 11;
    let mut rnd = || {
        seed = (seed * 1_103_515_245 + 12_345) % 2_147_483_648;
        seed as f64 / 2_147_483_648.0
    };
    let mut points = vec![];
    for i in 0..=n {
        for j in 0..=n {
            points.push(Vec3::new(
                2.0 * i as f64,
                2.0 * j as f64,
                (rnd() - 0.5) * 0.002,
            ));
        }
    }
    let mesh = dupin_core::mesh::PolyMesh::quad_grid(points, n, n).unwrap();
    let options = PqOptions {
        keep_design: true,
        ..PqOptions::default()
    };
    let mut s = PqSceneStepper::for_mesh(&mesh, MeshRule::CatmullClark, 0, options).unwrap();
    s.commit().unwrap();
    (s, (n / 2) * (n + 1) + n / 2)
}

/// An `n x n` grid of 0.05 edges on a saddle, its heights with seeded noise of 8% of an edge
/// (the wasm-against-native workload of `tests/workloads_wasm.rs`).
fn noisy_curved_grid(n: usize) -> dupin_core::mesh::PolyMesh {
    let mut seed: u64 = 10_000;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut points = vec![];
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 * 0.05, j as f64 * 0.05);
            let z = 0.3 * ((x - 2.5).powi(2) - (y - 2.5).powi(2)) / 20.0;
            points.push(Vec3::new(x, y, z + 0.004 * (rnd() - 0.5)));
        }
    }
    dupin_core::mesh::PolyMesh::quad_grid(points, n, n).unwrap()
}

/// A drag of 1.2 edge lengths (five quarter-edge stages), in and out of the grid's plane.
const DRAG: [f64; 3] = [1.8, 1.2, 1.2];

fn drag(s: &mut PqSceneStepper, v: usize, to: Vec3) {
    s.hold_vertex(v, to).unwrap();
    s.run_to_end().unwrap();
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
    let (mut s, middle) = committed_grid(100);
    let target = s.mesh().positions[middle] + Vec3::from(DRAG);
    {
        let before = s.iteration();
        let t = std::time::Instant::now();
        let c0 = thread_cpu_seconds();
        drag(&mut s, middle, target);
        let cpu = c0.and_then(|c| Some(thread_cpu_seconds()? - c));
        eprintln!(
            "drag-grid-100x100: cpu {cpu:.4?} s, iterations {} converged {} max_planarity {:.3e} time {:.4} s",
            s.iteration() - before,
            s.converged(),
            max_planarity(s.mesh()),
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
    // A design near planar kept (face space, what `dupin planarize` does) beside the paper's
    // way (penalty phase, then vertices and planes) on the same 10 000 quads.
    let noisy = noisy_curved_grid(100);
    let keep = PqOptions {
        keep_design: true,
        ..PqOptions::default()
    };
    g.bench_function("planarize a noisy 100x100 grid keeping the design", |b| {
        b.iter(|| pq_perturb(black_box(&noisy), keep.clone()).unwrap())
    });
    g.bench_function("planarize a noisy 100x100 grid the paper's way", |b| {
        b.iter(|| pq_perturb(black_box(&noisy), planar.clone()).unwrap())
    });
    g.bench_function("drag a vertex of a 100x100 quad grid 1.2 edges", |b| {
        b.iter_batched(
            || committed_grid(100).0,
            |mut s| drag(&mut s, middle, black_box(target)),
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
