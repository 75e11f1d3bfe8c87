//! The translational freeform surface of the `freeform-parabolic` scene (P-Hex paper, Fig. 22
//! stand-in): not in the registry's catalogue, built by name by the P-Hex pipeline.

use crate::Vec3;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// Name of the scene-only freeform surface of `freeform-parabolic` (see [`FreeformSurface`]).
pub const FREEFORM: &str = "freeform-translational";

/// The translational freeform surface of the `freeform-parabolic` scene (Fig. 22 stand-in):
/// P(u, v) = (u, v, amplitude sin(u) + curl v^2), u in [-2, 2], v in [-1.5, 1.5] (pipeline
/// parameters `amplitude`, default 0.4, and `curl`, default 0.3, each in [-1, 1]). Its parameter
/// lines are conjugate (translational surface), K > 0 for u < 0, K < 0 for u > 0, with the
/// parabolic line u = 0 crossing every base curve.
pub struct FreeformSurface {
    /// Amplitude of the sine profile.
    pub amplitude: f64,
    /// Coefficient of v^2.
    pub curl: f64,
}

impl Surface for FreeformSurface {
    fn domain(&self) -> Domain {
        Domain {
            u: (-2.0, 2.0),
            v: (-1.5, 1.5),
            periodic_u: false,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (su, cu) = u.sin_cos();
        let (a, b) = (self.amplitude, self.curl);
        SurfaceDerivatives {
            p: Vec3::new(u, v, a * su + b * v * v),
            pu: Vec3::new(1.0, 0.0, a * cu),
            pv: Vec3::new(0.0, 1.0, 2.0 * b * v),
            puu: Vec3::new(0.0, 0.0, -a * su),
            puv: Vec3::zeros(),
            pvv: Vec3::new(0.0, 0.0, 2.0 * b),
        }
    }
}
