//! The Dupin indicatrix, Dupin conics, conjugate and asymptotic directions (P-Hex paper,
//! section 3, and section 4.2 for conjugate / asymptotic directions).
//!
//! All 2D quantities live in the principal frame of the tangent plane ([`Curvature::frame`]):
//! x along `dir1`, y along `dir2`. There the indicatrix is `k1 x^2 + k2 y^2 = +-1`; its
//! quadratic form `Q(x, y) = k1 x^2 + k2 y^2` is the second fundamental form.

use crate::surface::{Curvature, CurvatureTolerance, PointType};
use crate::{Vec2, Vec3};
use thiserror::Error;

/// Why an indicatrix operation has no answer.
///
/// (P-Hex paper, sections 3 and 4.2.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum IndicatrixError {
    /// A curvature or a direction is NaN or infinite.
    #[error("non-finite curvature or direction")]
    NonFinite,
    /// k1 = k2 = 0 (within tolerance): the indicatrix is undefined.
    #[error("planar point: the Dupin indicatrix is undefined")]
    Planar,
    /// The direction vector is zero.
    #[error("zero direction")]
    ZeroDirection,
    /// At a parabolic point, every direction is conjugate to the zero-curvature direction.
    #[error(
        "the direction is the zero-curvature direction of a parabolic point: its conjugate is undetermined"
    )]
    Undetermined,
    /// Asymptotic directions exist only where K < 0 (or along the ruling where K = 0).
    #[error("no asymptotic directions: the point is not hyperbolic")]
    NotHyperbolic,
}

/// The Dupin indicatrix `k1 x^2 + k2 y^2 = +-1` of a surface point in its principal frame
/// (P-Hex paper, section 3), with the point type fixed at construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DupinIndicatrix {
    k1: f64,
    k2: f64,
    kind: PointType,
}

impl DupinIndicatrix {
    /// Indicatrix of principal curvatures `k1`, `k2`, classified with the default
    /// [`CurvatureTolerance`]. Errors on non-finite input.
    pub fn new(k1: f64, k2: f64) -> Result<Self, IndicatrixError> {
        Self::with_tolerance(k1, k2, &CurvatureTolerance::default())
    }

    /// Same with an explicit tolerance for the point type.
    pub fn with_tolerance(
        k1: f64,
        k2: f64,
        tol: &CurvatureTolerance,
    ) -> Result<Self, IndicatrixError> {
        if !(k1.is_finite() && k2.is_finite()) {
            return Err(IndicatrixError::NonFinite);
        }
        Ok(DupinIndicatrix {
            k1,
            k2,
            kind: PointType::classify(k1, k2, tol),
        })
    }

    /// Curvature along the x axis.
    pub fn k1(&self) -> f64 {
        self.k1
    }

    /// Curvature along the y axis.
    pub fn k2(&self) -> f64 {
        self.k2
    }

    /// Gaussian curvature k1 k2.
    pub fn gaussian(&self) -> f64 {
        self.k1 * self.k2
    }

    /// Point type (elliptic: ellipse; hyperbolic: two hyperbolas; parabolic: parallel lines).
    pub fn point_type(&self) -> PointType {
        self.kind
    }

    /// Q(d) = k1 d.x^2 + k2 d.y^2 (the second fundamental form on d).
    #[inline]
    pub fn quadratic(&self, d: &Vec2) -> f64 {
        self.k1 * d.x * d.x + self.k2 * d.y * d.y
    }

    /// B(d, e) = k1 d.x e.x + k2 d.y e.y; d and e are conjugate when B(d, e) = 0.
    #[inline]
    pub fn bilinear(&self, d: &Vec2, e: &Vec2) -> f64 {
        self.k1 * d.x * e.x + self.k2 * d.y * e.y
    }

