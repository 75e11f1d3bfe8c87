//! Test and benchmark meshes for PQ perturbation: a skew quad grid on z = xy, a regular torus
//! quad mesh, a noisy vase, a regular torus triangulation and its centroid dual; and a NURBS
//! roof and a triangulated dome for the import path.

use crate::Vec3;
use crate::conical::principal_quad_mesh;
use crate::mesh::PolyMesh;
use crate::surface::{NurbsDefinition, Surface, SurfaceOfRevolution, Torus};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A quad grid of `n x n` quads over \[-1, 1\]², rotated by `rotation_deg` about the z axis
/// and lifted to the saddle z = xy. The grid lines are neither principal nor asymptotic
/// directions of the surface, so the quads are far from planar.
pub fn skew_quad_grid(n: usize, rotation_deg: f64) -> PolyMesh {
    let n = n.max(1);
    let (s, c) = rotation_deg.to_radians().sin_cos();
    let mut p = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let a = -1.0 + 2.0 * i as f64 / n as f64;
            let b = -1.0 + 2.0 * j as f64 / n as f64;
            let (x, y) = (c * a - s * b, s * a + c * b);
            p.push(Vec3::new(x, y, x * y));
        }
    }
    PolyMesh::quad_grid(p, n, n).expect("grid indices are valid")
}

/// The `nu x nv` quad mesh of a torus's parameter lines (R = `major`, r = `minor`; its
/// principal curvature lines, so the quads are planar up to O(h^2)): vertex `i * nv + j` at
/// (u, v) = 2π (i / nu, j / nv), quads oriented along the outward normal.
pub fn torus_quad_mesh(nu: usize, nv: usize, major: f64, minor: f64) -> PolyMesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let torus = Torus { major, minor };
    let (du, dv) = (
        std::f64::consts::TAU / nu as f64,
        std::f64::consts::TAU / nv as f64,
    );
    let p: Vec<Vec3> = (0..nu)
        .flat_map(|i| (0..nv).map(move |j| (i, j)))
        .map(|(i, j)| torus.position(i as f64 * du, j as f64 * dv))
        .collect();
    let faces: Vec<[u32; 4]> = (0..nu)
        .flat_map(|i| {
            (0..nv).map(move |j| {
                let (i1, j1) = ((i + 1) % nu, (j + 1) % nv);
                [i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1].map(|k| k as u32)
            })
        })
        .collect();
    PolyMesh::new(p, faces).expect("grid indices are valid")
}

/// The principal `n x n` quad mesh of the vase (its profile over (0, 6), angles (-0.9, 0.9))
/// with seeded noise of 2% of the grid spacing on every coordinate: a conical start far from
/// conical, the PQ benchmarks' harder case.
pub fn noisy_vase(n: usize) -> PolyMesh {
    let mut m = principal_quad_mesh(&SurfaceOfRevolution::vase(), (0.0, 6.0), (-0.9, 0.9), n, n);
    let h = 6.0 / n as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += 0.02 * h * (rng.random::<f64>() * 2.0 - 1.0);
        }
    }
    m
}

/// The regular triangulation of a torus (R = `major`, r = `minor`) with `nu x nv` vertices at
/// u = 2 pi i / nu, v = 2 pi j / nv, each parameter quad split along the same diagonal (all
/// valences 6): `2 nu nv` triangles, oriented along the outward normal. The closed test mesh of
/// the mesh-surface queries (closest point, footpoints) and their benchmarks.
pub fn torus_triangulation(nu: usize, nv: usize, major: f64, minor: f64) -> PolyMesh {
    let torus = Torus { major, minor };
    let mut pos = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let u = std::f64::consts::TAU * i as f64 / nu as f64;
            let v = std::f64::consts::TAU * j as f64 / nv as f64;
            pos.push(torus.position(u, v));
        }
    }
    let id = |i: usize, j: usize| ((j % nv) * nu + (i % nu)) as u32;
    let mut faces = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(pos, faces).expect("grid indices are valid")
}

/// The centroid dual of the regular triangulation of a torus (R = `major`, r = `minor`) with
/// `nu x nv` vertices (each parameter quad split along the same diagonal, all valences 6):
/// one vertex per triangle at its centroid, one hexagon per torus vertex. `nu * nv` hexagons,
/// oriented along the outward normal.
pub fn torus_centroid_dual(nu: usize, nv: usize, major: f64, minor: f64) -> PolyMesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let torus = Torus { major, minor };
    let du = std::f64::consts::TAU / nu as f64;
    let dv = std::f64::consts::TAU / nv as f64;
    let vert = |i: usize, j: usize| torus.position((i % nu) as f64 * du, (j % nv) as f64 * dv);
    // Triangle (i, j, 0) = (i,j),(i+1,j),(i+1,j+1); (i, j, 1) = (i,j),(i+1,j+1),(i,j+1).
    let mut p = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            p.push((vert(i, j) + vert(i + 1, j) + vert(i + 1, j + 1)) / 3.0);
            p.push((vert(i, j) + vert(i + 1, j + 1) + vert(i, j + 1)) / 3.0);
        }
    }
    let tri = |i: usize, j: usize, k: usize| (2 * ((j % nv) * nu + (i % nu)) + k) as u32;
    let mut faces = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (im, jm) = (i + nu - 1, j + nv - 1);
            faces.push([
                tri(i, j, 0),
                tri(i, j, 1),
                tri(im, j, 0),
                tri(im, jm, 1),
                tri(im, jm, 0),
                tri(i, jm, 1),
            ]);
        }
    }
    PolyMesh::new(p, faces).expect("dual indices are valid")
}

