//! Chaikin's corner cutting on a polyline (conical paper, Sec. 3: applied to the two boundary
//! polylines of a PQ strip). Each segment (p, q) yields 3/4 p + 1/4 q and 1/4 p + 3/4 q. Open
//! polylines keep their end points.

use crate::Vec3;

/// One Chaikin step on `points`, closed (cyclic) or open.
pub fn chaikin(points: &[Vec3], closed: bool) -> Vec<Vec3> {
    let n = points.len();
    if n < 2 {
        return points.to_vec();
    }
    let segs = if closed { n } else { n - 1 };
    let mut out = Vec::with_capacity(2 * segs + 2);
    if !closed {
        out.push(points[0]);
    }
    for i in 0..segs {
        let (a, b) = (points[i], points[(i + 1) % n]);
        out.push(0.75 * a + 0.25 * b);
        out.push(0.25 * a + 0.75 * b);
    }
    if !closed {
        out.push(points[n - 1]);
    }
    out
}