    /// The unit direction conjugate to `d` (section 4.2: `B(d, e) = 0`), oriented to the left
    /// of `d` (`d x e >= 0`). An asymptotic direction is its own conjugate.
    ///
    /// Errors: zero or non-finite `d`; a planar point; `d` along the zero-curvature direction of
    /// a parabolic point (then every direction is conjugate to it).
    #[inline]
    pub fn conjugate_direction(&self, d: &Vec2) -> Result<Vec2, IndicatrixError> {
        if !(d.x.is_finite() && d.y.is_finite()) {
            return Err(IndicatrixError::NonFinite);
        }
        if self.kind == PointType::Planar {
            return Err(IndicatrixError::Planar);
        }
        let n = d.norm();
        if n == 0.0 {
            return Err(IndicatrixError::ZeroDirection);
        }
        let d = d / n;
        let e = Vec2::new(-self.k2 * d.y, self.k1 * d.x);
        let en = e.norm();
        let kmax = self.k1.abs().max(self.k2.abs());
        if en <= 1e-12 * kmax {
            return Err(IndicatrixError::Undetermined);
        }
        let e = e / en;
        // d x e = Q(d) / en: flip to the left side when Q(d) < 0.
        Ok(if d.x * e.y - d.y * e.x < 0.0 { -e } else { e })
    }

    /// The two unit asymptotic directions (Q(d) = 0; section 4.2, self-conjugate), for K < 0:
    /// `(sqrt|k2|, +-sqrt|k1|)` normalised. Errors unless the point is hyperbolic.
    pub fn asymptotic_directions(&self) -> Result<[Vec2; 2], IndicatrixError> {
        if self.kind != PointType::Hyperbolic {
            return Err(IndicatrixError::NotHyperbolic);
        }
        let (x, y) = (self.k2.abs().sqrt(), self.k1.abs().sqrt());
        let n = (x * x + y * y).sqrt();
        Ok([Vec2::new(x / n, y / n), Vec2::new(x / n, -y / n)])
    }

    /// The Dupin conic `Q(p - center) = level` (a homothetic copy of the indicatrix, section 3).
    pub fn conic(&self, center: Vec2, level: f64) -> DupinConic {
        DupinConic {
            indicatrix: *self,
            center,
            level,
        }
    }
}

/// A Dupin conic: the homothetic copy `Q(p - center) = level` of the Dupin indicatrix
/// (P-Hex paper, section 3). `level = +-1` with `center = 0` is the indicatrix itself; the
/// homothety ratio is `sqrt(|level|)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DupinConic {
    /// The indicatrix it copies.
    pub indicatrix: DupinIndicatrix,
    /// Its center.
    pub center: Vec2,
    /// Its level.
    pub level: f64,
}

impl DupinConic {
    /// Q(p - center) - level: zero on the conic.
    #[inline]
    pub fn residual(&self, p: &Vec2) -> f64 {
        self.indicatrix.quadratic(&(p - self.center)) - self.level
    }

    /// First-order (Sampson) distance of `p` to the conic: |residual| / |grad residual|.
    /// Exact to second order in the distance; infinite at the center of a degenerate conic.
    pub fn distance_estimate(&self, p: &Vec2) -> f64 {
        let d = p - self.center;
        let g = 2.0 * Vec2::new(self.indicatrix.k1 * d.x, self.indicatrix.k2 * d.y);
        let r = self.residual(p).abs();
        if r == 0.0 { 0.0 } else { r / g.norm() }
    }

    /// Homothety ratio relative to the indicatrix (`sqrt(|level|)`).
    pub fn scale(&self) -> f64 {
        self.level.abs().sqrt()
    }

    /// For a hyperbola (K < 0, level != 0): which branch `p` lies on, +1 or -1 (the sign of
    /// `p - center` along the transverse axis). `None` for ellipses, degenerate conics, or a
    /// point on the conjugate axis.
    pub fn branch(&self, p: &Vec2) -> Option<i8> {
        let (k1, k2) = (self.indicatrix.k1, self.indicatrix.k2);
        if !(k1 * k2 < 0.0) || self.level == 0.0 {
            return None;
        }
        let d = p - self.center;
        let along = if (k1 > 0.0) == (self.level > 0.0) {
            d.x
        } else {
            d.y
        };
        if along > 0.0 {
            Some(1)
        } else if along < 0.0 {
            Some(-1)
        } else {
            None
        }
    }

