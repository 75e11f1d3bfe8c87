//! Triaxial ellipsoid (an elliptic surface everywhere; P-Hex paper, section 4.2, K > 0).

use crate::Vec3;
use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives};
use std::f64::consts::FRAC_PI_2;

/// Ellipsoid (a cos v cos u, b cos v sin u, c sin v), u in [0, 2 pi) periodic, v in
/// [-pi/2, pi/2] (poles singular). Outward normal, so both principal curvatures are negative.
///
/// (P-Hex paper, section 4.2, K > 0.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    a: f64,
    b: f64,
    c: f64,
}

impl Ellipsoid {
    /// Semi-axes along x, y, z; each must be finite and positive.
    pub fn new(a: f64, b: f64, c: f64) -> Result<Self, RegistryError> {
        for (key, x) in [("a", a), ("b", b), ("c", c)] {
            if !(x.is_finite() && x > 0.0) {
                return Err(RegistryError::Constraint(format!(
                    "ellipsoid semi-axis {key} = {x} must be finite and positive"
                )));
            }
        }
        Ok(Ellipsoid { a, b, c })
    }

    /// The semi-axes (a, b, c).
    pub fn axes(&self) -> (f64, f64, f64) {
        (self.a, self.b, self.c)
    }
}

impl Surface for Ellipsoid {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((-FRAC_PI_2, FRAC_PI_2))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        let s = Vec3::new(self.a, self.b, self.c);
        let m = |x: Vec3| x.component_mul(&s);
        SurfaceDerivatives {
            p: m(Vec3::new(cv * cu, cv * su, sv)),
            pu: m(Vec3::new(-cv * su, cv * cu, 0.0)),
            pv: m(Vec3::new(-sv * cu, -sv * su, cv)),
            puu: m(Vec3::new(-cv * cu, -cv * su, 0.0)),
            puv: m(Vec3::new(sv * su, -sv * cu, 0.0)),
            pvv: m(Vec3::new(-cv * cu, -cv * su, -sv)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let (a, b, c) = (1.5, 1.0, 0.7);
        let s = Ellipsoid::new(a, b, c).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, -1.0), (5.5, 1.3)], 1e-6);
        for i in 0..60 {
            let u = 0.11 * i as f64;
            let v = -1.45 + 0.049 * i as f64;
            let p = s.position(u, v);
            // Closed forms of the implicit ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1:
            // K = 1 / (a b c h^2)^2, H = (|p|^2 - a^2 - b^2 - c^2) / (2 a^2 b^2 c^2 h^3) (outward
            // normal) with h^2 = x^2/a^4 + y^2/b^4 + z^2/c^4.
            let h2 = p.x * p.x / a.powi(4) + p.y * p.y / b.powi(4) + p.z * p.z / c.powi(4);
            let abc2 = (a * b * c).powi(2);
            let k = 1.0 / (abc2 * h2 * h2);
            let h = (p.norm_squared() - a * a - b * b - c * c) / (2.0 * abc2 * h2 * h2.sqrt());
            let d = (h * h - k).max(0.0).sqrt();
            check_curvature(&s, u, v, h + d, h - d, 1e-9);
        }
        assert!(Ellipsoid::new(1.0, 0.0, 1.0).is_err());
        assert!(Ellipsoid::new(1.0, f64::NAN, 1.0).is_err());
    }
}
