//! Triangle stars, Dupin hexagons and their validity (P-Hex paper, section 4.1 and 4.2:
//! Propositions 3, 4 and 5; proofs in the appendix).
//!
//! A triangle star is six congruent triangles around a center whose outer vertices form a
//! centrally symmetric hexagon; it is fixed by its fundamental triangle (center, center + a,
//! center + b). Its ring is center + [a, b, b - a, -a, -b, a - b] and triangle i is
//! (center, ring_i, ring_(i+1)). The Dupin hexagon joins the Dupin centers of the six triangles
//! in order; the star is valid when that hexagon is simple.

use crate::Vec2;
use crate::mesh::{is_simple_polygon, strictly_inside_triangle};
use crate::phex::{DupinCenterError, dupin_conic_through};
use crate::phex::{DupinConic, DupinIndicatrix};
use crate::surface::PointType;
use std::f64::consts::{FRAC_PI_2, PI};
use thiserror::Error;

/// Why a triangle star cannot be built or judged.
///
/// (P-Hex paper, sections 4.1 and 4.2.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum TriangleStarError {
    /// A vertex is NaN or infinite.
    #[error("non-finite star vertex")]
    NonFinite,
    /// The fundamental triangle is degenerate (coincident or collinear vertices).
    #[error("degenerate fundamental triangle")]
    DegenerateTriangle,
    /// The Dupin centers do not exist (K = 0, see [`DupinCenterError`]).
    #[error(transparent)]
    DupinCenter(#[from] DupinCenterError),
    /// A condition of Proposition 4 was asked at a point with K <= 0, or of Proposition 5 at a
    /// point with K >= 0.
    #[error("this condition needs a {needed:?} point, the indicatrix is {got:?}")]
    WrongPointType {
        /// The point type the proposition is about.
        needed: PointType,
        /// The indicatrix's point type.
        got: PointType,
    },
}

/// A triangle star in the tangent plane (section 4.1), given by its fundamental triangle
/// (center, center + a, center + b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleStar {
    center: Vec2,
    a: Vec2,
    b: Vec2,
}

/// The Dupin hexagon of a triangle star with the Dupin conic through its vertices
/// (Proposition 3: centered at the star's center, congruent to the triangles' conics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DupinHexagon {
    /// Dupin centers of triangles 0..6, in order.
    pub vertices: [Vec2; 6],
    /// Conic through all six vertices (center = star center, level = the triangles' level).
    pub conic: DupinConic,
    /// The fundamental triangle's own Dupin conic.
    pub triangle_conic: DupinConic,
}

impl TriangleStar {
    /// The star around `center` with fundamental triangle (center, p, q).
    pub fn new(center: Vec2, p: Vec2, q: Vec2) -> Result<Self, TriangleStarError> {
        if !center
            .iter()
            .chain(p.iter())
            .chain(q.iter())
            .all(|x| x.is_finite())
        {
            return Err(TriangleStarError::NonFinite);
        }
        let (a, b) = (p - center, q - center);
        let cross = a.x * b.y - a.y * b.x;
        if !(cross.abs() > 1e-12 * a.norm() * b.norm()) {
            return Err(TriangleStarError::DegenerateTriangle);
        }
        Ok(TriangleStar { center, a, b })
    }

    /// The star's center v_c.
    pub fn center(&self) -> Vec2 {
        self.center
    }

    /// The fundamental triangle (center, center + a, center + b).
    pub fn fundamental_triangle(&self) -> [Vec2; 3] {
        [self.center, self.center + self.a, self.center + self.b]
    }

    /// Offsets of the six ring vertices from the center, in order.
    pub fn ring_offsets(&self) -> [Vec2; 6] {
        let (a, b) = (self.a, self.b);
        [a, b, b - a, -a, -b, a - b]
    }

    /// The six ring vertices (a centrally symmetric hexagon around the center).
    pub fn ring(&self) -> [Vec2; 6] {
        self.ring_offsets().map(|d| self.center + d)
    }

    /// Triangle i = (center, ring_i, ring_(i+1)).
    pub fn triangles(&self) -> [[Vec2; 3]; 6] {
        let r = self.ring();
        std::array::from_fn(|i| [self.center, r[i], r[(i + 1) % 6]])
    }

    /// The Dupin hexagon (Dupin duality, section 4.1): the six triangles are translates and point
    /// reflections of the fundamental one, so with o its Dupin center (relative to the center)
    /// the vertices are center + [o, b - o, o - a, -o, o - b, a - o].
    pub fn dupin_hexagon(&self, ind: &DupinIndicatrix) -> Result<DupinHexagon, TriangleStarError> {
        let [c, p, q] = self.fundamental_triangle();
        let tc = dupin_conic_through(ind, &c, &p, &q)?;
        let o = tc.center - self.center;
        let (a, b) = (self.a, self.b);
        let vertices = [o, b - o, o - a, -o, o - b, a - o].map(|d| self.center + d);
        Ok(DupinHexagon {
            vertices,
            conic: ind.conic(self.center, tc.level),
            triangle_conic: tc,
        })
    }