    /// A point of the conic for drawing: for an ellipse the point at angle parameter `t`; for a
    /// hyperbola the point at hyperbolic parameter `t` on branch `branch` (sign taken). `None`
    /// for parabolic/planar indicatrices or level 0, or an ellipse of the wrong level sign.
    pub fn point_at(&self, t: f64, branch: i8) -> Option<Vec2> {
        let (k1, k2, s) = (self.indicatrix.k1, self.indicatrix.k2, self.level);
        match self.indicatrix.kind {
            PointType::Elliptic if s / k1 > 0.0 => {
                Some(self.center + Vec2::new((s / k1).sqrt() * t.cos(), (s / k2).sqrt() * t.sin()))
            }
            PointType::Hyperbolic if s != 0.0 => {
                let b = if branch < 0 { -1.0 } else { 1.0 };
                Some(if (k1 > 0.0) == (s > 0.0) {
                    self.center
                        + Vec2::new(b * (s / k1).sqrt() * t.cosh(), (-s / k2).sqrt() * t.sinh())
                } else {
                    self.center
                        + Vec2::new((-s / k1).sqrt() * t.sinh(), b * (s / k2).sqrt() * t.cosh())
                })
            }
            _ => None,
        }
    }
}

impl Curvature {
    /// The Dupin indicatrix of this point (default tolerance), in [`Curvature::frame`]
    /// coordinates (P-Hex paper, section 3).
    pub fn indicatrix(&self) -> Result<DupinIndicatrix, IndicatrixError> {
        DupinIndicatrix::new(self.k1, self.k2)
    }

    /// The unit 3D tangent direction conjugate to the tangent direction `t` (its normal
    /// component is ignored), to the left of `t` seen from the normal (section 4.2).
    pub fn conjugate_direction(&self, t: &Vec3) -> Result<Vec3, IndicatrixError> {
        let f = self.frame();
        let e = self
            .indicatrix()?
            .conjugate_direction(&f.vector_to_local(t))?;
        Ok(f.vector_to_world(&e))
    }

