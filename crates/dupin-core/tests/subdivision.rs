//! Subdivision rules and their combination with PQ perturbation (conical paper, Sec. 3).

use dupin_core::mesh::{
    MeshTopology, PolyMesh, catmull_clark, chaikin, doo_sabin, lane_riesenfeld_cubic, max_planarity,
};

use dupin_core::conical::{
    PqOptions, PqStrip, StripClosure, StripRule, focal_points, pq_perturb, principal_quad_mesh,
};

use dupin_core::surface::Torus;

use dupin_core::Vec3;

fn grid(n: usize, lift: impl Fn(f64, f64) -> f64) -> PolyMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64, j as f64);
            p.push(Vec3::new(x, y, lift(x, y)));
        }
    }
    PolyMesh::quad_grid(p, n, n).unwrap()
}

#[test]
fn chaikin_and_lane_riesenfeld_known_values() {
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(4.0, 4.0, 0.0),
    ];
    let c = chaikin(&p, false);
    assert_eq!(c.len(), 6);
    assert_eq!(c[1], Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(c[2], Vec3::new(3.0, 0.0, 0.0));
    assert_eq!(c[5], p[2]);
    let c = chaikin(&p, true);
    assert_eq!(c.len(), 6);
    // Cubic B-spline rule: vertex point (p0 + 6 p1 + p2) / 8, edge midpoints.
    let l = lane_riesenfeld_cubic(&p, false);
    assert_eq!(l.len(), 5);
    assert_eq!(l[1], Vec3::new(2.0, 0.0, 0.0));
    assert_eq!(l[2], (p[0] + 6.0 * p[1] + p[2]) / 8.0);
    // Points on a line stay on it; a closed polygon keeps its centroid.
    let sq = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    for q in [chaikin(&sq, true), lane_riesenfeld_cubic(&sq, true)] {
        let c = q.iter().sum::<Vec3>() / q.len() as f64;
        assert!((c - Vec3::new(0.5, 0.5, 0.0)).norm() < 1e-15);
    }
}

#[test]
fn catmull_clark_counts_planarity_and_boundary() {
    let m = grid(3, |_, _| 0.0);
    let s = catmull_clark(&m).unwrap();
    assert_eq!(s.num_faces(), 36);
    assert_eq!(s.num_vertices(), 49);
    assert!(max_planarity(&s) < 1e-15);
    MeshTopology::new(&s).unwrap();
    // Corners stay fixed; a bilinear (affine here) grid is reproduced on the inside.
    assert_eq!(s.positions[0], m.positions[0]);
    // Hexagons become quads too.
    let hex = dupin_core::scenes::benchmark_meshes::torus_centroid_dual(6, 6, 3.0, 1.0);
    let s = catmull_clark(&hex).unwrap();
    assert_eq!(s.num_faces(), 36 * 6);
    assert!(s.faces().all(|f| f.len() == 4));
    MeshTopology::new(&s).unwrap();
}

#[test]
fn doo_sabin_counts_and_orientation() {
    let m = grid(3, |x, y| 0.1 * x * y);
    let s = doo_sabin(&m).unwrap();
    // With boundary nothing is dropped: 9 face-faces, 24 edge quads (12 interior, 12 on the
    // boundary), 16 vertex faces (4 interior quads, 8 boundary quads, 4 corner triangles).
    assert_eq!(s.num_faces(), 9 + 24 + 16);
    assert_eq!(s.num_vertices(), 36 + 2 * 12);
    let sizes = s.face_sizes();
    assert_eq!((sizes[&3], sizes[&4]), (4, 45));
    let topo = MeshTopology::new(&s).unwrap();
    // The boundary is kept: one loop, twice as many edges, and its vertices are exactly the
    // Chaikin points of the old boundary polygon (corner cutting at 1/4 and 3/4).
    let loop_of = |m: &PolyMesh| -> Vec<Vec3> {
        let t = MeshTopology::new(m).unwrap();
        let start = (0..m.num_vertices()).find(|&v| t.is_boundary(v)).unwrap();
        let mut out = vec![m.positions[start]];
        let mut v = start;
        loop {
            v = t.target(t.star(v)[0]) as usize;
            if v == start {
                return out;
            }
            out.push(m.positions[v]);
        }
    };
    let (old, new) = (loop_of(&m), loop_of(&s));
    assert_eq!(old.len(), 12);
    assert_eq!(new.len(), 24);
    assert_eq!(
        (0..s.num_vertices())
            .filter(|&v| topo.is_boundary(v))
            .count(),
        24
    );
    let expected = chaikin(&old, true);
    for q in &new {
        let d = expected
            .iter()
            .map(|e| (e - q).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-14, "boundary vertex {q} is not a Chaikin point");
    }
    // Bounding box barely shrinks (the boundary is not eaten away).
    let width = |m: &PolyMesh| {
        let xs = m.positions.iter().map(|p| p.x);
        xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min)
    };
    assert!((width(&s) - width(&m)).abs() < 1e-12);
    // On a closed mesh: F + E + V faces.
    let hex = dupin_core::scenes::benchmark_meshes::torus_centroid_dual(6, 6, 3.0, 1.0);
    let s = doo_sabin(&hex).unwrap();
    assert_eq!(s.num_faces(), 36 + 108 + 72);
    MeshTopology::new(&s).unwrap();
}

