//! Catenoid, the minimal surface of revolution (P-Hex paper, Fig. 21 left: minimal surfaces,
//! K < 0 everywhere, H = 0).

use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives, revolution_derivatives};

/// Catenoid (c cosh(v/c) cos u, c cosh(v/c) sin u, v), u in [0, 2 pi) periodic,
/// v in [-height/2, height/2]. Principal curvatures +-1 / (c cosh^2(v/c)).
///
/// (P-Hex paper, section 7, Fig. 21.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Catenoid {
    c: f64,
    height: f64,
}

impl Catenoid {
    /// Waist radius `c > 0` and total height `height > 0`.
    pub fn new(c: f64, height: f64) -> Result<Self, RegistryError> {
        if !(c.is_finite() && c > 0.0 && height.is_finite() && height > 0.0) {
            return Err(RegistryError::Constraint(format!(
                "catenoid c = {c} and height = {height} must be finite and positive"
            )));
        }
        Ok(Catenoid { c, height })
    }
}

impl Surface for Catenoid {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((-0.5 * self.height, 0.5 * self.height))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let c = self.c;
        let (sh, ch) = ((v / c).sinh(), (v / c).cosh());
        revolution_derivatives(u, (c * ch, sh, ch / c), (v, 1.0, 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let c = 0.8;
        let s = Catenoid::new(c, 3.0).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, -1.0), (5.5, 1.3)], 1e-6);
        for i in 0..60 {
            let u = 0.11 * i as f64;
            let v = -1.45 + 0.049 * i as f64;
            let k = 1.0 / (c * (v / c).cosh().powi(2));
            check_curvature(&s, u, v, k, -k, 1e-9);
        }
    }
}
