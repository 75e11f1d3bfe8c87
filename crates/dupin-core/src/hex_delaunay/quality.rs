//! Quality measures of a planar triangulation: the quantities the paper's section 6 bounds.

use crate::Vec2;
use robust::{Coord, incircle};
use rustc_hash::FxHashMap;

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
    // Directed edge (a, b) -> opposite vertex.
    let mut edges: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    edges.reserve(triangles.len() * 3);
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
            if edges
                .insert((t[i], t[(i + 1) % 3]), t[(i + 2) % 3])
                .is_some()
            {
                q.nonmanifold_edges += 1;
            }
        }
    }
    for (&(a, b), &o) in &edges {
        match edges.get(&(b, a)) {
            None => q.boundary_edges += 1,
            Some(&o2) => {
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
    q
}
