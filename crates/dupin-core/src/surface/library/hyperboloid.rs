//! One-sheet hyperboloid of revolution, parametrised as in the outside contract (P-Hex paper,
//! Fig. 11: K < 0 everywhere).

use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives, revolution_derivatives};

/// Hyperboloid (a cosh v cos u, a cosh v sin u, c sinh v), u in [0, 2 pi) periodic,
/// v in [-v_max, v_max]. `a` is the waist radius, `c` the vertical scale; K < 0 everywhere.
///
/// (P-Hex paper, section 4.2, Fig. 11.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hyperboloid {
    a: f64,
    c: f64,
    v_max: f64,
}

impl Hyperboloid {
    /// Waist radius `a > 0`, vertical scale `c > 0`, half-range `v_max > 0` of v.
    pub fn new(a: f64, c: f64, v_max: f64) -> Result<Self, RegistryError> {
        for (key, x) in [("a", a), ("c", c), ("vmax", v_max)] {
            if !(x.is_finite() && x > 0.0) {
                return Err(RegistryError::Constraint(format!(
                    "hyperboloid {key} = {x} must be finite and positive"
                )));
            }
        }
        Ok(Hyperboloid { a, c, v_max })
    }
}

impl Surface for Hyperboloid {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((-self.v_max, self.v_max))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (a, c) = (self.a, self.c);
        let (sh, ch) = (v.sinh(), v.cosh());
        revolution_derivatives(u, (a * ch, a * sh, a * ch), (c * sh, c * ch, c * sh))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let (a, c) = (1.0, 1.6);
        let s = Hyperboloid::new(a, c, 1.5).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, -1.0), (5.5, 1.3)], 1e-6);
        for i in 0..60 {
            let u = 0.11 * i as f64;
            let v = -1.45 + 0.049 * i as f64;
            // Closed forms: K of the implicit quadric x^2/a^2 + y^2/a^2 - z^2/c^2 = 1: K = -1 / (a^4 c^2 h^4) with
            // h^2 = (x^2 + y^2)/a^4 + z^2/c^4; and the meridian/parallel curvatures of revolution.
            let p = s.position(u, v);
            let h2 = (p.x * p.x + p.y * p.y) / a.powi(4) + p.z * p.z / c.powi(4);
            let k = -1.0 / (a.powi(4) * c * c * h2 * h2);
            let (k1, k2) = revolution_curvatures(
                a * v.cosh(),
                (a * v.sinh(), c * v.cosh()),
                (a * v.cosh(), c * v.sinh()),
            );
            assert_close(k1 * k2, k, k.abs(), 1e-12, "implicit K");
            check_curvature(&s, u, v, k1, k2, 1e-9);
        }
        assert!(Hyperboloid::new(-1.0, 1.0, 1.0).is_err());
    }
}
