//! Ideal triangles (P-Hex paper, section 4.2 "Optimal shape of P-Hex faces" and section 5.1,
//! Fig. 13): given the base AB, the apex C on the line through the midpoint M conjugate to AB
//! such that the Dupin center of ABC is at the centroid (K > 0, affine regular Dupin hexagon) or
//! at (A + B + 4C) / 6 (K < 0, affine quasi-regular Dupin hexagon).
//!
//! Construction (section 5.1): w is the unit direction conjugate to AB; D = A + t w and
//! E = B + t w with DE tangent to the Dupin ellipse with diameter AB (K > 0: Q(t w) = Q(AB/2)),
//! or with MD, ME on the asymptotes of the Dupin hyperbola centered at M (K < 0:
//! Q(t w) = -Q(AB/2)); then C = M + sqrt(3) t w, i.e. |CM| = sqrt(3) |AD|.
//! Note: for K < 0 the paper's text says |CM| = sqrt(3)|AE|; the rule that places the Dupin
//! center at (A + B + 4C)/6 is |CM| = sqrt(3)|AD| (as for K > 0), which the tests verify.
//! Any apex on the line beyond DE gives a valid triangle star (Propositions 4 and 5).

use crate::phex::{DupinIndicatrix, IndicatrixError};
use crate::surface::{Curvature, PointType};
use crate::{Vec2, Vec3};
use thiserror::Error;

/// Why no ideal triangle exists on this base.
///
/// (P-Hex paper, section 5.1.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum IdealTriangleError {
    /// A point or curvature is NaN or infinite.
    #[error("non-finite base point or curvature")]
    NonFinite,
    /// A = B.
    #[error("the base AB has zero length")]
    DegenerateBase,
    /// K = 0: the construction fails (section 5.3: the step size |CM| becomes 0 or infinite).
    #[error("the point is {0:?}: no ideal triangle (K = 0, see section 5.3)")]
    ZeroGaussianCurvature(PointType),
    /// K < 0 and AB lies along an asymptotic direction (self-conjugate): no apex line.
    #[error("the base AB lies along an asymptotic direction")]
    AsymptoticBase,
}

/// An ideal triangle ABC and the auxiliary points of its construction (section 5.1, Fig. 13),
/// in the indicatrix's principal frame. C lies to the left of AB (swap A and B for the other
/// side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdealTriangle {
    /// Base vertex A.
    pub a: Vec2,
    /// Base vertex B.
    pub b: Vec2,
    /// The apex C.
    pub c: Vec2,
    /// Midpoint M of AB.
    pub m: Vec2,
    /// D = A + t w: with E, the line DE bounds the valid region.
    pub d: Vec2,
    /// E = B + t w.
    pub e: Vec2,
    /// Unit direction w of the line l through M conjugate to AB (to the left of AB).
    pub direction: Vec2,
    /// |CM| = sqrt(3) t.
    pub step: f64,
}

impl IdealTriangle {
    /// Where the Dupin center of ABC lies by construction: the centroid (K > 0) or
    /// (A + B + 4C) / 6 (K < 0).
    pub fn ideal_dupin_center(&self, ind: &DupinIndicatrix) -> Vec2 {
        if ind.gaussian() > 0.0 {
            (self.a + self.b + self.c) / 3.0
        } else {
            (self.a + self.b + 4.0 * self.c) / 6.0
        }
    }

    /// Whether `p` lies strictly beyond the line DE, on the side away from AB: any apex there
    /// (on the line l) gives a valid triangle star (Propositions 4 and 5).
    pub fn beyond_de(&self, p: &Vec2) -> bool {
        let u = self.e - self.d;
        let side = |q: &Vec2| {
            let r = q - self.d;
            u.x * r.y - u.y * r.x
        };
        side(p) * side(&self.m) < 0.0
    }
}

