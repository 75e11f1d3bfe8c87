//! Minimum enclosing circle of a point set (Welzl 1991, randomised incremental form), used by
//! the paper's section 4.1 as the inner circle of the bounding hexagon.
//!
//! Input: any finite points. Output: centre and radius of the smallest circle containing them
//! all (radius 0 for a single point). Expected O(n) time: the points are visited in a seeded
//! random order (ChaCha8, fixed seed) so the result and its cost are reproducible.
//! Written by hand: no maintained crate in the dependency set offers it for `nalgebra` points,
//! and it is thirty lines.

use crate::Vec2;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

/// A circle in the plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Centre.
    pub center: Vec2,
    /// Radius (>= 0).
    pub radius: f64,
}

impl Circle {
    fn contains(&self, p: &Vec2) -> bool {
        // Relative slack so that the circle's own defining points always pass.
        (p - self.center).norm() <= self.radius * (1.0 + 1e-12) + 1e-300
    }

    fn from_two(a: &Vec2, b: &Vec2) -> Circle {
        let center = (a + b) * 0.5;
        Circle {
            center,
            radius: (a - center).norm().max((b - center).norm()),
        }
    }

    fn from_three(a: &Vec2, b: &Vec2, c: &Vec2) -> Circle {
        let (bx, by) = (b.x - a.x, b.y - a.y);
        let (cx, cy) = (c.x - a.x, c.y - a.y);
        let d = 2.0 * (bx * cy - by * cx);
        let fallback = || {
            // (Nearly) collinear: the circle on the farthest pair.
            let cands = [
                Circle::from_two(a, b),
                Circle::from_two(a, c),
                Circle::from_two(b, c),
            ];
            cands
                .into_iter()
                .filter(|k| k.contains(a) && k.contains(b) && k.contains(c))
                .min_by(|p, q| p.radius.total_cmp(&q.radius))
                .unwrap_or(cands[0])
        };
        if d.abs() < 1e-300 {
            return fallback();
        }
        let b2 = bx * bx + by * by;
        let c2 = cx * cx + cy * cy;
        let ux = (cy * b2 - by * c2) / d;
        let uy = (bx * c2 - cx * b2) / d;
        let center = Vec2::new(a.x + ux, a.y + uy);
        let radius = [a, b, c]
            .iter()
            .map(|p| (*p - center).norm())
            .fold(0.0, f64::max);
        if !radius.is_finite() {
            return fallback();
        }
        Circle { center, radius }
    }
}

/// The minimum enclosing circle of `points` (Welzl). Returns `None` for an empty slice.
pub fn min_enclosing_circle(points: &[Vec2]) -> Option<Circle> {
    let mut p: Vec<Vec2> = points.to_vec();
    if p.is_empty() {
        return None;
    }
    p.shuffle(&mut ChaCha8Rng::seed_from_u64(0x5e1_2d1));
    let mut c = Circle {
        center: p[0],
        radius: 0.0,
    };
    for i in 1..p.len() {
        if c.contains(&p[i]) {
            continue;
        }
        c = Circle {
            center: p[i],
            radius: 0.0,
        };
        for j in 0..i {
            if c.contains(&p[j]) {
                continue;
            }
            c = Circle::from_two(&p[i], &p[j]);
            for k in 0..j {
                if !c.contains(&p[k]) {
                    c = Circle::from_three(&p[i], &p[j], &p[k]);
                }
            }
        }
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn encloses_all_and_is_minimal_by_support() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..2000 {
            let n = rng.random_range(1..40);
            let pts: Vec<Vec2> = (0..n)
                .map(|_| Vec2::new(rng.random::<f64>() * 10.0 - 5.0, rng.random::<f64>()))
                .collect();
            let c = min_enclosing_circle(&pts).unwrap();
            for p in &pts {
                assert!((p - c.center).norm() <= c.radius * (1.0 + 1e-9) + 1e-12);
            }
            // Minimality: at least two points on the circle (support), unless a single point.
            let on = pts
                .iter()
                .filter(|p| ((*p - c.center).norm() - c.radius).abs() <= 1e-9 * c.radius.max(1e-12))
                .count();
            assert!(n == 1 || on >= 2, "support of {on} points");
            // No smaller circle around the centre of the farthest pair contains everything.
            let mut far = 0.0f64;
            for a in &pts {
                for b in &pts {
                    far = far.max((a - b).norm());
                }
            }
            assert!(c.radius >= far / 2.0 * (1.0 - 1e-12));
            assert!(c.radius <= far / 3f64.sqrt() * (1.0 + 1e-9) + 1e-12);
        }
    }
}
