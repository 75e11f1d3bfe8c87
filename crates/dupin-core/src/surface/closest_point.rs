//! Closest-point projection onto a parametric surface (used by distance terms and checks of the
//! P-Hex pipeline, P-Hex paper section 6, F_d = sum dist^2(u_i, S)).
//!
//! Written by hand: the problem is a 2-variable Newton iteration on the squared distance, which
//! no crate in the stack offers for an arbitrary `Surface`; it allocates nothing.

use super::Surface;
use crate::{Vec2, Vec3};
use thiserror::Error;

/// Result of a closest-point query.
///
/// (P-Hex paper, section 6, distance term F_d.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// Parameters of the foot point (normalised into the domain).
    pub uv: Vec2,
    /// The foot point P(u, v).
    pub point: Vec3,
    /// Distance from the query point to `point`.
    pub distance: f64,
}

/// Why a closest point could not be found.
///
/// (P-Hex paper, section 6.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ClosestPointError {
    /// The query point or the start parameters contain NaN or infinity.
    #[error("the query point or start parameters are not finite")]
    NonFinite,
    /// The surface returned a non-finite position during the search.
    #[error("the surface is not finite near the search path")]
    SurfaceNotFinite,
}

const GRID: usize = 24;
const MAX_ITER: usize = 60;

/// Local closest point on `s` to `p`.
///
/// Starting from `start` (or the best node of a 24 x 24 grid over the domain), runs a damped
/// Newton iteration on f(u, v) = |P(u, v) - p|^2 / 2, wrapping periodic directions and clamping
/// at domain borders; every step decreases f. The result is a local minimum of the distance over
/// the domain: on the interior, P - p is normal to the surface. Global optimality is only
/// guaranteed when the start (or grid) lies in the right basin.
///
/// (P-Hex paper, section 6, distance term F_d.)
pub fn closest_point<S: Surface + ?Sized>(
    s: &S,
    p: &Vec3,
    start: Option<Vec2>,
) -> Result<ClosestPoint, ClosestPointError> {
    if !p.iter().all(|c| c.is_finite()) {
        return Err(ClosestPointError::NonFinite);
    }
    let dom = s.domain();
    let (mut u, mut v) = match start {
        Some(st) => {
            if !(st.x.is_finite() && st.y.is_finite()) {
                return Err(ClosestPointError::NonFinite);
            }
            dom.normalize(st.x, st.y)
        }
        None => {
            let mut best = (f64::INFINITY, dom.u.0, dom.v.0);
            for i in 0..=GRID {
                let u = dom.u.0 + (dom.u.1 - dom.u.0) * i as f64 / GRID as f64;
                for j in 0..=GRID {
                    let v = dom.v.0 + (dom.v.1 - dom.v.0) * j as f64 / GRID as f64;
                    let d2 = (s.position(u, v) - p).norm_squared();
                    if d2 < best.0 {
                        best = (d2, u, v);
                    }
                }
            }
            (best.1, best.2)
        }
    };
    let mut d = s.derivatives(u, v);
    let mut f = 0.5 * (d.p - p).norm_squared();
    if !f.is_finite() {
        return Err(ClosestPointError::SurfaceNotFinite);
    }
    let mut lambda = 1e-9;
    for _ in 0..MAX_ITER {
        let r = d.p - p;
        let g = Vec2::new(d.pu.dot(&r), d.pv.dot(&r));
        let (huu, huv, hvv) = (
            d.pu.dot(&d.pu) + d.puu.dot(&r),
            d.pu.dot(&d.pv) + d.puv.dot(&r),
            d.pv.dot(&d.pv) + d.pvv.dot(&r),
        );
        let scale = (d.pu.norm_squared() + d.pv.norm_squared()).max(1e-300);
        if g.norm() <= 1e-15 * scale.sqrt() * (1.0 + r.norm()) {
            break;
        }
        let mut improved = false;
        for _ in 0..30 {
            // Levenberg-style damping keeps the step a descent direction when the Hessian is
            // indefinite (query point beyond a focal point).
            let a = huu + lambda * scale;
            let c = hvv + lambda * scale;
            let det = a * c - huv * huv;
            if det > 0.0 && a > 0.0 {
                let du = -(c * g.x - huv * g.y) / det;
                let dv = -(a * g.y - huv * g.x) / det;
                let (nu, nv) = dom.normalize(u + du, v + dv);
                let nd = s.derivatives(nu, nv);
                let nr = nd.p - p;
                let nf = 0.5 * nr.norm_squared();
                // Near the optimum f changes below rounding: then accept steps that shrink the
                // gradient (Newton's quadratic convergence) instead.
                let ng = Vec2::new(nd.pu.dot(&nr), nd.pv.dot(&nr)).norm();
                if nf.is_finite() && (nf < f || (nf <= f * (1.0 + 1e-12) && ng < g.norm())) {
                    let done = (nu - u).abs() + (nv - v).abs() <= 1e-15 * (1.0 + u.abs() + v.abs());
                    u = nu;
                    v = nv;
                    d = nd;
                    f = nf;
                    lambda = (lambda * 0.1).max(1e-12);
                    improved = !done;
                    break;
                }
            }
            lambda = if lambda < 1e-6 { 1e-6 } else { lambda * 10.0 };
        }
        if !improved {
            break;
        }
    }
    Ok(ClosestPoint {
        uv: Vec2::new(u, v),
        point: d.p,
        distance: (2.0 * f).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Ellipsoid, Hyperboloid, Torus};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn offsets_project_back<S: Surface>(s: &S, max_offset: f64, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let dom = s.domain();
        for _ in 0..300 {
            let u = rng.random_range(dom.u.0..dom.u.1);
            let v = rng.random_range(dom.v.0 + 0.1..dom.v.1 - 0.1);
            let t = rng.random_range(-max_offset..max_offset);
            let q = s.position(u, v) + s.normal(u, v) * t;
            // From a nearby start and from the grid.
            let start = Vec2::new(u + rng.random_range(-0.05..0.05), v);
            for st in [Some(start), None] {
                let cp = s.closest_point(&q, st).unwrap();
                assert!(
                    (cp.point - s.position(u, v)).norm() < 1e-9,
                    "foot at {u},{v} t {t} start {st:?} got {cp:?}"
                );
                assert!((cp.distance - t.abs()).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn normal_offsets_project_back() {
        offsets_project_back(
            &Torus {
                major: 2.0,
                minor: 0.7,
            },
            0.3,
            1,
        );
        offsets_project_back(&Ellipsoid::new(1.5, 1.0, 0.8).unwrap(), 0.2, 2);
        offsets_project_back(&Hyperboloid::new(1.0, 1.5, 1.0).unwrap(), 0.2, 3);
    }

    #[test]
    fn rejects_non_finite() {
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        assert_eq!(
            t.closest_point(&Vec3::new(f64::NAN, 0.0, 0.0), None),
            Err(ClosestPointError::NonFinite)
        );
        assert_eq!(
            t.closest_point(&Vec3::zeros(), Some(Vec2::new(f64::INFINITY, 0.0))),
            Err(ClosestPointError::NonFinite)
        );
    }
}