/// The ideal triangle on base AB (section 5.1). Inputs in the principal frame of `ind`.
///
/// Errors: non-finite input, A = B, K = 0, or (K < 0) AB along an asymptotic direction.
#[inline]
pub fn ideal_triangle(
    ind: &DupinIndicatrix,
    a: &Vec2,
    b: &Vec2,
) -> Result<IdealTriangle, IdealTriangleError> {
    let kind = ind.point_type();
    if kind == PointType::Parabolic || kind == PointType::Planar {
        return Err(IdealTriangleError::ZeroGaussianCurvature(kind));
    }
    if !(a.iter().chain(b.iter()).all(|x| x.is_finite())) {
        return Err(IdealTriangleError::NonFinite);
    }
    let ab = b - a;
    let len = ab.norm();
    if len == 0.0 {
        return Err(IdealTriangleError::DegenerateBase);
    }
    let w = ind.conjugate_direction(&ab).map_err(|e| match e {
        IndicatrixError::NonFinite => IdealTriangleError::NonFinite,
        IndicatrixError::ZeroDirection => IdealTriangleError::DegenerateBase,
        _ => IdealTriangleError::ZeroGaussianCurvature(kind),
    })?;
    let h = ab * 0.5;
    let (qh, qw) = (ind.quadratic(&h), ind.quadratic(&w));
    let kmax = ind.k1().abs().max(ind.k2().abs());
    if !(qh.abs() > 1e-12 * kmax * h.norm_squared()) || !(qw.abs() > 1e-12 * kmax) {
        return Err(IdealTriangleError::AsymptoticBase);
    }
    // K > 0: Q(t w) = Q(h) (the point M + t w is on the ellipse with diameter AB, where the
    // tangent is parallel to AB). K < 0: Q(h - t w) = Q(h) + t^2 Q(w) = 0 (MD on an asymptote).
    let t2 = if kind == PointType::Elliptic {
        qh / qw
    } else {
        -qh / qw
    };
    if !(t2 > 0.0 && t2.is_finite()) {
        return Err(IdealTriangleError::AsymptoticBase);
    }
    let t = t2.sqrt();
    let m = a + h;
    let step = 3f64.sqrt() * t;
    Ok(IdealTriangle {
        a: *a,
        b: *b,
        c: m + w * step,
        m,
        d: a + w * t,
        e: b + w * t,
        direction: w,
        step,
    })
}

/// The apex C (a 3D point of the tangent plane of `curv`) of the ideal triangle on the base AB
/// projected into that tangent plane (the step of section 5.2's triangulation methods). C is on
/// the left of AB seen from the normal.
pub fn ideal_apex_3d(curv: &Curvature, a: &Vec3, b: &Vec3) -> Result<Vec3, IdealTriangleError> {
    let f = curv.frame();
    let ind = curv
        .indicatrix()
        .map_err(|_| IdealTriangleError::NonFinite)?;
    let t = ideal_triangle(&ind, &f.to_local(a), &f.to_local(b))?;
    Ok(f.to_world(&t.c))
}

/// Whether a centrally symmetric hexagon (vertices relative to its center) is affine regular:
/// h_(i+1) = h_i + h_(i+2) for all i (true for the regular hexagon, preserved by linear maps),
/// to relative tolerance `tol`.
///
/// (P-Hex paper, section 4.2, Fig. 12 left.)
pub fn is_affine_regular_hexagon(h: &[Vec2; 6], center: &Vec2, tol: f64) -> bool {
    let r = h.map(|p| p - center);
    let scale = r.iter().map(|v| v.norm()).fold(0.0, f64::max);
    scale > 0.0
        && (0..6).all(|i| (r[(i + 1) % 6] - r[i] - r[(i + 2) % 6]).norm() <= tol * scale)
        && cross(&r[0], &r[2]).abs() > tol * scale * scale
}

