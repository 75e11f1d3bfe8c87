//! Geometry Fact 3 (conical paper, Sec. 4): refining a conical mesh by subdivision and conical
//! perturbation makes its edges follow the principal curvature lines.

use dupin_core::{
    MeshTopology, PolyMesh, PqMode, PqOptions, Surface, SurfaceOfRevolution, Vec3, catmull_clark,
    conical_residual, pq_perturb,
};

/// Mean and max angle (radians) between the edges of `m` inside the parameter window and the
/// nearest principal direction of the vase (meridian or parallel) at the edge midpoint. The
/// vase has z = v, so a point near it has parameters (atan2(y, x), z).
fn principal_angle(m: &PolyMesh, window: ((f64, f64), (f64, f64))) -> (f64, f64) {
    let s = SurfaceOfRevolution::vase();
    let topo = MeshTopology::new(m).unwrap();
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0);
    for (a, b) in topo.edges() {
        let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
        let mid = 0.5 * (pa + pb);
        let (u, v) = (mid.y.atan2(mid.x), mid.z);
        if u < window.0.0 || u > window.0.1 || v < window.1.0 || v > window.1.1 {
            continue;
        }
        let d = s.derivatives(u, v);
        let n = d.pu.cross(&d.pv).normalize();
        let e: Vec3 = pb - pa;
        let e = (e - n * n.dot(&e)).normalize();
        let (e1, e2) = (d.pu.normalize(), d.pv.normalize());
        let ang = e
            .dot(&e1)
            .abs()
            .min(1.0)
            .acos()
            .min(e.dot(&e2).abs().min(1.0).acos());
        sum += ang;
        max = max.max(ang);
        count += 1;
    }
    (sum / count as f64, max)
}

#[test]
fn refinement_aligns_with_principal_directions() {
    // A sheared (non-principal) quad grid on the vase.
    let s = SurfaceOfRevolution::vase();
    let (nu, nv) = (8usize, 6usize);
    let mut p = Vec::new();
    for j in 0..=nv {
        for i in 0..=nu {
            let v = -0.7 + 1.4 * j as f64 / nv as f64;
            let u = 0.3 * i as f64 + 0.12 * j as f64;
            p.push(s.position(u, v));
        }
    }
    let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    let faces: Vec<[u32; 4]> = (0..nv)
        .flat_map(|j| {
            (0..nu).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    let mut m = PolyMesh::new(p, faces).unwrap();
    let opts = PqOptions {
        mode: PqMode::Conical,
        ..PqOptions::default()
    };
    let start = principal_angle(&m, ((-10.0, 10.0), (-10.0, 10.0))).0;
    let mut angles = Vec::new();
    for level in 0..4 {
        let r = pq_perturb(&m, opts.clone()).unwrap();
        assert!(r.converged, "level {level}: {:?}", r.reason);
        let topo = MeshTopology::new(&r.mesh).unwrap();
        assert!(conical_residual(&r.mesh, &topo) <= 1e-10);
        angles.push(principal_angle(&r.mesh, ((-10.0, 10.0), (-10.0, 10.0))).0);
        m = catmull_clark(&r.mesh).unwrap();
    }
    eprintln!("mean angle to the principal directions: input {start}, per level {angles:?}");
    assert!(angles[0] < 0.5 * start);
    for w in angles.windows(2) {
        assert!(w[1] < w[0], "not shrinking: {angles:?}");
    }
}
