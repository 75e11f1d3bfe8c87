//! P-Hex pipeline benchmarks: triangulation, initialisation (dual hexagons),
//! optimisation and the whole pipeline for about 1k, 10k and 50k faces on the torus-bound
//! scene (ideal triangulation with the parabolic bound, both regions of K).

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::mesh::PolyMesh;
use dupin_core::phex::{
    DualMesh, DualMeshOptions, Initialisation, PhexConfig, PhexPipeline, PlanarityOptimiser,
    PlanarityOptions, TriangulationMethod, TriangulationSpec, dual_mesh, phex_run, triangulate,
};
use dupin_core::scenes::phex_scene;
use dupin_core::surface::{Surface, surface_by_name};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

/// CPU time of this thread in seconds (Linux `schedstat`), to separate our own work from the
/// waiting caused by other processes on a shared machine; `None` elsewhere.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Thread CPU since `c0` and the optimiser's counters, for the printed report lines.
fn optimiser_summary(o: &PlanarityOptimiser, c0: Option<f64>) -> String {
    format!(
        "thread CPU {:.3} s, {} iterations, {} CG iterations, {} planarity rejections, {} factorisations (nnz(L) {}), max_planarity {:.2e}",
        c0.and_then(|c| Some(thread_cpu_seconds()? - c))
            .unwrap_or(f64::NAN),
        o.iteration(),
        o.cg_iterations(),
        o.planarity_rejections(),
        o.factorizations(),
        o.factor_len(),
        o.max_planarity()
    )
}

/// Runs the planarity optimisation of `m` (the dual `d`'s hexagons, perhaps perturbed) on
/// `surface` to the end: what the optimisation benchmarks time and what their report lines
/// describe, so both run the same thing.
fn optimise(
    m: &mut PolyMesh,
    d: &DualMesh,
    surface: &dyn Surface,
    options: PlanarityOptions,
) -> PlanarityOptimiser {
    let mut o = PlanarityOptimiser::new(m, Some(&d.vertex_uv), options).unwrap();
    while !o.is_done() {
        o.step(m, surface).unwrap();
    }
    o
}

/// Base-curve edge lengths that give about 1k, 10k and 50k hexagons on the default torus.
const SIZES: [(&str, f64); 3] = [("1k", 0.49), ("10k", 0.155), ("50k", 0.069)];

fn config(size: f64) -> PhexConfig {
    let mut c = phex_scene("torus-bound").unwrap().config;
    c.size = Some(size);
    c
}

fn spec(size: f64) -> TriangulationSpec {
    let s = surface_by_name("torus", &[]).unwrap();
    let len = 2.0 * std::f64::consts::PI * (2.0 + 0.7);
    let _ = s;
    TriangulationSpec {
        max_vertices: dupin_core::phex::MAX_PHEX_FACES,
        method: TriangulationMethod::Prescribed,
        rule: dupin_core::phex::LayerRule::Ideal { bound: 0.3 },
        samples: (len / size).round() as usize,
        swap: false,
        start: 0.0,
        end: std::f64::consts::TAU,
        along: (0.0, std::f64::consts::TAU),
        max_layers: 4000,
    }
}

fn bench(c: &mut Criterion) {
    let torus = surface_by_name("torus", &[]).unwrap();
    for (label, size) in SIZES {
        let r = phex_run(config(size)).unwrap();
        eprintln!(
            "phex torus-bound {label}: {} faces, {} vertices, max_planarity {:.2e}, iterations {}",
            r.report.faces, r.report.vertices, r.report.max_planarity, r.report.iterations
        );
        let sp = spec(size);
        let mut g = c.benchmark_group(format!("phex_{label}"));
        g.sample_size(10);
        g.bench_function("triangulation", |b| {
            b.iter(|| black_box(triangulate(torus.as_ref(), &sp).unwrap()))
        });
        let tri = triangulate(torus.as_ref(), &sp).unwrap();
        g.bench_function("initialisation", |b| {
            b.iter(|| black_box(dual_mesh(&tri, None, &DualMeshOptions::default()).unwrap()))
        });
        // Optimisation from a perturbed start (the pipeline's start is already planar): run
        // to max_planarity <= 1e-10.
        let d = dual_mesh(&tri, None, &DualMeshOptions::default()).unwrap();
        let mut noisy = d.mesh.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let e = noisy.face_mean_edge(0);
        for p in noisy.positions.iter_mut() {
            for k in 0..3 {
                p[k] += rng.random_range(-1.0..1.0) * 1e-3 * e;
            }
        }
        {
            let c0 = thread_cpu_seconds();
            let mut m = noisy.clone();
            let o = optimise(&mut m, &d, torus.as_ref(), PlanarityOptions::default());
            eprintln!(
                "phex torus-bound {label} optimisation from 1e-3 noise: {} faces, {}",
                m.num_faces(),
                optimiser_summary(&o, c0)
            );
        }
        g.bench_function("optimisation", |b| {
            b.iter(|| {
                let mut m = noisy.clone();
                black_box(
                    optimise(&mut m, &d, torus.as_ref(), PlanarityOptions::default())
                        .max_planarity(),
                )
            })
        });
        if label != "50k" {
            bench_dupin_start(&mut g, label, size);
        }
        g.bench_function("pipeline", |b| {
            b.iter(|| black_box(phex_run(config(size)).unwrap()))
        });
        g.finish();
    }
}

