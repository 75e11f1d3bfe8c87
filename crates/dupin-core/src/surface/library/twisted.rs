//! A surface with a sheared parametrisation: the spiral patterns of the P-Hex paper (Fig. 20).

use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// A surface re-parametrised as P(u + twist v, v): its v-lines become spirals (used for the
/// spiral sphere pattern of Fig. 20).
pub struct TwistedSurface {
    /// The original surface.
    pub inner: Box<dyn Surface>,
    /// Shear factor.
    pub twist: f64,
}

impl Surface for TwistedSurface {
    fn domain(&self) -> Domain {
        self.inner.domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let t = self.twist;
        let d = self.inner.derivatives(u + t * v, v);
        SurfaceDerivatives {
            p: d.p,
            pu: d.pu,
            pv: d.pu * t + d.pv,
            puu: d.puu,
            puv: d.puu * t + d.puv,
            pvv: d.puu * (t * t) + d.puv * (2.0 * t) + d.pvv,
        }
    }
}