    /// The two unit 3D asymptotic directions where K < 0 (section 4.2).
    pub fn asymptotic_directions(&self) -> Result<[Vec3; 2], IndicatrixError> {
        let f = self.frame();
        let [a, b] = self.indicatrix()?.asymptotic_directions()?;
        Ok([f.vector_to_world(&a), f.vector_to_world(&b)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Surface, Torus};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn conjugate_directions_are_conjugate_and_left() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for _ in 0..10_000 {
            let k1 = rng.random_range(-3.0..3.0);
            let k2 = rng.random_range(-3.0..3.0);
            let ind = DupinIndicatrix::new(k1, k2).unwrap();
            let d = Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let Ok(e) = ind.conjugate_direction(&d) else {
                continue;
            };
            assert!((e.norm() - 1.0).abs() < 1e-12);
            assert!(ind.bilinear(&d, &e).abs() < 1e-12 * d.norm() * (k1.abs() + k2.abs()));
            assert!(d.x * e.y - d.y * e.x >= 0.0);
        }
    }

    #[test]
    fn asymptotic_directions_are_self_conjugate() {
        let ind = DupinIndicatrix::new(2.0, -0.5).unwrap();
        for a in ind.asymptotic_directions().unwrap() {
            assert!(ind.quadratic(&a).abs() < 1e-15);
            let c = ind.conjugate_direction(&a).unwrap();
            assert!((c.x * a.y - c.y * a.x).abs() < 1e-12, "self-conjugate");
        }
        assert_eq!(
            DupinIndicatrix::new(2.0, 0.5)
                .unwrap()
                .asymptotic_directions(),
            Err(IndicatrixError::NotHyperbolic)
        );
    }

    #[test]
    fn degenerate_cases_are_typed_errors() {
        let par = DupinIndicatrix::new(1.0, 0.0).unwrap();
        assert_eq!(par.point_type(), PointType::Parabolic);
        assert_eq!(
            par.conjugate_direction(&Vec2::new(0.0, 1.0)),
            Err(IndicatrixError::Undetermined)
        );
        // Every other direction is conjugate to the ruling.
        let e = par.conjugate_direction(&Vec2::new(1.0, 0.3)).unwrap();
        assert!(e.x.abs() < 1e-15);
        let flat = DupinIndicatrix::new(0.0, 0.0).unwrap();
        assert_eq!(
            flat.conjugate_direction(&Vec2::new(1.0, 0.0)),
            Err(IndicatrixError::Planar)
        );
        assert_eq!(
            DupinIndicatrix::new(f64::NAN, 1.0),
            Err(IndicatrixError::NonFinite)
        );
        let ind = DupinIndicatrix::new(1.0, 2.0).unwrap();
        assert_eq!(
            ind.conjugate_direction(&Vec2::zeros()),
            Err(IndicatrixError::ZeroDirection)
        );
        assert_eq!(
            ind.conjugate_direction(&Vec2::new(f64::NAN, 0.0)),
            Err(IndicatrixError::NonFinite)
        );
    }

    #[test]
    fn conic_points_lie_on_the_conic_and_branches_split() {
        for (k1, k2, s) in [
            (2.0, 0.5, 3.0),
            (-1.0, -3.0, -0.5),
            (1.5, -0.7, 2.0),
            (1.5, -0.7, -2.0),
        ] {
            let ind = DupinIndicatrix::new(k1, k2).unwrap();
            let c = ind.conic(Vec2::new(0.3, -0.2), s);
            for i in 0..20 {
                let t = -2.0 + 0.2 * i as f64;
                for br in [1i8, -1] {
                    let p = c.point_at(t, br).unwrap();
                    assert!(
                        c.residual(&p).abs() < 1e-12 * (1.0 + s.abs()) * (1.0 + t.cosh().powi(2))
                    );
                    if k1 * k2 < 0.0 {
                        assert_eq!(c.branch(&p), Some(br));
                    }
                }
            }
        }
    }

    #[test]
    fn indicatrix_approximates_plane_sections() {
        // Section 3: a plane parallel to the tangent plane at height delta cuts S in a curve whose
        // projection, scaled by 1/sqrt(2 delta), tends to the indicatrix Q = +-1.
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let c = t.curvature(0.3, 0.4).unwrap();
        let ind = c.indicatrix().unwrap();
        let f = c.frame();
        let mut prev = f64::INFINITY;
        for k in 0..4 {
            let delta = 1e-2 / 4f64.powi(k);
            let mut worst: f64 = 0.0;
            for i in 0..16 {
                // March along a ray from the point in the tangent plane until the height is delta.
                let ang = std::f64::consts::TAU * i as f64 / 16.0;
                let dir = f.vector_to_world(&Vec2::new(ang.cos(), ang.sin()));
                let h = |s: f64| -> (f64, Vec2) {
                    let q = c.point + dir * s;
                    let cp = t.closest_point(&q, Some(Vec2::new(0.3, 0.4))).unwrap();
                    (-(f.height(&cp.point)), f.to_local(&cp.point))
                };
                let (mut lo, mut hi) = (0.0, 0.5);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if h(mid).0 < delta { lo = mid } else { hi = mid }
                }
                let x = h(lo).1 / (2.0 * delta).sqrt();
                worst = worst.max((ind.quadratic(&x).abs() - 1.0).abs());
            }
            assert!(worst < prev, "section converges to the indicatrix");
            prev = worst;
        }
        assert!(prev < 0.02, "{prev}");
    }
}
