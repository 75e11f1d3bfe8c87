//! The planarity measure of the outside contract: for each face, the largest distance of its
//! vertices from the face's least-squares plane, divided by the face's mean edge length.

use crate::Vec3;
use crate::mesh::PolyMesh;
use nalgebra::{Matrix3, SymmetricEigen};

/// Planarity error of face `i` of `mesh` (exactly 0 for a triangle).
///
/// The least-squares plane passes through the centroid, with normal the eigenvector of the
/// smallest eigenvalue of the vertices' covariance matrix (`least_squares_normal`). Three
/// points lie in their plane, so a triangle takes no eigen decomposition (the page measures
/// every revealed triangle of a P-Hex run at every step: on the 10k-face NURBS roof its
/// per-state metrics went from 0.9 s to 0.3 s in all).
pub fn face_planarity(mesh: &PolyMesh, i: usize) -> f64 {
    let f = mesh.face(i);
    let n = f.len();
    if n <= 3 {
        return 0.0;
    }
    let p = |k: usize| mesh.positions[f[k] as usize];
    let (c, normal) = least_squares_plane((0..n).map(p));
    let dmax = (0..n)
        .map(|k| (p(k) - c).dot(&normal).abs())
        .fold(0.0, f64::max);
    let e = mesh.face_mean_edge(i);
    if e > 0.0 { dmax / e } else { 0.0 }
}

/// The least-squares plane of `points` (at least one): its point, the centroid, and its unit
/// normal (sign arbitrary), the eigenvector of the smallest eigenvalue of the points'
/// covariance matrix (`least_squares_normal`). The one plane fit of the crate: the contract's
/// `max_planarity`, panel flattening and the PQ solver's start all use it.
pub fn least_squares_plane(points: impl Iterator<Item = Vec3> + Clone) -> (Vec3, Vec3) {
    let (sum, n) = points
        .clone()
        .fold((Vec3::zeros(), 0usize), |(s, n), p| (s + p, n + 1));
    let c = sum / n as f64;
    let covariance = |scale: f64| {
        let mut cov = Matrix3::zeros();
        for p in points.clone() {
            let d = (p - c) * scale;
            cov += d * d.transpose();
        }
        cov
    };
    let cov = covariance(1.0);
    // The covariance of a face of size 1e-160 underflows, of size 1e160 overflows: there,
    // scale the offsets to about 1 first, by a power of two so that the scaling is exact.
    let m = cov.amax();
    if m == 0.0 || (1e-280..1e280).contains(&m) {
        return (c, least_squares_normal(&cov));
    }
    let size = points.clone().map(|p| (p - c).amax()).fold(0.0, f64::max);
    if !(size > 0.0 && size.is_finite()) {
        return (c, least_squares_normal(&cov));
    }
    let scale = 2f64.powi((-size.log2().floor() as i32).clamp(-1000, 1000));
    (c, least_squares_normal(&covariance(scale)))
}

/// The faces of `after` (the same faces as `before`, moved vertices) whose orientation turned
/// over: Newell normals (through the centroid, robust for non-planar and non-convex faces) at
/// an angle of 90 degrees or more. A planarisation that folds faces over has not kept the
/// design, whatever its planarity.
pub fn flipped_faces(before: &PolyMesh, after: &PolyMesh) -> Vec<usize> {
    let newell = |m: &PolyMesh, f: usize| -> Vec3 {
        let p: Vec<Vec3> = m.face(f).iter().map(|&v| m.positions[v as usize]).collect();
        let c = p.iter().sum::<Vec3>() / p.len() as f64;
        (0..p.len())
            .map(|k| (p[k] - c).cross(&(p[(k + 1) % p.len()] - c)))
            .sum()
    };
    (0..before.num_faces().min(after.num_faces()))
        .filter(|&f| !(newell(before, f).dot(&newell(after, f)) > 0.0))
        .collect()
}

