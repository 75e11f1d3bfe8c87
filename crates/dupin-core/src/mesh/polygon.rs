//! Simple-polygon test with exact predicates (P-Hex paper, section 4.2: a P-Hex face, or a
//! Dupin hexagon, is valid when it has no self-intersection).
//!
//! Uses `robust::orient2d` (Shewchuk's adaptive exact orientation), so the answer is exact for
//! the given floating-point vertices. O(n^2) segment pairs: meant for faces (n ~ 6).

use crate::Vec2;
use robust::{Coord, orient2d};
use thiserror::Error;

/// Why a polygon could not be tested.
///
/// (P-Hex paper, section 4.2.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum PolygonError {
    /// Fewer than three vertices.
    #[error("a polygon needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// A coordinate is NaN or infinite.
    #[error("non-finite polygon vertex {0}")]
    NonFinite(usize),
}

#[inline]
fn orient(a: &Vec2, b: &Vec2, c: &Vec2) -> f64 {
    orient2d(
        Coord { x: a.x, y: a.y },
        Coord { x: b.x, y: b.y },
        Coord { x: c.x, y: c.y },
    )
}

/// Whether c, known collinear with segment ab, lies on the closed segment ab.
#[inline]
fn on_segment(a: &Vec2, b: &Vec2, c: &Vec2) -> bool {
    c.x >= a.x.min(b.x) && c.x <= a.x.max(b.x) && c.y >= a.y.min(b.y) && c.y <= a.y.max(b.y)
}

/// Whether the closed segments ab and cd share a point (exact).
///
/// (P-Hex paper, section 4.2.)
pub fn segments_intersect(a: &Vec2, b: &Vec2, c: &Vec2, d: &Vec2) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    (o1 == 0.0 && on_segment(a, b, c))
        || (o2 == 0.0 && on_segment(a, b, d))
        || (o3 == 0.0 && on_segment(c, d, a))
        || (o4 == 0.0 && on_segment(c, d, b))
}

/// Whether the closed polygon `pts` (edges p_i p_(i+1), last to first) is simple: no two
/// non-adjacent edges meet, adjacent edges meet only at their shared vertex, no zero-length
/// edge. Exact for the given coordinates.
///
/// (P-Hex paper, section 4.2: validity of a face or Dupin hexagon.)
pub fn is_simple_polygon(pts: &[Vec2]) -> Result<bool, PolygonError> {
    let n = pts.len();
    if n < 3 {
        return Err(PolygonError::TooFewVertices(n));
    }
    if let Some(i) = pts
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(PolygonError::NonFinite(i));
    }
    for i in 0..n {
        let (a, b) = (&pts[i], &pts[(i + 1) % n]);
        if a == b {
            return Ok(false);
        }
        // Adjacent edge (b, c): folding back along the same line overlaps.
        let c = &pts[(i + 2) % n];
        if orient(a, b, c) == 0.0 && (c - b).dot(&(a - b)) > 0.0 {
            return Ok(false);
        }
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            if segments_intersect(a, b, &pts[j], &pts[(j + 1) % n]) {
                return Ok(false);
            }
        }
    }
    Ok(true)
}

/// Whether `p` lies strictly inside triangle abc (exact; false on the boundary or for a
/// degenerate triangle).
///
/// (P-Hex paper, Proposition 4, condition 2.)
pub fn strictly_inside_triangle(p: &Vec2, a: &Vec2, b: &Vec2, c: &Vec2) -> bool {
    let s = orient(a, b, c);
    if s == 0.0 {
        return false;
    }
    let (x, y, z) = (orient(a, b, p), orient(b, c, p), orient(c, a, p));
    if s > 0.0 {
        x > 0.0 && y > 0.0 && z > 0.0
    } else {
        x < 0.0 && y < 0.0 && z < 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn simple_and_self_intersecting() {
        let hex: Vec<Vec2> = (0..6)
            .map(|k| {
                let a = std::f64::consts::PI / 3.0 * k as f64;
                v(a.cos(), a.sin())
            })
            .collect();
        assert_eq!(is_simple_polygon(&hex), Ok(true));
        let bow = [v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)];
        assert_eq!(is_simple_polygon(&bow), Ok(false));
        // Non-convex but simple (arrow).
        let arrow = [v(0.0, 0.0), v(2.0, 1.0), v(0.0, 2.0), v(0.5, 1.0)];
        assert_eq!(is_simple_polygon(&arrow), Ok(true));
        // Touching: a vertex on a non-adjacent edge.
        let touch = [
            v(0.0, 0.0),
            v(2.0, 0.0),
            v(2.0, 2.0),
            v(1.0, 0.0),
            v(0.0, 2.0),
        ];
        assert_eq!(is_simple_polygon(&touch), Ok(false));
        // Repeated vertex and folding edge.
        assert_eq!(
            is_simple_polygon(&[v(0.0, 0.0), v(0.0, 0.0), v(1.0, 1.0)]),
            Ok(false)
        );
        assert_eq!(
            is_simple_polygon(&[v(0.0, 0.0), v(2.0, 0.0), v(1.0, 0.0), v(1.0, 1.0)]),
            Ok(false)
        );
        assert_eq!(
            is_simple_polygon(&[v(0.0, 0.0)]),
            Err(PolygonError::TooFewVertices(1))
        );
        assert_eq!(
            is_simple_polygon(&[v(0.0, 0.0), v(1.0, f64::NAN), v(1.0, 1.0)]),
            Err(PolygonError::NonFinite(1))
        );
    }

    #[test]
    fn exact_near_degenerate_crossing() {
        // A vertex displaced by one ulp across an edge flips the answer.
        let e = f64::EPSILON;
        let inside = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(1.0, 1.0),
            v(0.5, e),
            v(0.0, 1.0),
        ];
        let across = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(1.0, 1.0),
            v(0.5, -e),
            v(0.0, 1.0),
        ];
        assert_eq!(is_simple_polygon(&inside), Ok(true));
        assert_eq!(is_simple_polygon(&across), Ok(false));
    }
}