#[test]
fn doo_sabin_with_boundary_then_pq_perturbation() {
    // A curved 3x3 grid with its first two quads merged into a hexagon (an interior vertex
    // of valence 3 and a boundary vertex in one face): Doo-Sabin gives triangles, quads and
    // hexagons; every level keeps F + E + V faces and perturbation makes all of them planar.
    let g = grid(3, |x, y| 0.15 * (x - 1.5) * (y - 1.2) + 0.04 * y * y);
    let mut faces: Vec<Vec<u32>> = vec![vec![0, 1, 2, 6, 5, 4]];
    faces.extend(g.faces().skip(2).map(|f| f.to_vec()));
    let mut m = PolyMesh::new(g.positions.clone(), faces).unwrap();
    for level in 0..2 {
        let topo = MeshTopology::new(&m).unwrap();
        let (f, e, v) = (m.num_faces(), topo.edges().len(), m.num_vertices());
        // One boundary loop: as many boundary edges as boundary vertices.
        let nb = (0..v).filter(|&v| topo.is_boundary(v)).count();
        let s = doo_sabin(&m).unwrap();
        assert_eq!(s.num_faces(), f + e + v, "level {level}");
        let st = MeshTopology::new(&s).unwrap();
        let sb = (0..s.num_vertices()).filter(|&v| st.is_boundary(v)).count();
        assert_eq!(sb, 2 * nb, "level {level}: boundary not kept");
        assert!(
            max_planarity(&s) > 1e-4,
            "level {level}: nothing to planarise"
        );
        let r = pq_perturb(&s, PqOptions::default()).unwrap();
        assert!(r.converged, "level {level}: {:?}", r.reason);
        assert!(max_planarity(&r.mesh) <= 1e-10);
        m = r.mesh;
    }
    assert!(m.faces().any(|f| f.len() > 4));
}

#[test]
fn subdivision_with_perturbation_gives_a_pq_hierarchy() {
    let mut m = grid(3, |x, y| 0.2 * (x - 1.5) * (y - 1.5) + 0.05 * x * x);
    for level in 0..3 {
        let r = pq_perturb(&m, PqOptions::default()).unwrap();
        assert!(r.converged, "level {level}");
        assert!(max_planarity(&r.mesh) <= 1e-10);
        m = if level % 2 == 0 {
            catmull_clark(&r.mesh).unwrap()
        } else {
            doo_sabin(&r.mesh).unwrap()
        };
    }
}

#[test]
fn developable_open_strip_and_singular_curve() {
    // A cone strip: rulings through the apex (0, 0, 4): the singular curve is the apex.
    let n = 6;
    let apex = Vec3::new(0.0, 0.0, 4.0);
    let a: Vec<Vec3> = (0..n)
        .map(|i| {
            let t = 0.3 * i as f64;
            Vec3::new(2.0 * t.cos(), 2.0 * t.sin(), 0.0)
        })
        .collect();
    let b: Vec<Vec3> = a.iter().map(|p| p + 0.5 * (apex - p)).collect();
    let strip = PqStrip {
        a,
        b,
        closure: StripClosure::Open,
    };
    assert!(strip.max_determinant() < 1e-14);
    for s in strip.singular_curve() {
        let (p, t) = s.unwrap();
        assert!((p - apex).norm() < 1e-12);
        assert!((t - 2.0).abs() < 1e-12, "apex beyond b: t = {t}");
    }
    // Subdividing the boundaries breaks planarity; perturbation restores it.
    let sub = strip.subdivide(StripRule::Chaikin);
    let (pq, r) = sub.perturb(PqOptions::default()).unwrap();
    assert!(r.converged);
    assert!(pq.max_determinant() <= 1e-10);
}

/// Largest distance of the meridian-edge focal points from the torus' central circle (the
/// smooth focal curve of the meridians), and how many there were.
fn focal_error(nu: usize, nv: usize) -> (f64, usize) {
    let torus = Torus {
        major: 3.0,
        minor: 1.0,
    };
    let m = principal_quad_mesh(&torus, (0.0, 1.2), (-1.0, 1.0), nu, nv);
    let topo = MeshTopology::new(&m).unwrap();
    let mut worst: f64 = 0.0;
    let mut count = 0;
    for (a, b, p) in focal_points(&m, &topo) {
        // Same u column: a meridian edge.
        if a as usize % (nu + 1) == b as usize % (nu + 1) {
            let p = p.expect("meridian axes intersect");
            let r = (p.x * p.x + p.y * p.y).sqrt();
            worst = worst.max(((r - 3.0).powi(2) + p.z * p.z).sqrt());
            count += 1;
        }
    }
    (worst, count)
}

#[test]
fn focal_points_converge_to_the_focal_curve() {
    // The normals along a meridian circle of the torus meet at the tube centre; the discrete
    // focal points (intersections of neighbouring cone axes) approach that circle as the
    // principal mesh is refined.
    let (e1, c1) = focal_error(6, 8);
    let (e2, c2) = focal_error(12, 16);
    assert!(c1 > 10 && c2 > c1);
    assert!(e1 < 0.05, "{e1}");
    assert!(e2 < 0.5 * e1, "{e1} -> {e2}");
}
