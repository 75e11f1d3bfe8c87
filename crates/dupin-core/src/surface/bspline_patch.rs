//! Freeform bicubic B-spline patch with an editable control net (P-Hex paper, Figs. 1 bottom
//! right and 22: freeform surfaces with parabolic curves).

use super::{Domain, Surface, SurfaceDerivatives};
use crate::Vec3;
use thiserror::Error;

/// Why a control net was rejected.
///
/// (P-Hex paper, section 7, Fig. 22.)
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BSplinePatchError {
    /// A bicubic patch needs at least 4 x 4 control points.
    #[error("a bicubic patch needs at least 4 x 4 control points, got {nu} x {nv}")]
    TooSmall {
        /// Control points along u.
        nu: usize,
        /// Control points along v.
        nv: usize,
    },
    /// The number of points does not match nu x nv.
    #[error("expected {expected} control points, got {got}")]
    WrongCount {
        /// nu x nv.
        expected: usize,
        /// What was given.
        got: usize,
    },
    /// A control point has a NaN or infinite coordinate.
    #[error("control point ({i}, {j}) is not finite")]
    NonFinite {
        /// Index along u.
        i: usize,
        /// Index along v.
        j: usize,
    },
    /// An index is outside the net.
    #[error("control point ({i}, {j}) is outside the {nu} x {nv} net")]
    OutOfRange {
        /// Index along u.
        i: usize,
        /// Index along v.
        j: usize,
        /// Control points along u.
        nu: usize,
        /// Control points along v.
        nv: usize,
    },
}

/// Uniform bicubic B-spline patch. Control point (i, j), i < nu, j < nv, is stored at
/// `i * nv + j`; the domain is u in [0, nu - 3], v in [0, nv - 3] (one unit per knot span).
///
/// (P-Hex paper, section 7, Fig. 22.)
#[derive(Debug, Clone, PartialEq)]
pub struct BSplinePatch {
    nu: usize,
    nv: usize,
    points: Vec<Vec3>,
}

/// Uniform cubic B-spline basis values, first and second derivatives at t in [0, 1].
#[inline]
fn basis(t: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    (
        [
            s * s * s / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ],
        [
            -0.5 * s * s,
            (3.0 * t2 - 4.0 * t) / 2.0,
            (-3.0 * t2 + 2.0 * t + 1.0) / 2.0,
            0.5 * t2,
        ],
        [s, 3.0 * t - 2.0, 1.0 - 3.0 * t, t],
    )
}

impl BSplinePatch {
    /// A patch from an `nu` x `nv` net (row-major: index `i * nv + j`).
    pub fn new(nu: usize, nv: usize, points: Vec<Vec3>) -> Result<Self, BSplinePatchError> {
        if nu < 4 || nv < 4 {
            return Err(BSplinePatchError::TooSmall { nu, nv });
        }
        if points.len() != nu * nv {
            return Err(BSplinePatchError::WrongCount {
                expected: nu * nv,
                got: points.len(),
            });
        }
        if let Some(k) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(BSplinePatchError::NonFinite {
                i: k / nv,
                j: k % nv,
            });
        }
        Ok(BSplinePatch { nu, nv, points })
    }

    /// A net sampled from a height field: control point (i, j) at
    /// (x_i, y_j, height(x_i, y_j)) with x_i, y_j evenly spaced over [-size, size].
    pub fn from_height_field(
        nu: usize,
        nv: usize,
        size: f64,
        height: impl Fn(f64, f64) -> f64,
    ) -> Result<Self, BSplinePatchError> {
        let mut pts = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            let x = -size + 2.0 * size * i as f64 / (nu.max(2) - 1) as f64;
            for j in 0..nv {
                let y = -size + 2.0 * size * j as f64 / (nv.max(2) - 1) as f64;
                pts.push(Vec3::new(x, y, height(x, y)));
            }
        }
        Self::new(nu, nv, pts)
    }

    /// Net size (nu, nv).
    pub fn net_size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }

    /// All control points, row-major.
    pub fn control_points(&self) -> &[Vec3] {
        &self.points
    }

    /// Control point (i, j), if it exists.
    pub fn control_point(&self, i: usize, j: usize) -> Option<Vec3> {
        (i < self.nu && j < self.nv).then(|| self.points[i * self.nv + j])
    }

    /// Moves control point (i, j) (editing the net).
    pub fn set_control_point(
        &mut self,
        i: usize,
        j: usize,
        p: Vec3,
    ) -> Result<(), BSplinePatchError> {
        if i >= self.nu || j >= self.nv {
            return Err(BSplinePatchError::OutOfRange {
                i,
                j,
                nu: self.nu,
                nv: self.nv,
            });
        }
        if !p.iter().all(|c| c.is_finite()) {
            return Err(BSplinePatchError::NonFinite { i, j });
        }
        self.points[i * self.nv + j] = p;
        Ok(())
    }
}

