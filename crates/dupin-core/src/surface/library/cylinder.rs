//! Circular cylinder, a developable surface (P-Hex paper, section 3 last paragraph and
//! section 5.3: K = 0 everywhere, Dupin conics degenerate to pairs of lines).

use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives, revolution_derivatives};

/// Cylinder (r cos u, r sin u, v), u in [0, 2 pi) periodic, v in [0, height].
/// k1 = 0 (along the rulings), k2 = -1/r (outward normal): every point is parabolic.
///
/// (P-Hex paper, section 3, last paragraph.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    radius: f64,
    height: f64,
}

impl Cylinder {
    /// Radius > 0 and height > 0.
    pub fn new(radius: f64, height: f64) -> Result<Self, RegistryError> {
        if !(radius.is_finite() && radius > 0.0 && height.is_finite() && height > 0.0) {
            return Err(RegistryError::Constraint(format!(
                "cylinder radius = {radius} and height = {height} must be finite and positive"
            )));
        }
        Ok(Cylinder { radius, height })
    }
}

impl Surface for Cylinder {
    fn domain(&self) -> Domain {
        Domain::full_turn_in_u((0.0, self.height))
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        revolution_derivatives(u, (self.radius, 0.0, 0.0), (v, 1.0, 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;
    use crate::surface::{CurvatureTolerance, PointType};

    #[test]
    fn derivatives_and_curvature() {
        let s = Cylinder::new(1.4, 2.0).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.0, 1.0), (5.5, 1.3)], 1e-6);
        for i in 0..60 {
            let u = 0.11 * i as f64;
            let v = 0.02 + 0.03 * i as f64;
            check_curvature(&s, u, v, 0.0, -1.0 / 1.4, 1e-9);
            let c = s.curvature(u, v).unwrap();
            assert_eq!(
                c.point_type(&CurvatureTolerance::default()),
                PointType::Parabolic
            );
            // The zero-curvature direction is the ruling.
            assert!(c.dir1.z.abs() > 1.0 - 1e-12);
        }
    }
}
