//! Geometry Fact 3 (conical paper, Sec. 4): refining a conical mesh by subdivision and conical
//! perturbation makes its edges follow the principal curvature lines.
//!
//! Why the earlier version levelled off (at 0.067 rad): the closeness term pulls towards the
//! *input* mesh of each level, so after Catmull-Clark (which shrinks and smooths) the levels
//! drift away from the vase (5.5e-2 at every level) and the mesh aligns with the principal
//! directions of the drifted surface, not of the vase. As in the paper (closeness to the
//! reference surface), every subdivided level is now projected onto the vase before the
//! perturbation; and the angle is measured at a fixed distance from the boundary, where the
//! conical condition (interior vertices only) does not hold.

use dupin_core::mesh::{MeshTopology, PolyMesh, catmull_clark, max_planarity};

use dupin_core::conical::{PqMode, PqOptions, conical_residual, pq_perturb};

use dupin_core::surface::{Surface, SurfaceOfRevolution};

use dupin_core::Vec3;

/// Graph distance of every vertex from the boundary.
fn depth(m: &PolyMesh, topo: &MeshTopology) -> Vec<usize> {
    let mut d = vec![usize::MAX; m.num_vertices()];
    let mut queue = std::collections::VecDeque::new();
    for (v, dv) in d.iter_mut().enumerate() {
        if topo.is_boundary(v) {
            *dv = 0;
            queue.push_back(v);
        }
    }
    while let Some(v) = queue.pop_front() {
        for u in topo.neighbors(v) {
            if d[u as usize] == usize::MAX {
                d[u as usize] = d[v] + 1;
                queue.push_back(u as usize);
            }
        }
    }
    d
}

/// Mean and max angle (radians) between the edges of `m` with both ends at least `min_depth`
/// edges from the boundary and the nearest principal direction of the vase (meridian or
/// parallel) at the footpoint of the edge midpoint.
fn principal_angle(m: &PolyMesh, min_depth: usize) -> (f64, f64) {
    let s = SurfaceOfRevolution::vase();
    let topo = MeshTopology::new(m).unwrap();
    let dp = depth(m, &topo);
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0);
    for (a, b) in topo.edges() {
        if dp[a as usize].min(dp[b as usize]) < min_depth {
            continue;
        }
        let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
        let (u, v, _) = s.closest_point(0.5 * (pa + pb));
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
    assert!(count > 0);
    (sum / count as f64, max)
}

#[test]
fn refinement_aligns_with_principal_directions() {
    // A sheared (non-principal) 8 x 6 quad grid on the vase.
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
    let mut m = PolyMesh::quad_grid(p, nu, nv).unwrap();
    // More penalty iterations than the default 4: the closeness to the vase and the fairness
    // get time to act before the exact phase (4, measured before the probe: 0.0109, 0.0066,
    // 0.0056 at levels 1-3; 12: 0.0077, 0.0030, 0.0017; the exact-phase probe is discarded at
    // every level here).
    let opts = PqOptions {
        mode: PqMode::Conical,
        penalty_iterations: 12,
        ..PqOptions::default()
    };
    // Two rows of the coarse mesh away from the boundary: 2 << level edges at level `level`.
    let start = principal_angle(&m, 2).0;
    let mut angles = Vec::new();
    for level in 0..4 {
        let r = pq_perturb(&m, opts.clone()).unwrap();
        assert!(r.converged, "level {level}: {:?}", r.reason);
        let topo = MeshTopology::new(&r.mesh).unwrap();
        assert!(conical_residual(&r.mesh, &topo) <= 1e-10);
        assert!(max_planarity(&r.mesh) <= 1e-10);
        angles.push(principal_angle(&r.mesh, 2 << level));
        m = catmull_clark(&r.mesh).unwrap();
        for q in &mut m.positions {
            *q = s.closest_point(*q).2;
        }
    }
    eprintln!("(mean, max) angle to the principal directions: input {start}, per level {angles:?}");
    assert!(angles[0].0 < 0.5 * start);
    for w in angles.windows(2) {
        assert!(w[1].0 < 0.75 * w[0].0, "not shrinking: {angles:?}");
    }
    let last = angles[3];
    assert!(last.0 < 0.0025 && last.1 < 0.02, "final angle {last:?}");
}
