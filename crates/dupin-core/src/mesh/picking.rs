//! Picking a triangulation vertex under a view ray, and the one-ring (triangle star) around a
//! vertex, for the page's teaching inset (P-Hex paper, section 4.1: the triangle star of a
//! vertex and its Dupin hexagon).
//!
//! Input: vertex positions and counter-clockwise triangles (a [`crate::phex::Triangulation`]'s, or
//! the first layers of it). Output: the vertex nearest to where a ray first meets the
//! triangles, and the six ring neighbours of an interior valence-6 vertex in counter-clockwise
//! order. The ray test is written out (Moller-Trumbore, a dozen lines) because a collision
//! library (parry3d) would be a heavy dependency for one query per click.

use crate::Vec3;
use thiserror::Error;

/// Why a vertex has no complete triangle star.
///
/// (P-Hex paper, section 4.1.)
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum VertexStarError {
    /// The vertex index is not below the number of vertices.
    #[error("vertex {vertex} does not exist (the mesh has {vertices} vertices)")]
    OutOfRange {
        /// The index asked for.
        vertex: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// The triangles around the vertex do not close into a fan (a boundary vertex, or layers
    /// not yet built around it).
    #[error(
        "vertex {vertex} is on the boundary: its triangle star is incomplete ({triangles} triangles around it, the fan does not close)"
    )]
    Boundary {
        /// The vertex.
        vertex: usize,
        /// Triangles that contain it.
        triangles: usize,
    },
    /// The fan closes but has another number of triangles than six.
    #[error("vertex {vertex} has valence {valence}: a triangle star has six triangles")]
    Valence {
        /// The vertex.
        vertex: usize,
        /// Its number of triangles.
        valence: usize,
    },
    /// The triangles around the vertex do not form a single consistently oriented cycle.
    #[error("the triangles around vertex {vertex} do not form a single oriented fan")]
    NonManifold {
        /// The vertex.
        vertex: usize,
    },
}

/// Where a ray first meets a triangle mesh, and the vertex of that triangle nearest the hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexPick {
    /// The picked vertex (nearest corner of the hit triangle to the hit point).
    pub vertex: usize,
    /// The triangle hit first.
    pub triangle: usize,
    /// The hit point.
    pub hit: Vec3,
    /// Ray parameter of the hit (`origin + t * direction`).
    pub t: f64,
}

/// The first triangle the ray `origin + t * direction` (t > 0) meets, from either side, and
/// its corner nearest the hit point. `None` when the ray misses every triangle, the ray is not
/// finite or its direction is zero. Triangles with an index out of range are skipped.
pub fn pick_vertex(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    origin: Vec3,
    direction: Vec3,
) -> Option<VertexPick> {
    if !(origin.iter().chain(direction.iter()).all(|x| x.is_finite()))
        || direction.norm_squared() == 0.0
    {
        return None;
    }
    let mut best: Option<VertexPick> = None;
    for (ti, tri) in triangles.iter().enumerate() {
        let Some([a, b, c]) = corners(positions, tri) else {
            continue;
        };
        let Some(t) = ray_triangle(origin, direction, a, b, c) else {
            continue;
        };
        if best.is_some_and(|p| p.t <= t) {
            continue;
        }
        let hit = origin + direction * t;
        let k = (0..3)
            .min_by(|&i, &j| {
                let pi = positions[tri[i] as usize];
                let pj = positions[tri[j] as usize];
                (pi - hit)
                    .norm_squared()
                    .total_cmp(&(pj - hit).norm_squared())
            })
            .unwrap_or(0);
        best = Some(VertexPick {
            vertex: tri[k] as usize,
            triangle: ti,
            hit,
            t,
        });
    }
    best
}

fn corners(positions: &[Vec3], tri: &[u32; 3]) -> Option<[Vec3; 3]> {
    Some([
        *positions.get(tri[0] as usize)?,
        *positions.get(tri[1] as usize)?,
        *positions.get(tri[2] as usize)?,
    ])
}

const BARY_EPS: f64 = 1e-9;

