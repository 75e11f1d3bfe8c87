//! Principal curvatures and directions, Gaussian and mean curvature, point type (P-Hex paper,
//! section 3: the Dupin indicatrix is `k1 x^2 + k2 y^2 = +-1` in the principal frame).
//!
//! Sign convention: curvatures are taken for the unit normal `N` along `Pu x Pv`, with the
//! normal curvature of a tangent direction `t` equal to `II(t, t) / I(t, t)`, `II = P_tt . N`.
//! A sphere with outward normal therefore has `k1 = k2 = -1/r`.
//!
//! Closed-form 2 x 2 symmetric eigen-solution in an orthonormal tangent basis (written by hand:
//! it is a few lines, allocation free, stable at umbilics, and cheaper per vertex in the P-Hex
//! hot loops than a general eigen-solver).

use crate::surface::SurfaceDerivatives;
use crate::{Vec2, Vec3};
use thiserror::Error;

/// Why curvature could not be computed.
///
/// (P-Hex paper, section 3.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum CurvatureError {
    /// The derivatives contain NaN or infinity.
    #[error("the surface derivatives are not finite")]
    NonFinite,
    /// Pu and Pv are (nearly) parallel or zero: no tangent plane (e.g. the pole of a sphere).
    #[error("the parametrisation is singular here (Pu x Pv vanishes)")]
    SingularParametrisation,
}

/// Tolerances deciding the [`PointType`] of a point (P-Hex paper, section 3).
///
/// With `kmax = max(|k1|, |k2|)` and `kmin = min(|k1|, |k2|)`:
/// - planar when `kmax <= planar` (an absolute curvature, in 1 / length units);
/// - otherwise parabolic when `kmin <= parabolic * kmax` (relative);
/// - otherwise elliptic when `k1 k2 > 0`, hyperbolic when `k1 k2 < 0`.
///
/// The defaults (`planar = 1e-9`, `parabolic = 1e-8`) treat analytic zeros evaluated in floating
/// point (about 1e-16 relative) as zero while keeping every genuinely curved point of the
/// surfaces in the library classified by its sign; the P-Hex paper's own detection threshold for
/// parabolic regions (section 6, step 1) is 1e-8.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureTolerance {
    /// Absolute bound on the largest |k| for a planar point.
    pub planar: f64,
    /// Relative bound on the smaller |k| over the larger for a parabolic point.
    pub parabolic: f64,
}

impl Default for CurvatureTolerance {
    fn default() -> Self {
        CurvatureTolerance {
            planar: 1e-9,
            parabolic: 1e-8,
        }
    }
}

/// Classification of a surface point by the sign of its Gaussian curvature (P-Hex paper,
/// section 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PointType {
    /// K > 0: the Dupin indicatrix is an ellipse.
    Elliptic,
    /// K < 0: the Dupin indicatrix is a pair of conjugate hyperbolas.
    Hyperbolic,
    /// K = 0, one principal curvature non-zero: the indicatrix is a pair of parallel lines.
    Parabolic,
    /// k1 = k2 = 0: the indicatrix is undefined.
    Planar,
}

impl PointType {
    /// Classifies principal curvatures `k1`, `k2` with tolerance `tol`.
    pub fn classify(k1: f64, k2: f64, tol: &CurvatureTolerance) -> PointType {
        let (a, b) = (k1.abs(), k2.abs());
        let kmax = a.max(b);
        let kmin = a.min(b);
        if kmax <= tol.planar {
            PointType::Planar
        } else if kmin <= tol.parabolic * kmax {
            PointType::Parabolic
        } else if k1 * k2 > 0.0 {
            PointType::Elliptic
        } else {
            PointType::Hyperbolic
        }
    }

    /// The lower-case name used by the CLI (`elliptic`, `hyperbolic`, `parabolic`, `planar`).
    pub fn name(self) -> &'static str {
        match self {
            PointType::Elliptic => "elliptic",
            PointType::Hyperbolic => "hyperbolic",
            PointType::Parabolic => "parabolic",
            PointType::Planar => "planar",
        }
    }
}

/// An orthonormal frame of a tangent plane: origin, two tangent axes and the normal
/// (`e1 x e2 = normal`). Used to move between 3D and the 2D coordinates in which the Dupin
/// indicatrix, Dupin conics and Dupin centers live (P-Hex paper, section 4.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentFrame {
    /// The point of tangency.
    pub origin: Vec3,
    /// First unit tangent axis (x).
    pub e1: Vec3,
    /// Second unit tangent axis (y).
    pub e2: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

impl TangentFrame {
    /// 2D coordinates of the vertical (orthogonal) projection of `p` onto the plane.
    #[inline]
    pub fn to_local(&self, p: &Vec3) -> Vec2 {
        let d = p - self.origin;
        Vec2::new(d.dot(&self.e1), d.dot(&self.e2))
    }

