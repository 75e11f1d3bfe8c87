//! The cubic Lane-Riesenfeld rule (uniform cubic B-spline subdivision) on a polyline: new
//! vertex points (p_{i-1} + 6 p_i + p_{i+1}) / 8 and edge midpoints (p_i + p_{i+1}) / 2
//! (conical paper, Fig. 8). Open polylines keep their end points.

use crate::Vec3;

/// One cubic Lane-Riesenfeld step on `points`, closed (cyclic) or open.
pub fn lane_riesenfeld_cubic(points: &[Vec3], closed: bool) -> Vec<Vec3> {
    let n = points.len();
    if n < 3 {
        return points.to_vec();
    }
    let mut out = Vec::with_capacity(2 * n);
    for i in 0..n {
        let p = points[i];
        let even = if closed {
            (points[(i + n - 1) % n] + 6.0 * p + points[(i + 1) % n]) / 8.0
        } else if i == 0 || i == n - 1 {
            p
        } else {
            (points[i - 1] + 6.0 * p + points[i + 1]) / 8.0
        };
        out.push(even);
        if closed || i + 1 < n {
            out.push((p + points[(i + 1) % n]) * 0.5);
        }
    }
    out
}