/// An imported design for tests and benchmarks: a bicubic B-spline roof 20 m x 15 m (12 x 9
/// control points, in metres) whose control heights are f(x) + g(y): the surface is
/// then exactly translational, (X(s), Y(t), F(s) + G(t)), so its parameter lines are conjugate
/// (method 2 applies), and F = 2 sin(x / 5), G = 0.06 y^2 give K > 0 for x < 0, K < 0 for x > 0
/// and a parabolic line between (the imported stand-in of the paper's Fig. 22).
pub fn nurbs_roof() -> NurbsDefinition {
    let p = 3;
    let knots = |n: usize| {
        let spans = n - p;
        let mut k = vec![0.0; p + 1];
        k.extend((1..spans).map(|i| i as f64));
        k.extend(vec![spans as f64; p + 1]);
        k
    };
    let greville = |k: &[f64], n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| k[i + 1..i + p + 1].iter().sum::<f64>() / p as f64 / (n - p) as f64)
            .collect()
    };
    let (nu, nv) = (12, 9);
    let (ku, kv) = (knots(nu), knots(nv));
    let control_points = greville(&ku, nu)
        .iter()
        .map(|a| {
            let x = -10.0 + 20.0 * a;
            greville(&kv, nv)
                .iter()
                .map(|b| {
                    let y = -7.5 + 15.0 * b;
                    [x, y, 2.0 * (x / 5.0).sin() + 0.06 * y * y]
                })
                .collect()
        })
        .collect();
    NurbsDefinition {
        degree_u: p,
        degree_v: p,
        knots_u: ku,
        knots_v: kv,
        control_points,
        weights: None,
        unit: Some("m".into()),
    }
}

/// A triangle mesh with no UVs for the surface fit's tests and benchmarks: a dome 12 m x 12 m,
/// z = 3 - (x² + y²) / 24 (K > 0), as an irregular triangulation of `2 n²` triangles: a grid
/// with jittered interior vertices and randomly chosen diagonals, the vertex order shuffled.
pub fn dome_triangle_mesh(n: usize, seed: u64) -> PolyMesh {
    jittered_height_mesh(n, seed, |x, y| 3.0 - (x * x + y * y) / 24.0)
}

/// A triangle mesh with no UVs of mixed curvature: a Gaussian bump 12 m x 12 m,
/// z = 3 exp(-r² / 18), elliptic (K > 0) inside r = 3 m and hyperbolic (K < 0) outside, the
/// parabolic circle r = 3 m between, triangulated as [`dome_triangle_mesh`] is.
pub fn bump_triangle_mesh(n: usize, seed: u64) -> PolyMesh {
    jittered_height_mesh(n, seed, |x, y| 3.0 * (-(x * x + y * y) / 18.0).exp())
}

/// A triangle mesh with no UVs of mixed curvature with a conjugate network: a translational
/// roof 12 m x 12 m, z = 3 - x² / 24 + 0.8 sin(y / 2), elliptic (K > 0) for y > 0 and
/// hyperbolic (K < 0) for y < 0, the parabolic line y = 0 between; its x and y lines are
/// conjugate (z_xy = 0). Triangulated as [`dome_triangle_mesh`] is.
pub fn translational_roof_triangle_mesh(n: usize, seed: u64) -> PolyMesh {
    jittered_height_mesh(n, seed, |x, y| 3.0 - x * x / 24.0 + 0.8 * (y / 2.0).sin())
}

/// The height field `z(x, y)` over [-6, 6]² as an irregular triangulation of `2 n²` triangles:
/// a grid with jittered interior vertices and randomly chosen diagonals, the vertex order
/// shuffled (an exporter's order is not a grid's).
fn jittered_height_mesh(n: usize, seed: u64, z: impl Fn(f64, f64) -> f64) -> PolyMesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let h = 12.0 / n as f64;
    let mut order: Vec<usize> = (0..(n + 1) * (n + 1)).collect();
    for k in (1..order.len()).rev() {
        order.swap(k, rng.random_range(0..=k));
    }
    let mut positions = vec![Vec3::zeros(); order.len()];
    for i in 0..=n {
        for j in 0..=n {
            let jitter = |rng: &mut ChaCha8Rng, edge: bool| {
                if edge {
                    0.0
                } else {
                    rng.random_range(-0.3..0.3) * h
                }
            };
            let x = -6.0 + i as f64 * h + jitter(&mut rng, i == 0 || i == n);
            let y = -6.0 + j as f64 * h + jitter(&mut rng, j == 0 || j == n);
            positions[order[i * (n + 1) + j]] = Vec3::new(x, y, z(x, y));
        }
    }
    let id = |i: usize, j: usize| order[i * (n + 1) + j] as u32;
    let mut faces = vec![];
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if rng.random::<bool>() {
                faces.extend([[a, b, c], [a, c, d]]);
            } else {
                faces.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    PolyMesh::new(positions, faces).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshTopology;

    #[test]
    fn torus_quad_mesh_is_closed_and_faces_outward() {
        let m = torus_quad_mesh(12, 8, 2.0, 0.7);
        assert_eq!((m.num_vertices(), m.num_faces()), (96, 96));
        let topo = MeshTopology::new(&m).unwrap();
        assert!((0..m.num_vertices()).all(|v| !topo.is_boundary(v)));
        for f in 0..m.num_faces() {
            let v: Vec<Vec3> = m.face(f).iter().map(|&i| m.positions[i as usize]).collect();
            let n = (v[2] - v[0]).cross(&(v[3] - v[1]));
            let c = (v[0] + v[1] + v[2] + v[3]) / 4.0;
            let axis = Vec3::new(c.x, c.y, 0.0).normalize() * 2.0;
            assert!(n.dot(&(c - axis)) > 0.0, "face {f} points inward");
        }
    }
}