/// Moller-Trumbore: ray parameter t > 0 of the hit with triangle abc (both sides), if any.
fn ray_triangle(o: Vec3, d: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(&e2);
    let det = e1.dot(&p);
    // Relative cut-off: rays grazing the triangle's plane miss.
    if det.abs() <= 1e-12 * e1.norm() * e2.norm() * d.norm() {
        return None;
    }
    let s = o - a;
    let u = s.dot(&p) / det;
    // A little slack in the barycentric tests: a ray through a vertex or along an edge must hit
    // one of the triangles there despite rounding.
    if !(-BARY_EPS..=1.0 + BARY_EPS).contains(&u) {
        return None;
    }
    let q = s.cross(&e1);
    let v = d.dot(&q) / det;
    if v < -BARY_EPS || u + v > 1.0 + BARY_EPS {
        return None;
    }
    let t = e2.dot(&q) / det;
    (t > 0.0 && t.is_finite()).then_some(t)
}

/// The six neighbours of `vertex` in counter-clockwise order (the order of its triangles, each
/// given counter-clockwise): the ring of its triangle star. Errors: out-of-range index, a fan
/// that does not close (boundary), a valence other than six, a non-manifold fan.
pub fn vertex_ring(
    num_vertices: usize,
    triangles: &[[u32; 3]],
    vertex: usize,
) -> Result<[u32; 6], VertexStarError> {
    if vertex >= num_vertices {
        return Err(VertexStarError::OutOfRange {
            vertex,
            vertices: num_vertices,
        });
    }
    // Each triangle (vertex, p, q) in counter-clockwise order contributes the ring edge p -> q.
    let mut next: Vec<(u32, u32)> = Vec::new();
    for t in triangles {
        if let Some(k) = t.iter().position(|&i| i as usize == vertex) {
            next.push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    let n = next.len();
    let follow = |p: u32| -> Result<Option<u32>, VertexStarError> {
        let mut it = next.iter().filter(|e| e.0 == p);
        let q = it.next().map(|e| e.1);
        if it.next().is_some() {
            return Err(VertexStarError::NonManifold { vertex });
        }
        Ok(q)
    };
    let Some(&(start, _)) = next.first() else {
        return Err(VertexStarError::Boundary {
            vertex,
            triangles: 0,
        });
    };
    let mut ring = vec![start];
    let mut p = start;
    loop {
        let Some(q) = follow(p)? else {
            return Err(VertexStarError::Boundary {
                vertex,
                triangles: n,
            });
        };
        if q == start {
            break;
        }
        // An open fan of n triangles has n + 1 ring vertices, a closed one n.
        if ring.len() > n {
            return Err(VertexStarError::NonManifold { vertex });
        }
        ring.push(q);
        p = q;
    }
    if ring.len() != n {
        return Err(VertexStarError::NonManifold { vertex });
    }
    ring.try_into()
        .map_err(|r: Vec<u32>| VertexStarError::Valence {
            vertex,
            valence: r.len(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A regular triangular grid of `n` x `n` points in the plane z = 0, counter-clockwise
    /// seen from +z.
    fn grid(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut pos = Vec::new();
        for j in 0..n {
            for i in 0..n {
                pos.push(Vec3::new(
                    i as f64 + 0.5 * j as f64,
                    j as f64 * 0.75f64.sqrt(),
                    0.0,
                ));
            }
        }
        let id = |i: u32, j: u32| j * n + i;
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (pos, tris)
    }

    #[test]
    fn interior_ring_is_the_six_neighbours_counter_clockwise() {
        let (pos, tris) = grid(5);
        let v = 2 * 5 + 2;
        let ring = vertex_ring(pos.len(), &tris, v).unwrap();
        let mut sorted = ring.to_vec();
        sorted.sort();
        assert_eq!(sorted, vec![7, 8, 11, 13, 16, 17]);
        // Counter-clockwise: every consecutive pair turns left around the vertex.
        for k in 0..6 {
            let a = pos[ring[k] as usize] - pos[v];
            let b = pos[ring[(k + 1) % 6] as usize] - pos[v];
            assert!(
                a.cross(&b).z > 0.0,
                "ring {ring:?} not counter-clockwise at {k}"
            );
        }
    }

    #[test]
    fn boundary_valence_and_range_are_typed_errors() {
        let (pos, tris) = grid(5);
        assert!(matches!(
            vertex_ring(pos.len(), &tris, 2),
            Err(VertexStarError::Boundary { vertex: 2, .. })
        ));
        assert!(matches!(
            vertex_ring(pos.len(), &tris, 99),
            Err(VertexStarError::OutOfRange { .. })
        ));
        // Drop one triangle around vertex 12: the fan no longer closes.
        let v = 12u32;
        let fewer: Vec<_> = tris
            .iter()
            .copied()
            .filter(|t| !(t.contains(&v) && t.contains(&13) && t.contains(&17)))
            .collect();
        assert!(matches!(
            vertex_ring(pos.len(), &fewer, 12),
            Err(VertexStarError::Boundary { triangles: 5, .. })
        ));
        // An open fan listed from its middle (a base-curve vertex after one layer).
        let open = [[0, 1, 34], [33, 0, 67], [67, 0, 34]];
        assert!(matches!(
            vertex_ring(68, &open, 0),
            Err(VertexStarError::Boundary { triangles: 3, .. })
        ));
        // A closed fan of four triangles (an octahedron's apex).
        let oct = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        assert!(matches!(
            vertex_ring(5, &oct, 0),
            Err(VertexStarError::Valence { valence: 4, .. })
        ));
    }

    /// A ray through a vertex's position picks that vertex; random rays through random points
    /// of random triangles pick the nearest corner of the first triangle hit.
    #[test]
    fn rays_pick_the_nearest_corner_of_the_first_hit() {
        let (mut pos, tris) = grid(6);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for p in &mut pos {
            p.z = 0.05 * rng.random::<f64>();
        }
        // High above a gently bumped grid: nothing occludes a vertex.
        let eye = Vec3::new(3.5, 2.0, 40.0);
        for (v, p) in pos.iter().enumerate() {
            let pick = pick_vertex(&pos, &tris, eye, p - eye).unwrap();
            assert_eq!(pick.vertex, v);
            assert!((pick.hit - p).norm() < 1e-9);
        }
        for _ in 0..200 {
            let ti = rng.random_range(0..tris.len());
            let t = tris[ti];
            let (mut a, mut b) = (rng.random::<f64>(), rng.random::<f64>());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let [p0, p1, p2] = t.map(|i| pos[i as usize]);
            let target = p0 + (p1 - p0) * a + (p2 - p0) * b;
            let pick = pick_vertex(&pos, &tris, eye, target - eye).unwrap();
            // Direction target - eye: the target is at t = 1, so the first hit is no farther;
            // on the target's own triangle it is the target.
            assert!(pick.t <= 1.0 + 1e-12);
            if pick.triangle == ti {
                assert!((pick.hit - target).norm() < 1e-9);
            }
            let hit_tri = tris[pick.triangle];
            let d = |i: u32| (pos[i as usize] - pick.hit).norm();
            assert!(hit_tri.contains(&(pick.vertex as u32)));
            assert!(hit_tri.iter().all(|&i| d(pick.vertex as u32) <= d(i)));
        }
        // Misses, a zero direction and NaN give nothing.
        assert!(pick_vertex(&pos, &tris, eye, Vec3::new(0.0, 0.0, 1.0)).is_none());
        assert!(pick_vertex(&pos, &tris, eye, Vec3::zeros()).is_none());
        assert!(pick_vertex(&pos, &tris, eye, Vec3::new(f64::NAN, 0.0, -1.0)).is_none());
    }

    /// Two stacked layers: the ray picks on the one nearer the eye.
    #[test]
    fn the_nearer_of_two_layers_wins() {
        let (pos, tris) = grid(4);
        let n = pos.len() as u32;
        let mut all = pos.clone();
        all.extend(pos.iter().map(|p| p + Vec3::new(0.0, 0.0, 1.0)));
        let mut t2 = tris.clone();
        t2.extend(tris.iter().map(|t| t.map(|i| i + n)));
        let target = pos[5];
        let up = pick_vertex(
            &all,
            &t2,
            target + Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(0.0, 0.0, -1.0),
        )
        .unwrap();
        assert_eq!(up.vertex, 5 + n as usize);
        let down = pick_vertex(
            &all,
            &t2,
            target - Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(0.0, 0.0, 1.0),
        )
        .unwrap();
        assert_eq!(down.vertex, 5);
    }
}
