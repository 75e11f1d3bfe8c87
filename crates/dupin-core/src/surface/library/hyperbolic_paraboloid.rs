//! Hyperbolic paraboloid z = x^2 / (2a) - y^2 / (2b) (a saddle: K < 0 everywhere; P-Hex paper,
//! section 4.2, Proposition 5).

use crate::Vec3;
use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// Graph P(u, v) = (u, v, u^2 / (2a) - v^2 / (2b)) over [-size, size]^2. `a` and `b` are the
/// radii of curvature at the apex (k1 = 1/a, k2 = -1/b there, normal pointing up).
///
/// (P-Hex paper, section 4.2, Proposition 5.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HyperbolicParaboloid {
    a: f64,
    b: f64,
    size: f64,
}

impl HyperbolicParaboloid {
    /// Apex radii `a, b > 0` and half-extent `size > 0`.
    pub fn new(a: f64, b: f64, size: f64) -> Result<Self, RegistryError> {
        for (key, x) in [("a", a), ("b", b), ("size", size)] {
            if !(x.is_finite() && x > 0.0) {
                return Err(RegistryError::Constraint(format!(
                    "hyperbolic paraboloid {key} = {x} must be finite and positive"
                )));
            }
        }
        Ok(HyperbolicParaboloid { a, b, size })
    }
}

impl Surface for HyperbolicParaboloid {
    fn domain(&self) -> Domain {
        Domain {
            u: (-self.size, self.size),
            v: (-self.size, self.size),
            periodic_u: false,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (a, b) = (self.a, self.b);
        SurfaceDerivatives {
            p: Vec3::new(u, v, u * u / (2.0 * a) - v * v / (2.0 * b)),
            pu: Vec3::new(1.0, 0.0, u / a),
            pv: Vec3::new(0.0, 1.0, -v / b),
            puu: Vec3::new(0.0, 0.0, 1.0 / a),
            puv: Vec3::zeros(),
            pvv: Vec3::new(0.0, 0.0, -1.0 / b),
        }
    }
}

#[cfg(test)]
pub(crate) fn graph_curvatures(fu: f64, fv: f64, fuu: f64, fuv: f64, fvv: f64) -> (f64, f64) {
    // Monge patch closed forms (upward normal).
    let w = 1.0 + fu * fu + fv * fv;
    let k = (fuu * fvv - fuv * fuv) / (w * w);
    let h = ((1.0 + fv * fv) * fuu - 2.0 * fu * fv * fuv + (1.0 + fu * fu) * fvv)
        / (2.0 * w * w.sqrt());
    let d = (h * h - k).max(0.0).sqrt();
    (h + d, h - d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let (a, b) = (1.3, 0.8);
        let s = HyperbolicParaboloid::new(a, b, 2.0).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (1.0, -1.0), (-1.5, 1.3)], 1e-6);
        for i in 0..60 {
            let u = -1.9 + 0.063 * i as f64;
            let v = 1.8 - 0.061 * i as f64;
            let (k1, k2) = graph_curvatures(u / a, -v / b, 1.0 / a, 0.0, -1.0 / b);
            check_curvature(&s, u, v, k1, k2, 1e-9);
        }
        check_curvature(&s, 0.0, 0.0, 1.0 / a, -1.0 / b, 1e-14);
    }
}
