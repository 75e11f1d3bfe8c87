//! Parametric surfaces P(u, v) with analytic derivatives (P-Hex paper, section 3).

mod torus;

pub use torus::Torus;

use crate::math::Vec3;

/// The parameter rectangle of a surface and which directions wrap around.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Range of u.
    pub u: (f64, f64),
    /// Range of v.
    pub v: (f64, f64),
    /// Whether u is periodic with period `u.1 - u.0`.
    pub periodic_u: bool,
    /// Whether v is periodic with period `v.1 - v.0`.
    pub periodic_v: bool,
}

/// Position and first and second partial derivatives of P at one parameter point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivatives {
    /// P(u, v).
    pub p: Vec3,
    /// dP/du.
    pub pu: Vec3,
    /// dP/dv.
    pub pv: Vec3,
    /// d2P/du2.
    pub puu: Vec3,
    /// d2P/dudv.
    pub puv: Vec3,
    /// d2P/dv2.
    pub pvv: Vec3,
}

/// A smooth parametric surface. Implementors give analytic derivatives where they exist; all
/// differential geometry (normals, fundamental forms, curvature) is derived from them.
pub trait Surface: Send + Sync {
    /// Parameter domain and periodicity.
    fn domain(&self) -> Domain;

    /// Position and derivatives up to second order at (u, v).
    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives;

    /// P(u, v).
    fn position(&self, u: f64, v: f64) -> Vec3 {
        self.derivatives(u, v).p
    }

    /// Unit normal along Pu x Pv (zero where the parametrisation is singular).
    fn normal(&self, u: f64, v: f64) -> Vec3 {
        let d = self.derivatives(u, v);
        d.pu.cross(&d.pv)
            .try_normalize(0.0)
            .unwrap_or_else(Vec3::zeros)
    }
}
