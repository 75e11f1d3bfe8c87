//! Quality measures of a planar triangulation: the quantities the paper's section 6 bounds.

use crate::Vec2;
use robust::{Coord, incircle};

/// Angles, aspect ratio, edge lengths, tiling and Delaunay checks of a triangulation.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangulationQuality {
    /// Smallest interior angle, degrees.
    pub min_angle_deg: f64,
    /// Largest interior angle, degrees.
    pub max_angle_deg: f64,
    /// Largest circumradius / (2 · inradius) (1 for an equilateral triangle; section 6.2).
    pub max_aspect_ratio: f64,
    /// Shortest edge length.
    pub min_edge: f64,
    /// Sum of the triangles' signed areas (counter-clockwise positive).
    pub area: f64,
    /// Number of triangles with non-positive orientation (exact predicate).
    pub inverted: usize,
    /// Edges used by more than two triangles or twice in the same direction.
    pub nonmanifold_edges: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Interior edges where the exact incircle test finds the opposite vertex strictly inside the
    /// circumcircle and the two opposite angles sum to more than 180° plus a rounding tolerance
    /// (1e-7° plus 64 ulp of the largest coordinate over the shortest edge of the pair, in
    /// radians).
    pub delaunay_violations: usize,
    /// Interior edges whose four points are cocircular up to rounding (the exact incircle test is
    /// positive only because lattice positions, multiples of √3, are rounded to f64; the
    /// opposite angles sum to 180° within the tolerance above).
    pub delaunay_ties: usize,
}

impl TriangulationQuality {
    /// Whether the triangulation is Delaunay (no violation).
    pub fn is_delaunay(&self) -> bool {
        self.delaunay_violations == 0
    }
}

fn angle(at: Vec2, p: Vec2, q: Vec2) -> f64 {
    let (u, v) = (p - at, q - at);
    let c = u.x * v.y - u.y * v.x;
    let d = u.dot(&v);
    c.abs().atan2(d).to_degrees()
}

/// Interior angles of triangle (a, b, c) in degrees, at a, b and c, in [0, 180].
pub fn triangle_angles_deg(a: Vec2, b: Vec2, c: Vec2) -> [f64; 3] {
    [angle(a, b, c), angle(b, c, a), angle(c, a, b)]
}

/// Counts of the triangles' interior angles ([`triangle_angles_deg`]) per `bin_deg`-wide bin
/// over [0, 180) (180 itself in the last bin): the angle distribution the paper's bounds
/// (sections 4 and 5) are about.
pub fn angle_histogram(vertices: &[Vec2], triangles: &[[u32; 3]], bin_deg: f64) -> Vec<u32> {
    let bins = (180.0 / bin_deg) as usize;
    let mut histogram = vec![0u32; bins];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        for deg in triangle_angles_deg(a, b, c) {
            histogram[((deg / bin_deg) as usize).min(bins - 1)] += 1;
        }
    }
    histogram
}

