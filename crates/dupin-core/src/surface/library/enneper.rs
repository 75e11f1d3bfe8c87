//! Enneper's minimal surface (P-Hex paper, Fig. 21 left: minimal surfaces, K < 0, H = 0).

use crate::Vec3;
use crate::surface::RegistryError;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// Enneper surface s (u - u^3/3 + u v^2, v - v^3/3 + v u^2, u^2 - v^2) over
/// [-extent, extent]^2. Principal curvatures +-2 / (s (1 + u^2 + v^2)^2).
/// The surface is embedded for u^2 + v^2 < 3, so `extent` is limited to 1.2.
///
/// (P-Hex paper, section 7, Fig. 21.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enneper {
    scale: f64,
    extent: f64,
}

impl Enneper {
    /// Scale `s > 0` and half-extent of the square domain in (0, 1.2].
    pub fn new(scale: f64, extent: f64) -> Result<Self, RegistryError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(RegistryError::Constraint(format!(
                "enneper scale = {scale} must be finite and positive"
            )));
        }
        if !(extent > 0.0 && extent <= 1.2) {
            return Err(RegistryError::Constraint(format!(
                "enneper extent = {extent} must lie in (0, 1.2]"
            )));
        }
        Ok(Enneper { scale, extent })
    }
}

impl Surface for Enneper {
    fn domain(&self) -> Domain {
        Domain {
            u: (-self.extent, self.extent),
            v: (-self.extent, self.extent),
            periodic_u: false,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let s = self.scale;
        SurfaceDerivatives {
            p: s * Vec3::new(
                u - u * u * u / 3.0 + u * v * v,
                v - v * v * v / 3.0 + v * u * u,
                u * u - v * v,
            ),
            pu: s * Vec3::new(1.0 - u * u + v * v, 2.0 * u * v, 2.0 * u),
            pv: s * Vec3::new(2.0 * u * v, 1.0 - v * v + u * u, -2.0 * v),
            puu: s * Vec3::new(-2.0 * u, 2.0 * v, 2.0),
            puv: s * Vec3::new(2.0 * v, 2.0 * u, 0.0),
            pvv: s * Vec3::new(2.0 * u, -2.0 * v, -2.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::test_support::*;

    #[test]
    fn derivatives_and_curvature() {
        let sc = 1.3;
        let s = Enneper::new(sc, 1.2).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (1.0, -1.0), (-1.1, 0.7)], 1e-6);
        for i in 0..60 {
            let u = -1.15 + 0.039 * i as f64;
            let v = 1.1 - 0.037 * i as f64;
            let k = 2.0 / (sc * (1.0 + u * u + v * v).powi(2));
            check_curvature(&s, u, v, k, -k, 1e-9);
        }
        assert!(Enneper::new(1.0, 2.0).is_err());
    }
}
