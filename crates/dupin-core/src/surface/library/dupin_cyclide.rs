//! Ring Dupin cyclide (P-Hex paper, Figs. 1 and 15: both signs of K, curvature lines are circles).

use crate::Vec3;
use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// Ring Dupin cyclide in the standard form with focal ellipse x^2/a^2 + y^2/b^2 = 1 and focal
/// hyperbola x^2/c^2 - z^2/b^2 = 1, b^2 = a^2 - c^2:
///
/// ```text
/// d = a - c cos u cos v
/// P = ( (mu (c - a cos u cos v) + b^2 cos u) / d,
///       b sin u (a - mu cos v) / d,
///       b sin v (c cos u - mu) / d )
/// ```
///
/// u, v in [0, 2 pi), both periodic; parameter lines are curvature lines (circles). A ring
/// cyclide needs 0 <= c < mu < a. Each principal curvature is the reciprocal of a focal sphere's
/// signed radius: spheres centred on the focal ellipse (a cos u, b sin u, 0) with radius
/// mu - c cos u, and on the focal hyperbola (c / cos v, 0, -b tan v) with radius
/// (a - mu cos v) / cos v.
///
/// (P-Hex paper, Figs. 1 and 15.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DupinCyclide {
    a: f64,
    c: f64,
    mu: f64,
}

impl DupinCyclide {
    /// Ring cyclide parameters with 0 <= c < mu < a.
    pub fn new(a: f64, c: f64, mu: f64) -> Result<Self, RegistryError> {
        if !(a.is_finite() && c.is_finite() && mu.is_finite() && 0.0 <= c && c < mu && mu < a) {
            return Err(RegistryError::Constraint(format!(
                "dupin-cyclide needs 0 <= c < mu < a, got a = {a}, c = {c}, mu = {mu}"
            )));
        }
        Ok(DupinCyclide { a, c, mu })
    }

    /// (a, c, mu).
    pub fn params(&self) -> (f64, f64, f64) {
        (self.a, self.c, self.mu)
    }

    /// b = sqrt(a^2 - c^2).
    pub fn b(&self) -> f64 {
        (self.a * self.a - self.c * self.c).sqrt()
    }
}

impl Surface for DupinCyclide {
    fn domain(&self) -> Domain {
        Domain::full_turns()
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (a, c, mu) = (self.a, self.c, self.mu);
        let b = self.b();
        let b2 = b * b;
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        // P = N / d: numerator, denominator and their partial derivatives.
        let d = a - c * cu * cv;
        let (du, dv) = (c * su * cv, c * cu * sv);
        let (duu, duv, dvv) = (c * cu * cv, -c * su * sv, c * cu * cv);
        let n = Vec3::new(
            mu * (c - a * cu * cv) + b2 * cu,
            b * su * (a - mu * cv),
            b * sv * (c * cu - mu),
        );
        let nu = Vec3::new(
            mu * a * su * cv - b2 * su,
            b * cu * (a - mu * cv),
            -b * c * sv * su,
        );
        let nv = Vec3::new(mu * a * cu * sv, b * mu * su * sv, b * cv * (c * cu - mu));
        let nuu = Vec3::new(
            mu * a * cu * cv - b2 * cu,
            -b * su * (a - mu * cv),
            -b * c * sv * cu,
        );
        let nuv = Vec3::new(-mu * a * su * sv, b * mu * cu * sv, -b * c * cv * su);
        let nvv = Vec3::new(mu * a * cu * cv, b * mu * su * cv, -b * sv * (c * cu - mu));
        // Quotient rule, from N = P d differentiated.
        let p = n / d;
        let pu = (nu - p * du) / d;
        let pv = (nv - p * dv) / d;
        let puu = (nuu - pu * (2.0 * du) - p * duu) / d;
        let puv = (nuv - pu * dv - pv * du - p * duv) / d;
        let pvv = (nvv - pv * (2.0 * dv) - p * dvv) / d;
        SurfaceDerivatives {
            p,
            pu,
            pv,
            puu,
            puv,
            pvv,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature_from_focal_spheres() {
        let (a, c, mu) = (2.0, 0.6, 1.1);
        let s = DupinCyclide::new(a, c, mu).unwrap();
        let b = s.b();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, -1.0), (5.5, 1.3), (3.0, 3.1)], 1e-6);
        let mut signs = (0, 0);
        for i in 0..80 {
            let u = 0.079 * i as f64;
            let v = 0.3 + 0.071 * i as f64;
            let p = s.position(u, v);
            let n = s.normal(u, v);
            // Focal spheres: centre on the ellipse (for u) and on the hyperbola (for v); each
            // contains its whole curvature line and touches the cyclide along it.
            let m1 = Vec3::new(a * u.cos(), b * u.sin(), 0.0);
            let r1 = mu - c * u.cos();
            let m2 = Vec3::new(c / v.cos(), 0.0, -b * v.tan());
            let r2 = (a - mu * v.cos()) / v.cos();
            assert_close(
                (p - m1).norm(),
                r1.abs(),
                1.0,
                1e-12,
                "ellipse focal sphere",
            );
            assert_close(
                (p - m2).norm(),
                r2.abs(),
                1.0,
                1e-9,
                "hyperbola focal sphere",
            );
            // Centre of curvature m = p + n / k, so k = 1 / ((m - p) . n).
            let ka = 1.0 / (m1 - p).dot(&n);
            let kb = 1.0 / (m2 - p).dot(&n);
            check_curvature(&s, u, v, ka.max(kb), ka.min(kb), 1e-9);
            if ka * kb > 0.0 {
                signs.0 += 1;
            } else {
                signs.1 += 1;
            }
        }
        assert!(signs.0 > 10 && signs.1 > 10, "both signs of K: {signs:?}");
        assert!(DupinCyclide::new(2.0, 1.2, 1.0).is_err());
    }
}
