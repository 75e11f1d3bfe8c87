//! Hot paths of the Dupin toolkit, called per vertex / per triangle by the P-Hex pipeline.

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::mesh::is_simple_polygon;
use dupin_core::phex::{
    DupinIndicatrix, TriangleStar, dupin_center, dupin_center_3d, ideal_triangle,
    tangent_dual_point,
};
use dupin_core::scenes::benchmark_meshes::torus_triangulation;
use dupin_core::surface::{DupinCyclide, MeshSurface, Surface, Torus};
use dupin_core::{Vec2, Vec3};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let torus = Torus {
        major: 2.0,
        minor: 0.7,
    };
    let cyclide = DupinCyclide::new(2.0, 0.6, 1.1).unwrap();
    c.bench_function("curvature/torus", |b| {
        b.iter(|| torus.curvature(black_box(0.5), black_box(0.4)).unwrap())
    });
    c.bench_function("curvature/dupin-cyclide", |b| {
        b.iter(|| cyclide.curvature(black_box(0.5), black_box(0.4)).unwrap())
    });
    let ind = DupinIndicatrix::new(0.7, -1.3).unwrap();
    let (a, p, q) = (
        Vec2::new(0.1, 0.0),
        Vec2::new(1.0, 0.2),
        Vec2::new(0.3, 0.9),
    );
    c.bench_function("dupin_center/2d", |b| {
        b.iter(|| dupin_center(&ind, black_box(&a), black_box(&p), black_box(&q)).unwrap())
    });
    let curv = torus.curvature(0.5, 0.4).unwrap();
    // Three nearby surface points (a small triangle) and their normals.
    let at = [(0.5, 0.4), (0.55, 0.41), (0.52, 0.46)];
    let pts = at.map(|(u, v)| torus.position(u, v));
    c.bench_function("dupin_center/3d", |b| {
        b.iter(|| {
            dupin_center_3d(
                black_box(&curv),
                black_box(&pts[0]),
                black_box(&pts[1]),
                black_box(&pts[2]),
            )
            .unwrap()
        })
    });
    let nrm = at.map(|(u, v)| torus.normal(u, v));
    c.bench_function("tangent_dual_point", |b| {
        b.iter(|| {
            tangent_dual_point(
                [black_box(&pts[0]), black_box(&pts[1]), black_box(&pts[2])],
                [black_box(&nrm[0]), black_box(&nrm[1]), black_box(&nrm[2])],
            )
            .unwrap()
        })
    });
    c.bench_function("ideal_triangle", |b| {
        b.iter(|| ideal_triangle(&ind, black_box(&a), black_box(&p)).unwrap())
    });
    let star = TriangleStar::new(a, p, q).unwrap();
    c.bench_function("triangle_star/is_valid", |b| {
        b.iter(|| black_box(&star).is_valid(&ind).unwrap())
    });
    let hex = star.dupin_hexagon(&ind).unwrap().vertices;
    c.bench_function("is_simple_polygon/6", |b| {
        b.iter(|| is_simple_polygon(black_box(&hex)).unwrap())
    });
    let target = torus.position(1.0, 2.0) + torus.normal(1.0, 2.0) * 0.1;
    c.bench_function("closest_point/torus/warm", |b| {
        b.iter(|| {
            torus
                .closest_point(black_box(&target), Some(Vec2::new(1.02, 1.97)))
                .unwrap()
        })
    });
    // A 100 x 50 torus mesh (10k triangles).
    let mesh = torus_triangulation(100, 50, torus.major, torus.minor);
    c.bench_function("mesh_surface/build_10k_triangles", |b| {
        b.iter(|| MeshSurface::from_mesh(black_box(mesh.clone())))
    });
    let ms = MeshSurface::from_mesh(mesh);
    let qp = Vec3::new(1.3, 1.1, 0.2);
    c.bench_function("mesh_surface/closest_point", |b| {
        b.iter(|| ms.closest_point(black_box(&qp)).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