/// An orthonormal basis (e1, e2) of the plane with unit normal `n`, with (e1, e2, n)
/// right-handed: e1 is x (or y, when n is near x) projected onto the plane. Where faces are
/// flattened for exact 2D predicates.
pub fn plane_basis(n: Vec3) -> (Vec3, Vec3) {
    let e1 = if n.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = (e1 - n * n.dot(&e1)).normalize();
    (e1, n.cross(&e1))
}

/// Unit eigenvector of the smallest eigenvalue of a symmetric positive semi-definite 3 x 3
/// matrix (a covariance): the normal of the least-squares plane.
///
/// Closed form when that eigenvalue is well separated from the middle one, the case of every
/// polygon that is not thin: the eigenvalues by the trigonometric formula (Smith,
/// CACM 1961), the eigenvector as the longest cross product of two rows of `m - λI`, which
/// is accurate to rounding relative to the middle eigenvalue. Otherwise (ties, where the
/// vector is ill-determined) nalgebra's iterative solver decides. Written by hand: the
/// iterative solver costs ~20x more and the contract metric is evaluated after every
/// optimisation step.
pub(crate) fn least_squares_normal(m: &Matrix3<f64>) -> Vec3 {
    let scale = m.amax();
    if scale > 0.0 && scale.is_finite() {
        let a = m / scale;
        let q = a.trace() / 3.0;
        let b = a - Matrix3::identity() * q;
        let p = (b.norm_squared() / 6.0).sqrt();
        if p > 1e-12 {
            let r = ((b / p).determinant() / 2.0).clamp(-1.0, 1.0);
            let phi = r.acos() / 3.0;
            let largest = q + 2.0 * p * phi.cos();
            let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
            let middle = 3.0 * q - largest - smallest;
            // The vector's error is rounding over the gap (relative to the largest
            // eigenvalue): above 1e-2 it stays below 1e-14, the floor the optimisers'
            // tolerances need; thin faces (aspect ratio over ~10) take the iterative path.
            if middle - smallest > 1e-2 {
                let s = a - Matrix3::identity() * smallest;
                let (r0, r1, r2) = (
                    s.row(0).transpose(),
                    s.row(1).transpose(),
                    s.row(2).transpose(),
                );
                let best = [r0.cross(&r1), r0.cross(&r2), r1.cross(&r2)]
                    .into_iter()
                    .max_by(|x, y| x.norm_squared().total_cmp(&y.norm_squared()))
                    .expect("three candidates");
                if let Some(n) = best.try_normalize(0.0) {
                    return n;
                }
            }
        }
    }
    let eig = SymmetricEigen::new(*m);
    eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned()
}

/// Largest [`face_planarity`] over all faces (0 for a mesh without faces).
pub fn max_planarity(mesh: &PolyMesh) -> f64 {
    (0..mesh.num_faces())
        .map(|i| face_planarity(mesh, i))
        .fold(0.0, f64::max)
}

/// The planarity f64 coordinates can hold: their spacing at the mesh's largest coordinate over
/// its mean edge. A design far from the origin (state-plane coordinates of 1e7 m with 1.5 m
/// panels: 1.2e-9) cannot be planar much below this, whatever the solver does.
pub fn representable_planarity(mesh: &PolyMesh) -> f64 {
    let magnitude = mesh
        .positions
        .iter()
        .map(|p| p.x.abs().max(p.y.abs()).max(p.z.abs()))
        .fold(0.0, f64::max);
    let edge = mesh.mean_edge();
    if edge > 0.0 {
        f64::EPSILON * magnitude / edge
    } else {
        0.0
    }
}

/// When `mesh`'s coordinates cannot hold `tolerance` (a design far from the origin for its
/// size: [`representable_planarity`] above a tenth of it), the clause an unconverged reason
/// ends with, naming that precision and what to do; otherwise empty.
pub fn coordinate_precision_note(mesh: &PolyMesh, tolerance: f64) -> String {
    let floor = representable_planarity(mesh);
    if floor > 0.1 * tolerance {
        format!(
            "; the coordinates' precision at this distance from the origin allows \
             planarity of about {floor:.1e} only: move the design near the origin \
             (subtract a reference point, add it back after)"
        )
    } else {
        String::new()
    }
}