/// Optimisation from the Dupin-duality start of the page's free-mode torus (method 2, no
/// parabolic bound), as in `profile_10k` of dupin-web: the run where a planarity-raising CG step
/// used to switch the optimiser to Cholesky factorisations.
fn bench_dupin_start(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    label: &str,
    size: f64,
) {
    let mut cfg =
        PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(size));
    cfg.initialisation = Initialisation::DupinDuality;
    let p = PhexPipeline::new(cfg.clone()).unwrap();
    let d = p.initial_dual_mesh().unwrap();
    let options = cfg.planarity_options();
    let run = |d: &DualMesh| optimise(&mut d.mesh.clone(), d, p.solver_surface(), options);
    let c0 = thread_cpu_seconds();
    let o = run(&d);
    eprintln!(
        "phex torus {label} optimisation from the Dupin-duality start: {} faces, {}",
        d.mesh.num_faces(),
        optimiser_summary(&o, c0)
    );
    g.bench_function("optimisation_dupin_start", |b| {
        b.iter(|| black_box(run(&d).max_planarity()))
    });
}

/// The import path: evaluating the NURBS roof (position and derivatives to second order) with
/// our evaluator and with curvo's, side by side, and the whole P-Hex pipeline on it at about 10k
/// panels (method 2: its parameter lines are conjugate).
fn bench_nurbs(c: &mut Criterion) {
    use curvo::prelude::{KnotVector, NurbsSurface3D};
    use dupin_core::scenes::benchmark_meshes::nurbs_roof;
    use dupin_core::surface::NurbsSurface;
    let def = nurbs_roof();
    let ours = NurbsSurface::try_from(def.clone()).unwrap();
    let points = def
        .control_points
        .iter()
        .map(|row| {
            row.iter()
                .map(|p| nalgebra::Point4::new(p[0], p[1], p[2], 1.0))
                .collect()
        })
        .collect();
    let theirs = NurbsSurface3D::new(
        def.degree_u,
        def.degree_v,
        KnotVector::new(def.knots_u.clone()),
        KnotVector::new(def.knots_v.clone()),
        points,
    );
    let d = ours.domain();
    let params: Vec<(f64, f64)> = (0..1000)
        .map(|k| {
            let (a, b) = ((k % 37) as f64 / 37.0, (k % 41) as f64 / 41.0);
            (d.u.0 + a * (d.u.1 - d.u.0), d.v.0 + b * (d.v.1 - d.v.0))
        })
        .collect();
    let mut g = c.benchmark_group("nurbs_roof");
    g.bench_function("derivatives_1000_ours", |b| {
        b.iter(|| {
            params
                .iter()
                .map(|&(u, v)| ours.derivatives(u, v).puv.x)
                .sum::<f64>()
        })
    });
    g.bench_function("derivatives_1000_curvo", |b| {
        b.iter(|| {
            params
                .iter()
                .map(|&(u, v)| theirs.rational_derivatives(u, v, 2)[1][1].x)
                .sum::<f64>()
        })
    });
    let mut cfg = PhexConfig::for_nurbs("roof", ours.clone(), Some(0.22));
    cfg.method = TriangulationMethod::Prescribed;
    let r = phex_run(cfg.clone()).unwrap();
    eprintln!(
        "phex nurbs roof: {} faces, max_planarity {:.2e}, {} invalid, iterations {}",
        r.report.faces, r.report.max_planarity, r.report.invalid_faces, r.report.iterations
    );
    g.sample_size(10);
    g.bench_function("phex_pipeline_10k", |b| {
        b.iter(|| black_box(phex_run(cfg.clone()).unwrap()))
    });
    g.finish();
    // A design exported as a mesh: parametrisation and fit of 100k triangles, then P-Hex.
    let mesh = dupin_core::scenes::benchmark_meshes::dome_triangle_mesh(224, 1);
    let options = dupin_core::surface::MeshFitOptions::default();
    let fit = dupin_core::surface::fit_mesh_surface(&mesh, &options).unwrap();
    eprintln!(
        "mesh fit: {} triangles, {:?} control points, max distance {:.2e} m",
        mesh.num_faces(),
        fit.surface.control_net_size(),
        fit.max_distance
    );
    let mut g = c.benchmark_group("mesh_fit");
    g.sample_size(10);
    g.bench_function("fit_100k_triangles", |b| {
        b.iter(|| black_box(dupin_core::surface::fit_mesh_surface(&mesh, &options).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench, bench_nurbs);
criterion_main!(benches);