    /// Condition 1 of Propositions 4 and 5, the definition of validity: the Dupin hexagon is a
    /// simple polygon (exact predicates). Any sign of K != 0.
    pub fn is_valid(&self, ind: &DupinIndicatrix) -> Result<bool, TriangleStarError> {
        let h = self.dupin_hexagon(ind)?;
        is_simple_polygon(&h.vertices).map_err(|_| TriangleStarError::NonFinite)
    }

    /// Proposition 4, condition 2 (K > 0): the Dupin center of the fundamental triangle lies
    /// strictly inside it (exact orientation tests on the computed center).
    pub fn dupin_center_inside(&self, ind: &DupinIndicatrix) -> Result<bool, TriangleStarError> {
        need(ind, PointType::Elliptic)?;
        let [c, p, q] = self.fundamental_triangle();
        let o = dupin_conic_through(ind, &c, &p, &q)?.center;
        Ok(strictly_inside_triangle(&o, &c, &p, &q))
    }

    /// Proposition 4, condition 3 (K > 0): the three edge directions are not enclosed by any
    /// pair of conjugate directions. In the frame scaled by (sqrt|k1|, sqrt|k2|) conjugate pairs
    /// are orthogonal pairs, so the edge lines (angles mod pi) are enclosed by one iff they fit
    /// in a closed quarter-turn, i.e. iff the largest gap between consecutive edge angles is at
    /// least pi/2.
    pub fn edges_not_enclosed_by_conjugate_pair(
        &self,
        ind: &DupinIndicatrix,
    ) -> Result<bool, TriangleStarError> {
        need(ind, PointType::Elliptic)?;
        let (sx, sy) = (ind.k1().abs().sqrt(), ind.k2().abs().sqrt());
        let mut ang = self
            .edges()
            .map(|e| (sy * e.y).atan2(sx * e.x).rem_euclid(PI));
        ang.sort_by(f64::total_cmp);
        let gaps = [ang[1] - ang[0], ang[2] - ang[1], PI - (ang[2] - ang[0])];
        let max_gap = gaps.into_iter().fold(0.0, f64::max);
        Ok(max_gap < FRAC_PI_2)
    }

    /// Proposition 5, condition 2 (K < 0): the three vertices of the fundamental triangle are
    /// not all on one branch of its circumscribing Dupin hyperbola. A degenerate circumscribing
    /// conic (level 0) counts as invalid.
    pub fn vertices_on_different_branches(
        &self,
        ind: &DupinIndicatrix,
    ) -> Result<bool, TriangleStarError> {
        need(ind, PointType::Hyperbolic)?;
        let t = self.fundamental_triangle();
        let conic = dupin_conic_through(ind, &t[0], &t[1], &t[2])?;
        let br = t.map(|p| conic.branch(&p));
        Ok(match br {
            [Some(x), Some(y), Some(z)] => !(x == y && y == z),
            _ => false,
        })
    }

    /// Proposition 5, condition 3 (K < 0): the three edge directions are not all in the same
    /// range bounded by the two asymptotic directions, i.e. Q(edge) takes both signs (an edge
    /// along an asymptote counts as enclosed: invalid).
    pub fn edges_not_in_one_asymptotic_range(
        &self,
        ind: &DupinIndicatrix,
    ) -> Result<bool, TriangleStarError> {
        need(ind, PointType::Hyperbolic)?;
        let q = self.edges().map(|e| ind.quadratic(&e));
        Ok(q.iter().any(|&x| x > 0.0) && q.iter().any(|&x| x < 0.0))
    }

    /// Conditions 1, 2 and 3 of Proposition 4 (elliptic indicatrix, K > 0) or Proposition 5
    /// (hyperbolic, K < 0), in that order; the propositions say the three agree. Fails on a
    /// parabolic or planar indicatrix, where neither proposition speaks.
    pub fn validity_conditions(
        &self,
        ind: &DupinIndicatrix,
    ) -> Result<[bool; 3], TriangleStarError> {
        let c1 = self.is_valid(ind)?;
        Ok(if ind.point_type() == PointType::Elliptic {
            [
                c1,
                self.dupin_center_inside(ind)?,
                self.edges_not_enclosed_by_conjugate_pair(ind)?,
            ]
        } else {
            [
                c1,
                self.vertices_on_different_branches(ind)?,
                self.edges_not_in_one_asymptotic_range(ind)?,
            ]
        })
    }

    fn edges(&self) -> [Vec2; 3] {
        [self.a, self.b, self.b - self.a]
    }
}