/// [`face_planarity`] of every face of `mesh`, in face order.
pub fn face_planarities(mesh: &PolyMesh) -> Vec<f64> {
    (0..mesh.num_faces())
        .map(|i| face_planarity(mesh, i))
        .collect()
}

/// Mean of per-face planarity errors (as [`face_planarities`] returns them); 0 for no faces.
/// With [`max_planarity`] it tells one bad panel from a uniformly bent mesh.
pub fn mean_planarity(per_face: &[f64]) -> f64 {
    if per_face.is_empty() {
        0.0
    } else {
        per_face.iter().sum::<f64>() / per_face.len() as f64
    }
}

/// Number of bins of [`planarity_histogram`].
pub const PLANARITY_HIST_BINS: usize = 14;
/// log10 of the lower end of [`planarity_histogram`]'s axis (rounding of f64).
pub const PLANARITY_HIST_LO: f64 = -16.0;
/// log10 of the upper end of [`planarity_histogram`]'s axis (a visibly bent panel).
pub const PLANARITY_HIST_HI: f64 = -2.0;

/// Face counts per bin of log10(planarity): [`PLANARITY_HIST_BINS`] equal bins over
/// [[`PLANARITY_HIST_LO`], [`PLANARITY_HIST_HI`]]; exact zeros and values below go to the
/// first bin, values above to the last.
pub fn planarity_histogram(per_face: &[f64]) -> Vec<u32> {
    let (bins, lo, hi) = (PLANARITY_HIST_BINS, PLANARITY_HIST_LO, PLANARITY_HIST_HI);
    let mut h = vec![0u32; bins];
    let w = (hi - lo) / bins as f64;
    for &p in per_face {
        let x = if p > 0.0 { p.log10() } else { lo };
        let b = ((x - lo) / w).floor().clamp(0.0, (bins - 1) as f64) as usize;
        h[b] += 1;
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle is planar exactly, far from the origin too (its eigen decomposition left
    /// rounding there), while a quad beside it is measured.
    #[test]
    fn a_triangle_is_exactly_planar() {
        let o = Vec3::new(1.234e7, -5.678e6, 3.21e5);
        let positions = vec![
            o,
            o + Vec3::new(1.0, 0.1, 0.3),
            o + Vec3::new(0.2, 1.3, -0.4),
            o + Vec3::new(1.1, 1.2, 0.5),
        ];
        let mesh = PolyMesh::new(positions, vec![vec![0, 1, 2], vec![1, 3, 2, 0]]).unwrap();
        assert_eq!(face_planarity(&mesh, 0), 0.0);
        assert!(face_planarity(&mesh, 1) > 0.1);
    }

    #[test]
    fn histogram_counts_every_face_in_its_decade() {
        let h = planarity_histogram(&[0.0, 1e-20, 3e-15, 2e-12, 1e-3, 1.0]);
        assert_eq!(h.len(), PLANARITY_HIST_BINS);
        assert_eq!(h.iter().sum::<u32>(), 6);
        assert_eq!((h[0], h[1], h[4], h[PLANARITY_HIST_BINS - 1]), (2, 1, 1, 2));
    }
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The closed-form normal gives the iterative solver's planarity on random polygons from
    /// exactly planar to strongly bent, and on degenerate ones (collinear, a point).
    #[test]
    fn closed_form_normal_matches_the_iterative_eigensolver() {
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        let mut worst = 0.0f64;
        for trial in 0..20_000 {
            let n = 4 + trial % 5;
            let bend = [0.0, 1e-14, 1e-10, 1e-6, 1e-3, 0.3][trial % 6];
            // Round to thin (aspect ratio up to 1000).
            let thin = [1.0, 0.1, 0.001][(trial / 6) % 3];
            let (ax, ay) = (
                1.0 + rng.random::<f64>(),
                thin * (0.2 + rng.random::<f64>()),
            );
            let frame = nalgebra::Rotation3::new(Vec3::new(
                rng.random::<f64>() * 3.0,
                rng.random::<f64>() * 3.0,
                rng.random::<f64>() * 3.0,
            ));
            let offset = Vec3::new(rng.random(), rng.random(), rng.random()) * 100.0;
            let pts: Vec<Vec3> = (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    let z = bend * (rng.random::<f64>() - 0.5);
                    frame * Vec3::new(ax * t.cos(), ay * t.sin(), z) + offset
                })
                .collect();
            let c = pts.iter().sum::<Vec3>() / n as f64;
            let mut cov = Matrix3::zeros();
            for p in &pts {
                cov += (p - c) * (p - c).transpose();
            }
            let eig = SymmetricEigen::new(cov);
            let reference = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
            let normal = least_squares_normal(&cov);
            assert!((normal.norm() - 1.0).abs() < 1e-12);
            let dist = |v: &Vec3| pts.iter().map(|p| (p - c).dot(v).abs()).fold(0.0, f64::max);
            let (a, b) = (dist(&normal), dist(&reference));
            // Beyond the rounding of points at distance 100 from the origin (~1e-14).
            let err = ((a - b).abs() - 1e-13).max(0.0) / b.max(1e-300);
            worst = worst.max(err);
            assert!(err < 1e-9, "trial {trial}: {a:e} vs {b:e}");
        }
        eprintln!("worst relative difference {worst:e}");
        for cov in [
            Matrix3::zeros(),
            Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            Matrix3::identity(),
        ] {
            assert!((least_squares_normal(&cov).norm() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn planar_and_bent_quads() {
        let mut p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let m = PolyMesh::new(p.clone(), [[0u32, 1, 2, 3]]).unwrap();
        assert!(max_planarity(&m) < 1e-15);
        // Lift one corner by h: the LSQ plane leaves every vertex at distance h/4.
        p[2].z = 0.1;
        let m = PolyMesh::new(p, [[0u32, 1, 2, 3]]).unwrap();
        let edge = (2.0 + 2.0 * (1.0f64 + 0.01).sqrt()) / 4.0;
        let got = max_planarity(&m);
        assert!(got > 0.02 && got < 0.03, "{got} vs edge {edge}");
    }

    /// The measure is scale free from 1e-160 to 1e150 and at offsets of state-plane
    /// coordinates: the same bent quad gives the same figure to 1e-12 relative.
    #[test]
    fn planarity_is_scale_and_offset_free() {
        let base = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.1),
            Vec3::new(0.0, 1.1, 0.0),
        ];
        let at = |scale: f64, offset: Vec3| {
            let p: Vec<Vec3> = base.iter().map(|q| q * scale + offset).collect();
            max_planarity(&PolyMesh::new(p, [[0u32, 1, 2, 3]]).unwrap())
        };
        let want = at(1.0, Vec3::zeros());
        for scale in [1e-160, 1e-6, 1e6, 1e150] {
            let got = at(scale, Vec3::zeros());
            assert!(
                (got / want - 1.0).abs() < 1e-12,
                "scale {scale}: {got} vs {want}"
            );
        }
        // A 1 m panel 1e7 m from the origin keeps the figure to the rounding of its coordinates.
        let got = at(1.0, Vec3::new(1e7, -3e6, 2e5));
        assert!((got / want - 1.0).abs() < 1e-7, "offset: {got} vs {want}");
    }

    #[test]
    fn a_face_turned_over_is_flipped() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let a = PolyMesh::new(p.clone(), [[0u32, 1, 2, 3], [1, 4, 5, 2]]).unwrap();
        let mut q = p;
        // The second quad folded over its shared edge: its far corners now lie at x = 0.
        q[4].x = 0.5;
        q[5].x = 0.5;
        let b = PolyMesh::new(q, [[0u32, 1, 2, 3], [1, 4, 5, 2]]).unwrap();
        assert_eq!(flipped_faces(&a, &b), vec![1]);
        assert!(flipped_faces(&a, &a).is_empty());
    }
}