    /// Height of `p` above the plane, along the normal.
    #[inline]
    pub fn height(&self, p: &Vec3) -> f64 {
        (p - self.origin).dot(&self.normal)
    }

    /// The 3D point of the plane with 2D coordinates `q`.
    #[inline]
    pub fn to_world(&self, q: &Vec2) -> Vec3 {
        self.origin + self.e1 * q.x + self.e2 * q.y
    }

    /// 2D components of the tangential part of the vector `d`.
    #[inline]
    pub fn vector_to_local(&self, d: &Vec3) -> Vec2 {
        Vec2::new(d.dot(&self.e1), d.dot(&self.e2))
    }

    /// The 3D tangent vector with 2D components `q`.
    #[inline]
    pub fn vector_to_world(&self, q: &Vec2) -> Vec3 {
        self.e1 * q.x + self.e2 * q.y
    }
}

/// Curvature at one surface point (P-Hex paper, section 3).
///
/// `k1 >= k2` are the principal curvatures for `normal` (along Pu x Pv); `dir1`, `dir2` the unit
/// principal directions with `dir1 x dir2 = normal` (an orthonormal frame even at umbilics, where
/// `dir1` is Pu normalised). `gaussian = k1 k2`, `mean = (k1 + k2) / 2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature {
    /// The surface point.
    pub point: Vec3,
    /// Unit normal along Pu x Pv.
    pub normal: Vec3,
    /// Larger principal curvature.
    pub k1: f64,
    /// Smaller principal curvature.
    pub k2: f64,
    /// Unit principal direction of k1.
    pub dir1: Vec3,
    /// Unit principal direction of k2.
    pub dir2: Vec3,
    /// Gaussian curvature K = k1 k2.
    pub gaussian: f64,
    /// Mean curvature H = (k1 + k2) / 2.
    pub mean: f64,
}

impl Curvature {
    /// Curvature from position and derivatives up to second order (shape operator I^-1 II).
    ///
    /// Errors: non-finite input, or a singular parametrisation (|Pu x Pv| below 1e-12 of
    /// |Pu| |Pv|, or min(|Pu|, |Pv|) below 1e-12 of the max). Never returns NaN.
    pub fn from_derivatives(d: &SurfaceDerivatives) -> Result<Curvature, CurvatureError> {
        let finite = |v: &Vec3| v.iter().all(|c| c.is_finite());
        if !(finite(&d.p)
            && finite(&d.pu)
            && finite(&d.pv)
            && finite(&d.puu)
            && finite(&d.puv)
            && finite(&d.pvv))
        {
            return Err(CurvatureError::NonFinite);
        }
        let cross = d.pu.cross(&d.pv);
        let (nu, nv) = (d.pu.norm(), d.pv.norm());
        let area = cross.norm();
        // Singular: Pu, Pv (nearly) parallel, or one of them vanishing against the other (the
        // pole of a sphere, where |Pu| = r cos v).
        if !(area > 1e-12 * nu * nv) || area == 0.0 || nu.min(nv) <= 1e-12 * nu.max(nv) {
            return Err(CurvatureError::SingularParametrisation);
        }
        let normal = cross / area;
        let (l, m, n) = (d.puu.dot(&normal), d.puv.dot(&normal), d.pvv.dot(&normal));
        // Orthonormal tangent basis e1 = Pu/|Pu|, e2 = N x e1. With J the (upper triangular)
        // coordinates of Pu, Pv in it, the shape operator there is the symmetric
        // W = J^-T II J^-1: its eigen-solution is stable even at umbilics, unlike sqrt(H^2 - K).
        let e1 = d.pu / nu;
        let e2 = normal.cross(&e1);
        let (j11, j12, j22) = (nu, d.pv.dot(&e1), d.pv.dot(&e2));
        // J^-1 = [[1/j11, -j12/(j11 j22)], [0, 1/j22]].
        let (i11, i12, i22) = (1.0 / j11, -j12 / (j11 * j22), 1.0 / j22);
        let w11 = l * i11 * i11;
        let w12 = i11 * (l * i12 + m * i22);
        let w22 = i12 * (l * i12 + m * i22) + i22 * (m * i12 + n * i22);
        let half = 0.5 * (w11 - w22);
        let disc = half.hypot(w12);
        let avg = 0.5 * (w11 + w22);
        let k1 = avg + disc;
        let k2 = avg - disc;
        // Eigenvector of k1 in (e1, e2): (w12, k1 - w11) or (k1 - w22, w12), the longer.
        let v1 = Vec2::new(w12, k1 - w11);
        let v2 = Vec2::new(k1 - w22, w12);
        let w = if v1.norm_squared() >= v2.norm_squared() {
            v1
        } else {
            v2
        };
        let dir1 = match w.try_normalize(0.0) {
            Some(w) if disc > 0.0 => e1 * w.x + e2 * w.y,
            // Umbilic: every direction is principal.
            _ => e1,
        };
        let dir2 = normal.cross(&dir1);
        if !(k1.is_finite() && k2.is_finite()) {
            return Err(CurvatureError::NonFinite);
        }
        Ok(Curvature {
            point: d.p,
            normal,
            k1,
            k2,
            dir1,
            dir2,
            gaussian: k1 * k2,
            mean: 0.5 * (k1 + k2),
        })
    }

