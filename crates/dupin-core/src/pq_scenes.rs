//! Input meshes and the PQ scenes of the outside contract (conical paper figures), plus the
//! benchmark meshes of the issue: a skew quad grid on z = xy and the centroid dual of a regular
//! torus triangulation.

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::surface::{Surface, Torus};

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
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|j| (0..n).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]))
        .collect();
    PolyMesh::new(p, faces).expect("grid indices are valid")
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
