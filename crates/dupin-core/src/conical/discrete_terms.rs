//! The differentiable scalar terms of the conical paper (Sec. 2.2 and 5) with their analytic
//! gradients: angles between edges (eq. (1), (6), (7)) and determinants of unit edge vectors
//! (the `c_det` terms). Gradients are written out by hand because they are three-line closed
//! forms; no autodiff crate is needed for them.

use crate::Vec3;

/// Angle in \[0, π\] at `c` between the directions to `a` and `b`, with its gradients with
/// respect to `c`, `a` and `b`. At a degenerate corner (collinear edges) the gradients are
/// zero.
#[inline]
pub(crate) fn angle_grad(c: Vec3, a: Vec3, b: Vec3) -> (f64, [Vec3; 3]) {
    let ea = a - c;
    let eb = b - c;
    let cross = ea.cross(&eb);
    let s = cross.norm();
    let w = s.atan2(ea.dot(&eb));
    if s <= 1e-300 || ea.norm_squared() == 0.0 || eb.norm_squared() == 0.0 {
        return (w, [Vec3::zeros(); 3]);
    }
    let n = cross / s;
    let ga = ea.cross(&n) / ea.norm_squared();
    let gb = n.cross(&eb) / eb.norm_squared();
    (w, [-(ga + gb), ga, gb])
}

/// Corner angle at position `k` of a polygon given by its points.
#[inline]
pub(crate) fn corner_angle(pts: &[Vec3], k: usize) -> f64 {
    let n = pts.len();
    angle_grad(pts[k], pts[(k + n - 1) % n], pts[(k + 1) % n]).0
}

/// `det(ê1, ê2, ê3)` of the unit vectors along `e1`, `e2`, `e3`, with its gradients with respect
/// to the (unnormalised) edge vectors.
#[inline]
pub(crate) fn unit_det_grad(e: [Vec3; 3]) -> (f64, [Vec3; 3]) {
    let l = [e[0].norm(), e[1].norm(), e[2].norm()];
    if l.iter().any(|&x| x <= 1e-300) {
        return (0.0, [Vec3::zeros(); 3]);
    }
    let u = [e[0] / l[0], e[1] / l[1], e[2] / l[2]];
    let d = u[0].dot(&u[1].cross(&u[2]));
    let du = [u[1].cross(&u[2]), u[2].cross(&u[0]), u[0].cross(&u[1])];
    let mut g = [Vec3::zeros(); 3];
    for k in 0..3 {
        g[k] = (du[k] - u[k] * u[k].dot(&du[k])) / l[k];
    }
    (d, g)
}

/// The planarity determinant of four consecutive polygon vertices p0..p3: `det` of the unit
/// vectors along p1-p0, p2-p1, p3-p2, with gradients with respect to p0..p3.
#[inline]
pub(crate) fn quad_det_grad(p: [Vec3; 4]) -> (f64, [Vec3; 4]) {
    let (d, g) = unit_det_grad([p[1] - p[0], p[2] - p[1], p[3] - p[2]]);
    (d, [-g[0], g[0] - g[1], g[1] - g[2], g[2]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn rv(rng: &mut ChaCha8Rng) -> Vec3 {
        Vec3::new(
            rng.random::<f64>() * 2.0 - 1.0,
            rng.random::<f64>() * 2.0 - 1.0,
            rng.random::<f64>() * 2.0 - 1.0,
        )
    }

    /// Central differences agree with the analytic gradients on seeded random inputs.
    #[test]
    fn gradients_match_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let h = 1e-6;
        for _ in 0..200 {
            let p = [rv(&mut rng), rv(&mut rng), rv(&mut rng), rv(&mut rng)];
            let (_, ga) = angle_grad(p[0], p[1], p[2]);
            let (_, gd) = quad_det_grad(p);
            for k in 0..3 {
                for c in 0..3 {
                    let mut q = p;
                    q[k][c] += h;
                    let mut r = p;
                    r[k][c] -= h;
                    let fd = (angle_grad(q[0], q[1], q[2]).0 - angle_grad(r[0], r[1], r[2]).0)
                        / (2.0 * h);
                    assert!((fd - ga[k][c]).abs() < 1e-5 * (1.0 + fd.abs()), "angle");
                }
            }
            for k in 0..4 {
                for c in 0..3 {
                    let mut q = p;
                    q[k][c] += h;
                    let mut r = p;
                    r[k][c] -= h;
                    let fd = (quad_det_grad(q).0 - quad_det_grad(r).0) / (2.0 * h);
                    assert!((fd - gd[k][c]).abs() < 1e-5 * (1.0 + fd.abs()), "det");
                }
            }
        }
    }

    #[test]
    fn det_vanishes_exactly_on_coplanar_points() {
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(-3.0, 1.0, 0.0),
        ];
        assert_eq!(quad_det_grad(p).0, 0.0);
        let mut q = p;
        q[3].z = 0.1;
        assert!(quad_det_grad(q).0.abs() > 1e-3);
    }
}
