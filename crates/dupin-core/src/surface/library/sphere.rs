//! Sphere, parametrised as in the outside contract (P-Hex paper, section 7, Fig. 20).

use crate::surface::{Domain, Surface, SurfaceDerivatives, revolution_derivatives};
use std::f64::consts::FRAC_PI_2;

/// Sphere r (cos v cos u, cos v sin u, sin v), u in [0, 2 pi) periodic, v in [-pi/2, pi/2].
///
/// Umbilic everywhere: k1 = k2 = -1/r for the outward normal Pu x Pv. The poles v = +-pi/2 are
/// singular points of the parametrisation.
///
/// (P-Hex paper, section 7, Fig. 20.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Radius r > 0.
    pub radius: f64,
}

impl Surface for Sphere {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((-FRAC_PI_2, FRAC_PI_2))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let r = self.radius;
        let (sv, cv) = v.sin_cos();
        revolution_derivatives(u, (r * cv, -r * sv, -r * cv), (r * sv, r * cv, -r * sv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let s = Sphere { radius: 1.7 };
        check_derivatives(&s, &[(0.3, 0.2), (2.0, -1.0), (5.5, 1.3)], 1e-6);
        for i in 0..50 {
            let u = 0.13 * i as f64;
            let v = -1.5 + 0.06 * i as f64;
            check_curvature(&s, u, v, -1.0 / 1.7, -1.0 / 1.7, 1e-9);
        }
        // Outward normal, contract position.
        let p = s.position(0.5, 0.3);
        assert!((p.norm() - 1.7).abs() < 1e-14);
        assert!((s.normal(0.5, 0.3) - p / 1.7).norm() < 1e-14);
    }
}