/// Whether a hexagon is affine quasi-regular (P-Hex paper, Fig. 12 right: two halves of a
/// regular hexagon juxtaposed along their short sides): centrally symmetric, and for some
/// vertex k, h_(k+1) = (h_k + h_(k+2)) / 4 relative to the center with h_k, h_(k+2) independent
/// (the canonical one is (1,2), (0,1), (-1,2), (-1,-2), (0,-1), (1,-2)). Relative tolerance `tol`.
pub fn is_affine_quasi_regular_hexagon(h: &[Vec2; 6], center: &Vec2, tol: f64) -> bool {
    let r = h.map(|p| p - center);
    let scale = r.iter().map(|v| v.norm()).fold(0.0, f64::max);
    if !(scale > 0.0) || !(0..3).all(|i| (r[i] + r[i + 3]).norm() <= tol * scale) {
        return false;
    }
    (0..6).any(|k| {
        let (p, q, s) = (r[k], r[(k + 1) % 6], r[(k + 2) % 6]);
        (q - (p + s) / 4.0).norm() <= tol * scale && cross(&p, &s).abs() > tol * scale * scale
    })
}

fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::is_simple_polygon;
    use crate::phex::TriangleStar;
    use crate::phex::dupin_center;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_case(rng: &mut ChaCha8Rng, sign: f64) -> (DupinIndicatrix, Vec2, Vec2) {
        let flip = if rng.random_bool(0.5) { -1.0 } else { 1.0 };
        let k1: f64 = flip * rng.random_range(0.1..5.0);
        let k2: f64 = flip * sign * rng.random_range(0.1..5.0);
        let ind = DupinIndicatrix::new(k1, k2).unwrap();
        let a = Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let b = a + Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        (ind, a, b)
    }

    #[test]
    fn dupin_center_lands_on_the_ideal_location() {
        let mut rng = ChaCha8Rng::seed_from_u64(51);
        let mut worst = [0.0f64; 2];
        for (si, sign) in [1.0, -1.0].into_iter().enumerate() {
            let mut n = 0;
            while n < 10_000 {
                let (ind, a, b) = random_case(&mut rng, sign);
                let Ok(t) = ideal_triangle(&ind, &a, &b) else {
                    continue;
                };
                // Keep well-shaped bases: skip nearly asymptotic ones whose apex runs far away.
                if t.step > 20.0 * (b - a).norm() {
                    continue;
                }
                n += 1;
                let o = dupin_center(&ind, &t.a, &t.b, &t.c).unwrap();
                let want = if sign > 0.0 {
                    (t.a + t.b + t.c) / 3.0
                } else {
                    (t.a + t.b + 4.0 * t.c) / 6.0
                };
                assert_eq!(t.ideal_dupin_center(&ind), want);
                let scale = 1.0 + t.a.norm().max(t.b.norm()).max(t.c.norm());
                let err = (o - want).norm() / scale;
                worst[si] = worst[si].max(err);
                assert!(err <= 1e-12, "Dupin center off by {err}");
                // C is left of AB, on the conjugate line through M.
                assert!(cross(&(t.b - t.a), &(t.c - t.a)) > 0.0);
                assert!(
                    ind.bilinear(&(t.b - t.a), &(t.c - t.m)).abs() <= 1e-9 * scale * scale * 5.0
                );
                // The Dupin hexagon of the star is affine regular / quasi-regular and simple.
                let star = TriangleStar::new(t.a, t.b, t.c).unwrap();
                let h = star.dupin_hexagon(&ind).unwrap();
                if sign > 0.0 {
                    assert!(is_affine_regular_hexagon(&h.vertices, &t.a, 1e-9));
                    assert!(!is_affine_quasi_regular_hexagon(&h.vertices, &t.a, 1e-6));
                } else {
                    assert!(is_affine_quasi_regular_hexagon(&h.vertices, &t.a, 1e-9));
                    assert!(!is_affine_regular_hexagon(&h.vertices, &t.a, 1e-6));
                }
                assert_eq!(is_simple_polygon(&h.vertices), Ok(true));
            }
        }
        eprintln!(
            "ideal triangles: worst relative Dupin-center error K>0 {:.2e}, K<0 {:.2e}",
            worst[0], worst[1]
        );
    }

    #[test]
    fn line_de_bounds_the_valid_region() {
        let mut rng = ChaCha8Rng::seed_from_u64(52);
        for sign in [1.0, -1.0] {
            let mut n = 0;
            while n < 2_000 {
                let (ind, a, b) = random_case(&mut rng, sign);
                let Ok(t) = ideal_triangle(&ind, &a, &b) else {
                    continue;
                };
                n += 1;
                let tt = t.step / 3f64.sqrt();
                for lam in [0.3, 0.7, 0.95, 1.05, 1.5, 3.0] {
                    let apex = t.m + t.direction * (lam * tt);
                    let star = TriangleStar::new(t.a, t.b, apex).unwrap();
                    let valid = star.is_valid(&ind).unwrap();
                    assert_eq!(valid, lam > 1.0, "lambda {lam}, sign {sign}");
                    assert_eq!(t.beyond_de(&apex), lam > 1.0);
                }
                // D and E: the construction's defining properties.
                let e = t.b - t.a;
                assert!(cross(&(t.e - t.d), &e).abs() <= 1e-12 * e.norm_squared() * 10.0);
                if sign > 0.0 {
                    // DE touches the Dupin ellipse with diameter AB at M + t w.
                    let s = ind.quadratic(&(e / 2.0));
                    assert!(
                        (ind.quadratic(&(t.m + t.direction * tt - t.m)) - s).abs()
                            <= 1e-9 * s.abs()
                    );
                } else {
                    // MD and ME are asymptotic.
                    let q = ind.quadratic(&(t.d - t.m)).abs() + ind.quadratic(&(t.e - t.m)).abs();
                    assert!(q <= 1e-9 * ind.quadratic(&(e / 2.0)).abs());
                }
            }
        }
    }

    #[test]
    fn canonical_cases() {
        // Circle: the equilateral triangle.
        let ind = DupinIndicatrix::new(1.0, 1.0).unwrap();
        let t = ideal_triangle(&ind, &Vec2::new(-1.0, 0.0), &Vec2::new(1.0, 0.0)).unwrap();
        assert!((t.c - Vec2::new(0.0, 3f64.sqrt())).norm() < 1e-15);
        // x^2 - y^2: C = (0, sqrt 3), D = (-1, 1) on the asymptote y = -x through M.
        let ind = DupinIndicatrix::new(1.0, -1.0).unwrap();
        let t = ideal_triangle(&ind, &Vec2::new(-1.0, 0.0), &Vec2::new(1.0, 0.0)).unwrap();
        assert!((t.c - Vec2::new(0.0, 3f64.sqrt())).norm() < 1e-15);
        assert!((t.d - Vec2::new(-1.0, 1.0)).norm() < 1e-15);
    }

    #[test]
    fn degenerate_input_is_a_typed_error() {
        let ind = DupinIndicatrix::new(1.0, -1.0).unwrap();
        let a = Vec2::new(0.0, 0.0);
        assert_eq!(
            ideal_triangle(&ind, &a, &Vec2::new(1.0, 1.0)),
            Err(IdealTriangleError::AsymptoticBase)
        );
        assert_eq!(
            ideal_triangle(&ind, &a, &a),
            Err(IdealTriangleError::DegenerateBase)
        );
        assert_eq!(
            ideal_triangle(&ind, &a, &Vec2::new(f64::NAN, 1.0)),
            Err(IdealTriangleError::NonFinite)
        );
        for (k1, k2, t) in [
            (1.0, 0.0, PointType::Parabolic),
            (0.0, 0.0, PointType::Planar),
        ] {
            let ind = DupinIndicatrix::new(k1, k2).unwrap();
            assert_eq!(
                ideal_triangle(&ind, &a, &Vec2::new(1.0, 0.3)),
                Err(IdealTriangleError::ZeroGaussianCurvature(t))
            );
        }
    }
}