    /// The point type with tolerance `tol` (see [`CurvatureTolerance`]).
    pub fn point_type(&self, tol: &CurvatureTolerance) -> PointType {
        PointType::classify(self.k1, self.k2, tol)
    }

    /// The principal frame: origin at the point, axes `dir1`, `dir2`, `normal`. Dupin indicatrix
    /// coordinates (P-Hex paper, section 3) are 2D coordinates in this frame.
    pub fn frame(&self) -> TangentFrame {
        TangentFrame {
            origin: self.point,
            e1: self.dir1,
            e2: self.dir2,
            normal: self.normal,
        }
    }

    /// Normal curvature `k1 cos^2 + k2 sin^2` (Euler) of the unit tangent direction `t` (its
    /// normal component is ignored; zero vector gives 0).
    pub fn normal_curvature(&self, t: &Vec3) -> f64 {
        let x = t.dot(&self.dir1);
        let y = t.dot(&self.dir2);
        let n2 = x * x + y * y;
        if n2 > 0.0 {
            (self.k1 * x * x + self.k2 * y * y) / n2
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Surface, Torus};

    #[test]
    fn torus_principal_directions_follow_parameter_lines() {
        let t = Torus {
            major: 2.0,
            minor: 0.5,
        };
        for &(u, v) in &[(0.3, 0.2), (1.0, 2.5), (4.0, 4.0)] {
            let c = t.curvature(u, v).unwrap();
            let d = t.derivatives(u, v);
            let ku = -v.cos() / (2.0 + 0.5 * v.cos());
            let kv = -1.0 / 0.5;
            // The direction of k_u is Pu.
            let (dir_u, k_u_got) = if (c.k1 - ku).abs() < 1e-9 {
                (c.dir1, c.k1)
            } else {
                (c.dir2, c.k2)
            };
            assert!((k_u_got - ku).abs() < 1e-12);
            assert!(dir_u.cross(&d.pu.normalize()).norm() < 1e-9);
            assert!(
                (c.normal_curvature(&d.pv) - kv).abs() < 1e-12,
                "Euler along Pv"
            );
            // Orthonormal right-handed frame.
            assert!((c.dir1.cross(&c.dir2) - c.normal).norm() < 1e-12);
            assert!(c.k1 >= c.k2);
        }
    }

    #[test]
    fn classify_uses_the_documented_tolerances() {
        let tol = CurvatureTolerance::default();
        assert_eq!(PointType::classify(1.0, 2.0, &tol), PointType::Elliptic);
        assert_eq!(PointType::classify(-1.0, -2.0, &tol), PointType::Elliptic);
        assert_eq!(PointType::classify(1.0, -2.0, &tol), PointType::Hyperbolic);
        assert_eq!(PointType::classify(1.0, 1e-9, &tol), PointType::Parabolic);
        assert_eq!(PointType::classify(1.0, -1e-9, &tol), PointType::Parabolic);
        assert_eq!(PointType::classify(1.0, 2e-8, &tol), PointType::Elliptic);
        assert_eq!(PointType::classify(1e-10, -1e-10, &tol), PointType::Planar);
        assert_eq!(PointType::classify(2e-9, 0.0, &tol), PointType::Parabolic);
    }

    #[test]
    fn degenerate_derivatives_are_typed_errors() {
        let t = Torus {
            major: 2.0,
            minor: 0.5,
        };
        let mut d = t.derivatives(0.1, 0.2);
        d.puv.y = f64::NAN;
        assert_eq!(
            Curvature::from_derivatives(&d),
            Err(CurvatureError::NonFinite)
        );
        let s = crate::surface::Sphere { radius: 1.0 };
        assert_eq!(
            s.curvature(0.3, std::f64::consts::FRAC_PI_2),
            Err(CurvatureError::SingularParametrisation)
        );
        let mut d = t.derivatives(0.1, 0.2);
        d.pv = d.pu * 2.0;
        assert_eq!(
            Curvature::from_derivatives(&d),
            Err(CurvatureError::SingularParametrisation)
        );
    }
}