impl Surface for BSplinePatch {
    fn domain(&self) -> Domain {
        Domain {
            u: (0.0, (self.nu - 3) as f64),
            v: (0.0, (self.nv - 3) as f64),
            periodic_u: false,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let span = |x: f64, n: usize| -> (usize, f64) {
            let last = (n - 4) as f64;
            let fl = if x.is_finite() {
                x.floor().clamp(0.0, last)
            } else {
                0.0
            };
            (fl as usize, x - fl)
        };
        let (i0, tu) = span(u, self.nu);
        let (j0, tv) = span(v, self.nv);
        let (bu, du, ddu) = basis(tu);
        let (bv, dv, ddv) = basis(tv);
        let mut d = SurfaceDerivatives {
            p: Vec3::zeros(),
            pu: Vec3::zeros(),
            pv: Vec3::zeros(),
            puu: Vec3::zeros(),
            puv: Vec3::zeros(),
            pvv: Vec3::zeros(),
        };
        for a in 0..4 {
            for b in 0..4 {
                let c = self.points[(i0 + a) * self.nv + j0 + b];
                d.p += c * (bu[a] * bv[b]);
                d.pu += c * (du[a] * bv[b]);
                d.pv += c * (bu[a] * dv[b]);
                d.puu += c * (ddu[a] * bv[b]);
                d.puv += c * (du[a] * dv[b]);
                d.pvv += c * (bu[a] * ddv[b]);
            }
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::graph_curvatures;
    use crate::surface::test_support::*;

    #[test]
    fn reproduces_a_quadratic_graph_exactly() {
        // Control points (i - 1, j - 1, q(i - 1, j - 1)) of a quadratic q = al x^2 + be x y + ga y^2:
        // a uniform cubic B-spline reproduces x exactly and x^2 as x^2 + 1/3, so the patch is the
        // graph z = al (u^2 + 1/3) + be u v + ga (v^2 + 1/3) over (x, y) = (u, v) - offset.
        let (al, be, ga) = (0.3, -0.2, -0.25);
        let (nu, nv) = (8, 7);
        let mut pts = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (x, y) = (i as f64 - 1.0, j as f64 - 1.0);
                pts.push(Vec3::new(x, y, al * x * x + be * x * y + ga * y * y));
            }
        }
        let s = BSplinePatch::new(nu, nv, pts).unwrap();
        check_derivatives(&s, &[(0.3, 0.2), (2.5, 1.0), (4.4, 3.3)], 1e-6);
        for i in 0..60 {
            let u = 0.01 + 0.083 * i as f64;
            let v = 3.95 - 0.065 * i as f64;
            let p = s.position(u, v);
            let z = al * (u * u + 1.0 / 3.0) + be * u * v + ga * (v * v + 1.0 / 3.0);
            assert!((p - Vec3::new(u, v, z)).norm() < 1e-12);
            let (k1, k2) = graph_curvatures(
                2.0 * al * u + be * v,
                be * u + 2.0 * ga * v,
                2.0 * al,
                be,
                2.0 * ga,
            );
            check_curvature(&s, u, v, k1, k2, 1e-9);
        }
    }

    #[test]
    fn editing_the_net_moves_the_surface_locally() {
        let mut s = BSplinePatch::from_height_field(6, 6, 1.0, |_, _| 0.0).unwrap();
        let before = s.position(0.5, 0.5);
        s.set_control_point(5, 5, Vec3::new(1.0, 1.0, 3.0)).unwrap();
        assert_eq!(s.position(0.5, 0.5), before, "outside the point's support");
        assert!(s.position(2.9, 2.9).z > 0.01);
        assert!(s.set_control_point(6, 0, Vec3::zeros()).is_err());
        assert!(
            s.set_control_point(0, 0, Vec3::new(f64::NAN, 0.0, 0.0))
                .is_err()
        );
        assert!(BSplinePatch::new(3, 5, vec![Vec3::zeros(); 15]).is_err());
        assert!(BSplinePatch::new(4, 4, vec![Vec3::zeros(); 15]).is_err());
    }
}
