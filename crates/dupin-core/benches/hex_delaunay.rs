//! Criterion benchmarks of the hexagonal Delaunay triangulation (simple and extended
//! refinement) on seeded uniform points, with spade's constrained Delaunay refinement at its default 30° bound on the
//! same points as the peer, the quality check of the extended result, and the paper's PSLG data
//! set (the IMR letters fixture, both modes).
//! Run: `cargo bench -p dupin-core --bench hex_delaunay -- --quick`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use dupin_core::Vec2;
use dupin_core::hex_delaunay::{HexDelaunayMode, hex_delaunay, triangulation_quality};
use dupin_core::mesh::{parse_points, parse_segments};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spade::{ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use std::hint::black_box;

fn uniform(n: usize) -> Vec<Vec2> {
    let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
    (0..n)
        .map(|_| Vec2::new(rng.random::<f64>(), rng.random::<f64>()))
        .collect()
}

fn spade_refine(points: &[Vec2]) -> usize {
    let v: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(p.x, p.y)).collect();
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::bulk_load_cdt(v, vec![])
        .expect("finite points");
    cdt.refine(RefinementParameters::default());
    cdt.num_inner_faces()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("hex_delaunay");
    g.sample_size(10);
    for n in [2000usize, 16000] {
        let pts = uniform(n);
        let ours = hex_delaunay(&pts, &[], HexDelaunayMode::Simple)
            .expect("valid input")
            .triangles
            .len();
        let extended = hex_delaunay(&pts, &[], HexDelaunayMode::Extended)
            .expect("valid input")
            .triangles
            .len();
        let theirs = spade_refine(&pts);
        eprintln!(
            "{n} points: hex_delaunay simple {ours}, extended {extended} triangles, spade \
             30deg {theirs} triangles"
        );
        g.bench_with_input(BenchmarkId::new("simple", n), &pts, |b, p| {
            b.iter(|| {
                hex_delaunay(black_box(p), &[], HexDelaunayMode::Simple).map(|t| t.triangles.len())
            })
        });
        g.bench_with_input(BenchmarkId::new("extended", n), &pts, |b, p| {
            b.iter(|| {
                hex_delaunay(black_box(p), &[], HexDelaunayMode::Extended)
                    .map(|t| t.triangles.len())
            })
        });
        g.bench_with_input(BenchmarkId::new("spade_refine_30deg", n), &pts, |b, p| {
            b.iter(|| spade_refine(black_box(p)))
        });
        // The check every result gets in the tests and the CLI report: angles, edges, the
        // Delaunay property edge by edge.
        let t = hex_delaunay(&pts, &[], HexDelaunayMode::Extended).expect("valid input");
        g.bench_with_input(BenchmarkId::new("quality_extended", n), &t, |b, t| {
            b.iter(|| triangulation_quality(black_box(&t.vertices), &t.triangles))
        });
    }
    // The paper's data set 4: the letters IMR as a PSLG (75 points, 75 segments).
    let pts = parse_points(include_str!("../tests/data/imr_points.txt")).expect("fixture");
    let segs = parse_segments(include_str!("../tests/data/imr_segments.txt")).expect("fixture");
    for (name, mode) in [
        ("imr_pslg_simple", HexDelaunayMode::Simple),
        ("imr_pslg_extended", HexDelaunayMode::Extended),
    ] {
        let n = hex_delaunay(&pts, &segs, mode)
            .expect("valid PSLG")
            .triangles
            .len();
        eprintln!("IMR letters, {mode:?}: {n} triangles");
        g.bench_function(name, |b| {
            b.iter(|| hex_delaunay(black_box(&pts), &segs, mode).map(|t| t.triangles.len()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
