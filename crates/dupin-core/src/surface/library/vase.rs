//! A vase: surface of revolution whose profile has an inflection, so it carries a parabolic
//! circle (P-Hex paper, section 5.3, Figs. 17 left and 18).

use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives, revolution_derivatives};
use std::f64::consts::PI;

/// Vase (rho(v) cos u, rho(v) sin u, v) with rho(v) = radius + amplitude sin(2 pi v / height),
/// u in [0, 2 pi) periodic, v in [0, height].
///
/// The belly (v < height/2) is elliptic, the neck (v > height/2) hyperbolic; the profile's
/// inflection at v = height/2 makes that circle parabolic (K = 0, the zero principal direction
/// pointing across the circle, as in the paper's Fig. 17 left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vase {
    radius: f64,
    amplitude: f64,
    height: f64,
}

impl Vase {
    /// Mean radius > 0, amplitude in (0, radius), height > 0.
    pub fn new(radius: f64, amplitude: f64, height: f64) -> Result<Self, RegistryError> {
        if !(radius.is_finite() && radius > 0.0 && height.is_finite() && height > 0.0) {
            return Err(RegistryError::Constraint(format!(
                "vase radius = {radius} and height = {height} must be finite and positive"
            )));
        }
        if !(amplitude.is_finite() && amplitude > 0.0 && amplitude < radius) {
            return Err(RegistryError::Constraint(format!(
                "vase amplitude = {amplitude} must lie in (0, radius = {radius})"
            )));
        }
        Ok(Vase {
            radius,
            amplitude,
            height,
        })
    }

    /// The parameter v of the parabolic circle (height / 2).
    pub fn parabolic_v(&self) -> f64 {
        0.5 * self.height
    }

    /// Profile rho(v) and its first two derivatives.
    pub fn profile(&self, v: f64) -> (f64, f64, f64) {
        let w = 2.0 * PI / self.height;
        let (s, c) = (w * v).sin_cos();
        (
            self.radius + self.amplitude * s,
            self.amplitude * w * c,
            -self.amplitude * w * w * s,
        )
    }
}

impl Surface for Vase {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((0.0, self.height))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        revolution_derivatives(u, self.profile(v), (v, 1.0, 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;
    use crate::surface::{CurvatureTolerance, PointType};

    #[test]
    fn derivatives_curvature_and_parabolic_circle() {
        let s = Vase::new(1.0, 0.35, 3.0).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, 1.0), (5.5, 2.3)], 1e-6);
        for i in 0..60 {
            let u = 0.11 * i as f64;
            let v = 0.02 + 0.049 * i as f64;
            let (r, r1, r2) = s.profile(v);
            let (k1, k2) = revolution_curvatures(r, (r1, 1.0), (r2, 0.0));
            check_curvature(&s, u, v, k1, k2, 1e-9);
        }
        let tol = CurvatureTolerance::default();
        let t = |v: f64| s.curvature(0.4, v).unwrap().point_type(&tol);
        assert_eq!(t(0.7), PointType::Elliptic);
        assert_eq!(t(2.2), PointType::Hyperbolic);
        assert_eq!(t(s.parabolic_v()), PointType::Parabolic);
        assert!(Vase::new(1.0, 1.0, 3.0).is_err());
    }
}