/// Measures a triangulation given as positions and counter-clockwise triangles.
pub fn triangulation_quality(vertices: &[Vec2], triangles: &[[u32; 3]]) -> TriangulationQuality {
    let mut q = TriangulationQuality {
        min_angle_deg: f64::INFINITY,
        max_angle_deg: 0.0,
        max_aspect_ratio: 0.0,
        min_edge: f64::INFINITY,
        area: 0.0,
        inverted: 0,
        nonmanifold_edges: 0,
        boundary_edges: 0,
        delaunay_violations: 0,
        delaunay_ties: 0,
    };
    let c = |i: u32| {
        let p = vertices[i as usize];
        Coord { x: p.x, y: p.y }
    };
    // The directed edges (a, b) with their opposite vertex, grouped by a (a counting sort by
    // hand: a hash map of the edges took a quarter of a 16k-point run in wasm, where hashbrown
    // probes without SIMD).
    let n = vertices.len();
    let mut start = vec![0usize; n + 1];
    for t in triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut out = vec![(0u32, 0u32); start[n]];
    for t in triangles {
        let [a, b, cc] = t.map(|i| vertices[i as usize]);
        if robust::orient2d(c(t[0]), c(t[1]), c(t[2])) <= 0.0 {
            q.inverted += 1;
        }
        q.area += 0.5 * ((b - a).perp(&(cc - a)));
        for x in triangle_angles_deg(a, b, cc) {
            q.min_angle_deg = q.min_angle_deg.min(x);
            q.max_angle_deg = q.max_angle_deg.max(x);
        }
        let (la, lb, lc) = ((b - cc).norm(), (cc - a).norm(), (a - b).norm());
        q.min_edge = q.min_edge.min(la).min(lb).min(lc);
        let s = 0.5 * (la + lb + lc);
        let area = (b - a).perp(&(cc - a)).abs() * 0.5;
        let inr = area / s;
        let circ = la * lb * lc / (4.0 * area);
        q.max_aspect_ratio = q.max_aspect_ratio.max(circ / (2.0 * inr));
        for i in 0..3 {
            let a = t[i] as usize;
            out[fill[a]] = (t[(i + 1) % 3], t[(i + 2) % 3]);
            fill[a] += 1;
        }
    }
    // Stable: the triangles of a repeated directed edge (non-manifold) stay in order, the last
    // one's opposite vertex standing for the edge.
    for a in 0..n {
        out[start[a]..start[a + 1]].sort_by_key(|e| e.0);
    }
    let opposite = |a: u32, b: u32| {
        out[start[a as usize]..start[a as usize + 1]]
            .iter()
            .rev()
            .find(|e| e.0 == b)
            .map(|e| e.1)
    };
    for a in 0..n {
        let bucket = &out[start[a]..start[a + 1]];
        for (k, &(b, o)) in bucket.iter().enumerate() {
            if bucket.get(k + 1).is_some_and(|e| e.0 == b) {
                q.nonmanifold_edges += 1;
                continue;
            }
            let a = a as u32;
            match opposite(b, a) {
                None => q.boundary_edges += 1,
                Some(o2) => {
                    if a > b {
                        continue;
                    }
                    // Triangle (a, b, o) is counter-clockwise; o2 lies across edge (a, b).
                    if incircle(c(a), c(b), c(o), c(o2)) > 0.0 {
                        let (pa, pb) = (vertices[a as usize], vertices[b as usize]);
                        let (po, po2) = (vertices[o as usize], vertices[o2 as usize]);
                        let s = angle(po, pa, pb) + angle(po2, pa, pb);
                        // Rounding of the coordinates moves each angle by about ulp / edge length.
                        let mag = [pa, pb, po, po2]
                            .iter()
                            .map(|p| p.x.abs().max(p.y.abs()))
                            .fold(0.0, f64::max);
                        let short = [(pa - pb).norm(), (po - pa).norm(), (po - pb).norm()]
                            .into_iter()
                            .chain([(po2 - pa).norm(), (po2 - pb).norm()])
                            .fold(f64::INFINITY, f64::min);
                        let tol = 1e-7 + (64.0 * f64::EPSILON * mag / short).to_degrees();
                        if s > 180.0 + tol {
                            q.delaunay_violations += 1;
                        } else {
                            q.delaunay_ties += 1;
                        }
                    }
                }
            }
        }
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The edge counts and the Delaunay test on small triangulations: a square split along
    /// either diagonal of a kite (one of them not Delaunay), and a directed edge used twice.
    #[test]
    fn edges_are_counted_and_delaunay_checked() {
        // A flat kite: the short diagonal 1-3 is the Delaunay one (across the long one the
        // opposite angles sum to about 293 degrees).
        let v = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, -0.3),
            Vec2::new(2.0, 0.0),
            Vec2::new(1.0, 0.3),
        ];
        let good = triangulation_quality(&v, &[[0, 1, 3], [1, 2, 3]]);
        assert_eq!((good.boundary_edges, good.nonmanifold_edges), (4, 0));
        assert_eq!((good.delaunay_violations, good.inverted), (0, 0));
        assert!((good.area - 0.6).abs() < 1e-15);
        let bad = triangulation_quality(&v, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!((bad.boundary_edges, bad.delaunay_violations), (4, 1));
        // Edge 0 -> 1 in two triangles (a fold): one non-manifold edge, one inverted triangle.
        let v = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.5, 1.0),
            Vec2::new(0.5, -1.0),
        ];
        let folded = triangulation_quality(&v, &[[0, 1, 2], [0, 1, 3]]);
        assert_eq!((folded.nonmanifold_edges, folded.inverted), (1, 1));
        assert_eq!(folded.boundary_edges, 5);
    }
}
