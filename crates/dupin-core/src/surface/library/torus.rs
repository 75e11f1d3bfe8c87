//! Torus of revolution, parametrised as in the outside contract.

use crate::Vec3;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// Torus ((R + r cos v) cos u, (R + r cos v) sin u, r sin v), u, v in [0, 2 pi), both periodic.
///
/// `major` is R (distance from the axis to the tube centre), `minor` is r (tube radius).
/// K > 0 on the outer half (cos v > 0), K < 0 on the inner half, parabolic circles at v = +-pi/2.
///
/// (P-Hex paper, section 5.3, Figs. 3, 17 right and 19.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torus {
    /// R, the distance from the axis to the centre of the tube.
    pub major: f64,
    /// r, the radius of the tube.
    pub minor: f64,
}

impl Surface for Torus {
    fn domain(&self) -> Domain {
        Domain::full_turns()
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (su, cu) = u.sin_cos();
        let (sv, cv) = v.sin_cos();
        let (big, r) = (self.major, self.minor);
        let w = big + r * cv;
        SurfaceDerivatives {
            p: Vec3::new(w * cu, w * su, r * sv),
            pu: Vec3::new(-w * su, w * cu, 0.0),
            pv: Vec3::new(-r * sv * cu, -r * sv * su, r * cv),
            puu: Vec3::new(-w * cu, -w * su, 0.0),
            puv: Vec3::new(r * sv * su, -r * sv * cu, 0.0),
            pvv: Vec3::new(-r * cv * cu, -r * cv * su, -r * sv),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let h = 1e-6;
        for &(u, v) in &[(0.3, 1.1), (2.0, -0.4), (5.0, 3.0)] {
            let d = t.derivatives(u, v);
            let fu = (t.position(u + h, v) - t.position(u - h, v)) / (2.0 * h);
            let fv = (t.position(u, v + h) - t.position(u, v - h)) / (2.0 * h);
            assert!((fu - d.pu).norm() < 1e-8);
            assert!((fv - d.pv).norm() < 1e-8);
            let duu = (t.derivatives(u + h, v).pu - t.derivatives(u - h, v).pu) / (2.0 * h);
            let duv = (t.derivatives(u, v + h).pu - t.derivatives(u, v - h).pu) / (2.0 * h);
            let dvv = (t.derivatives(u, v + h).pv - t.derivatives(u, v - h).pv) / (2.0 * h);
            assert!((duu - d.puu).norm() < 1e-7);
            assert!((duv - d.puv).norm() < 1e-7);
            assert!((dvv - d.pvv).norm() < 1e-7);
        }
    }

    #[test]
    fn curvature_matches_closed_forms() {
        use crate::surface::test_support::check_curvature;
        let (big, r) = (2.0, 0.7);
        let t = Torus {
            major: big,
            minor: r,
        };
        for i in 0..80 {
            let u = 0.079 * i as f64;
            let v = 0.013 + 0.0787 * i as f64;
            // k along the parallels -cos v / (R + r cos v), along the meridians -1/r.
            let (ku, kv) = (-v.cos() / (big + r * v.cos()), -1.0 / r);
            check_curvature(&t, u, v, ku.max(kv), ku.min(kv), 1e-9);
        }
    }

    #[test]
    fn outer_normal_points_outward() {
        let t = Torus {
            major: 2.0,
            minor: 0.5,
        };
        let n = t.normal(0.0, 0.0);
        assert!((n - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    }
}