fn need(ind: &DupinIndicatrix, t: PointType) -> Result<(), TriangleStarError> {
    if ind.point_type() == t {
        Ok(())
    } else {
        Err(TriangleStarError::WrongPointType {
            needed: t,
            got: ind.point_type(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Propositions 4 and 5 on 10^5 seeded random stars per sign of K: the three conditions
    /// agree, and both outcomes occur often.
    fn agreement(sign: f64, seed: u64) -> (usize, usize) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (mut valid, mut invalid) = (0, 0);
        while valid + invalid < 100_000 {
            let k1: f64 = rng.random_range(0.05..5.0);
            let k2: f64 = sign * rng.random_range(0.05..5.0);
            let flip = if rng.random_bool(0.5) { -1.0 } else { 1.0 };
            let ind = DupinIndicatrix::new(flip * k1, flip * k2).unwrap();
            let mut p = || Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let (c, x, y) = (p(), p(), p());
            let Ok(star) = TriangleStar::new(c, x, y) else {
                continue;
            };
            let Ok(c1) = star.is_valid(&ind) else {
                continue;
            };
            let [_, c2, c3] = star.validity_conditions(&ind).unwrap();
            assert_eq!(c1, c2, "condition 1 vs 2 at k=({k1},{k2}) star {star:?}");
            assert_eq!(c1, c3, "condition 1 vs 3 at k=({k1},{k2}) star {star:?}");
            if c1 { valid += 1 } else { invalid += 1 }
        }
        (valid, invalid)
    }

    #[test]
    fn proposition_4_conditions_agree() {
        let (v, i) = agreement(1.0, 4);
        eprintln!(
            "Proposition 4 (K > 0): 100000 stars, {v} valid, {i} invalid, all 3 conditions agree"
        );
        assert!(v > 10_000 && i > 10_000);
    }

    #[test]
    fn proposition_5_conditions_agree() {
        let (v, i) = agreement(-1.0, 5);
        eprintln!(
            "Proposition 5 (K < 0): 100000 stars, {v} valid, {i} invalid, all 3 conditions agree"
        );
        assert!(v > 10_000 && i > 10_000);
    }

    #[test]
    fn proposition_3_hexagon_on_one_congruent_conic() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..20_000 {
            let k1: f64 = rng.random_range(-4.0..4.0);
            let k2: f64 = rng.random_range(-4.0..4.0);
            let Ok(ind) = DupinIndicatrix::new(k1, k2) else {
                continue;
            };
            let mut p = || Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let Ok(star) = TriangleStar::new(p(), p(), p()) else {
                continue;
            };
            let Ok(h) = star.dupin_hexagon(&ind) else {
                continue;
            };
            // One conic through all six vertices, centred at the star's center ...
            let scale = h
                .vertices
                .iter()
                .map(|v| ind.quadratic(&(v - star.center())).abs())
                .fold(h.conic.level.abs(), f64::max)
                .max(1e-300);
            for v in &h.vertices {
                assert!(h.conic.residual(v).abs() <= 1e-10 * scale);
            }
            // ... congruent to the six triangles' conics: same level, hence a translate.
            for t in star.triangles() {
                let c = dupin_conic_through(&ind, &t[0], &t[1], &t[2]).unwrap();
                assert!((c.level - h.conic.level).abs() <= 1e-10 * scale);
            }
            assert_eq!(h.conic.center, star.center());
            // Dupin centers really are the six triangles' Dupin centers.
            for (i, t) in star.triangles().iter().enumerate() {
                let c = dupin_conic_through(&ind, &t[0], &t[1], &t[2]).unwrap();
                assert!((c.center - h.vertices[i]).norm() <= 1e-9 * (1.0 + c.center.norm()));
            }
        }
    }

    #[test]
    fn wrong_sign_and_degenerate_are_typed_errors() {
        let star =
            TriangleStar::new(Vec2::zeros(), Vec2::new(1.0, 0.0), Vec2::new(0.3, 1.0)).unwrap();
        let pos = DupinIndicatrix::new(1.0, 2.0).unwrap();
        let neg = DupinIndicatrix::new(1.0, -2.0).unwrap();
        assert!(matches!(
            star.dupin_center_inside(&neg),
            Err(TriangleStarError::WrongPointType { .. })
        ));
        assert!(matches!(
            star.edges_not_in_one_asymptotic_range(&pos),
            Err(TriangleStarError::WrongPointType { .. })
        ));
        let par = DupinIndicatrix::new(1.0, 0.0).unwrap();
        assert!(matches!(
            star.is_valid(&par),
            Err(TriangleStarError::DupinCenter(
                DupinCenterError::ZeroGaussianCurvature(_)
            ))
        ));
        assert_eq!(
            TriangleStar::new(Vec2::zeros(), Vec2::zeros(), Vec2::new(1.0, 1.0)),
            Err(TriangleStarError::DegenerateTriangle)
        );
        assert_eq!(
            TriangleStar::new(Vec2::zeros(), Vec2::new(f64::NAN, 0.0), Vec2::new(1.0, 1.0)),
            Err(TriangleStarError::NonFinite)
        );
    }
}
