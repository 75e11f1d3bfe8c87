//! A triangle (or polygon) mesh read from OBJ used as a surface: per-vertex curvature estimated
//! by quadric fitting on the 2-ring, closest point through a spatial index (P-Hex paper,
//! section 6: the distance term F_d to "the underlying surface approximated by a triangular
//! mesh", and section 7: curvature of freeform input).
//!
//! Spatial index: `rstar` (pure Rust R*-tree, no_std-friendly, builds for wasm32, already in
//! the dependency tree of `spade`); its exact nearest-neighbour search runs on our own triangle
//! type with an exact point-triangle distance.

use crate::Vec3;
use crate::mesh::PolyMesh;
use crate::mesh::{ObjError, parse_obj};
use crate::surface::SurfaceDerivatives;
use crate::surface::{Curvature, CurvatureError};
use nalgebra::{Matrix5, Vector5};
use rstar::{AABB, PointDistance, RTree, RTreeObject};
use thiserror::Error;

/// Why a mesh surface could not be built or queried.
///
/// (P-Hex paper, section 6.)
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshSurfaceError {
    /// The OBJ text could not be read.
    #[error(transparent)]
    Obj(#[from] ObjError),
    /// The query point contains NaN or infinity.
    #[error("the query point is not finite")]
    NonFinite,
    /// A vertex index is out of range.
    #[error("vertex {vertex} does not exist (the mesh has {count})")]
    NoSuchVertex {
        /// The index asked for.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// The vertex has too few neighbours in its 2-ring (fewer than 5) or a degenerate
    /// neighbourhood (zero normal, collinear neighbours), so no quadric can be fitted.
    #[error("no curvature estimate at vertex {vertex}: degenerate or too small 2-ring")]
    CurvatureUnavailable {
        /// The vertex.
        vertex: usize,
    },
}

/// Curvature estimated at one mesh vertex (same conventions as [`Curvature`]; the normal points
/// to the side from which faces are counter-clockwise).
///
/// (P-Hex paper, sections 3 and 6.)
pub type VertexCurvature = Curvature;

/// Closest point on a mesh surface.
///
/// (P-Hex paper, section 6.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshClosestPoint {
    /// The closest point.
    pub point: Vec3,
    /// The face it lies on (index into the input mesh's faces).
    pub face: usize,
    /// Distance from the query point.
    pub distance: f64,
}

#[derive(Debug, Clone, Copy)]
struct Tri {
    a: Vec3,
    b: Vec3,
    c: Vec3,
    face: u32,
}

impl RTreeObject for Tri {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        let lo = self.a.inf(&self.b).inf(&self.c);
        let hi = self.a.sup(&self.b).sup(&self.c);
        AABB::from_corners([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z])
    }
}

impl PointDistance for Tri {
    fn distance_2(&self, p: &[f64; 3]) -> f64 {
        let p = Vec3::new(p[0], p[1], p[2]);
        (closest_on_triangle(&p, &self.a, &self.b, &self.c) - p).norm_squared()
    }
}

/// Exact closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
pub(crate) fn closest_on_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    if !denom.is_finite() {
        // Degenerate (zero-area) triangle: the nearest of its edges.
        let seg = |x: &Vec3, y: &Vec3| {
            let d = y - x;
            let t = if d.norm_squared() > 0.0 {
                ((p - x).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            x + d * t
        };
        let cands = [seg(a, b), seg(b, c), seg(c, a)];
        return cands
            .into_iter()
            .min_by(|x, y| (x - p).norm_squared().total_cmp(&(y - p).norm_squared()))
            .unwrap_or(*a);
    }
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// A polygon mesh used as a surface (P-Hex paper, section 6).
#[derive(Debug, Clone)]
pub struct MeshSurface {
    mesh: PolyMesh,
    curvature: Vec<Option<VertexCurvature>>,
    tree: RTree<Tri>,
}

impl MeshSurface {
    /// Reads an OBJ (contract format) and builds the surface.
    pub fn from_obj(text: &str) -> Result<Self, MeshSurfaceError> {
        Ok(Self::from_mesh(parse_obj(text)?))
    }

    /// Builds the surface: polygon faces are fanned into triangles for the index; every vertex
    /// gets a curvature estimate where its 2-ring allows one.
    pub fn from_mesh(mesh: PolyMesh) -> Self {
        let n = mesh.num_vertices();
        let mut tris = Vec::new();
        let mut normals = vec![Vec3::zeros(); n];
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (fi, f) in mesh.faces().enumerate() {
            let p = |k: usize| mesh.positions[f[k] as usize];
            // Newell normal, area-weighted.
            let mut fnorm = Vec3::zeros();
            for k in 0..f.len() {
                fnorm += p(k).cross(&p((k + 1) % f.len()));
            }
            for k in 0..f.len() {
                normals[f[k] as usize] += fnorm;
                let (x, y) = (f[k], f[(k + 1) % f.len()]);
                if !adj[x as usize].contains(&y) {
                    adj[x as usize].push(y);
                }
                if !adj[y as usize].contains(&x) {
                    adj[y as usize].push(x);
                }
            }
            for k in 1..f.len() - 1 {
                tris.push(Tri {
                    a: p(0),
                    b: p(k),
                    c: p(k + 1),
                    face: fi as u32,
                });
            }
        }
        let mut ring = Vec::new();
        let curvature = (0..n)
            .map(|i| {
                ring.clear();
                for &j in &adj[i] {
                    if !ring.contains(&j) {
                        ring.push(j);
                    }
                    for &k in &adj[j as usize] {
                        if k as usize != i && !ring.contains(&k) {
                            ring.push(k);
                        }
                    }
                }
                fit_quadric(&mesh.positions, i, &ring, &normals[i]).ok()
            })
            .collect();
        MeshSurface {
            tree: RTree::bulk_load(tris),
            mesh,
            curvature,
        }
    }

    /// The underlying mesh.
    pub fn mesh(&self) -> &PolyMesh {
        &self.mesh
    }

    /// Estimated curvature at vertex `i`.
    pub fn vertex_curvature(&self, i: usize) -> Result<VertexCurvature, MeshSurfaceError> {
        match self.curvature.get(i) {
            None => Err(MeshSurfaceError::NoSuchVertex {
                vertex: i,
                count: self.curvature.len(),
            }),
            Some(None) => Err(MeshSurfaceError::CurvatureUnavailable { vertex: i }),
            Some(Some(c)) => Ok(*c),
        }
    }

    /// The closest point of the mesh to `p` (exact, through the R*-tree).
    pub fn closest_point(&self, p: &Vec3) -> Result<MeshClosestPoint, MeshSurfaceError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(MeshSurfaceError::NonFinite);
        }
        let q = [p.x, p.y, p.z];
        let t = self
            .tree
            .nearest_neighbor(q)
            .ok_or(MeshSurfaceError::NonFinite)?;
        let point = closest_on_triangle(p, &t.a, &t.b, &t.c);
        Ok(MeshClosestPoint {
            point,
            face: t.face as usize,
            distance: (point - p).norm(),
        })
    }
}

/// Least-squares fit of z = a x^2 + b x y + c y^2 + d x + e y over the ring in a local frame
/// around the estimated normal, then the Monge-patch curvature at the origin.
fn fit_quadric(
    pos: &[Vec3],
    i: usize,
    ring: &[u32],
    normal: &Vec3,
) -> Result<VertexCurvature, CurvatureError> {
    let n = normal
        .try_normalize(0.0)
        .ok_or(CurvatureError::SingularParametrisation)?;
    if ring.len() < 5 {
        return Err(CurvatureError::SingularParametrisation);
    }
    let helper = if n.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let t1 = n.cross(&helper).normalize();
    let t2 = n.cross(&t1);
    let o = pos[i];
    let scale = ring
        .iter()
        .map(|&j| (pos[j as usize] - o).norm())
        .sum::<f64>()
        / ring.len() as f64;
    if !(scale > 0.0) {
        return Err(CurvatureError::SingularParametrisation);
    }
    let mut ata = Matrix5::zeros();
    let mut atb = Vector5::zeros();
    for &j in ring {
        let d = (pos[j as usize] - o) / scale;
        let (x, y, z) = (d.dot(&t1), d.dot(&t2), d.dot(&n));
        let row = Vector5::new(x * x, x * y, y * y, x, y);
        ata += row * row.transpose();
        atb += row * z;
    }
    let sol = ata
        .cholesky()
        .ok_or(CurvatureError::SingularParametrisation)?
        .solve(&atb);
    // Undo the scaling: z/s = A (x/s)^2 + ... so second-order coefficients divide by s.
    let (a, b, c) = (sol[0] / scale, sol[1] / scale, sol[2] / scale);
    let (d, e) = (sol[3], sol[4]);
    let local = SurfaceDerivatives {
        p: Vec3::zeros(),
        pu: Vec3::new(1.0, 0.0, d),
        pv: Vec3::new(0.0, 1.0, e),
        puu: Vec3::new(0.0, 0.0, 2.0 * a),
        puv: Vec3::new(0.0, 0.0, b),
        pvv: Vec3::new(0.0, 0.0, 2.0 * c),
    };
    let k = Curvature::from_derivatives(&local)?;
    let world = |v: &Vec3| t1 * v.x + t2 * v.y + n * v.z;
    Ok(Curvature {
        point: o,
        normal: world(&k.normal),
        dir1: world(&k.dir1),
        dir2: world(&k.dir2),
        ..k
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::write_obj;
    use crate::scenes::benchmark_meshes::torus_triangulation;
    use crate::surface::{Surface, Torus};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn torus_curvature_within_two_percent() {
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let (nu, nv) = (240, 96);
        // Through OBJ text, as the CLI reads it.
        let surf =
            MeshSurface::from_obj(&write_obj(&torus_triangulation(nu, nv, t.major, t.minor)))
                .unwrap();
        let mut worst: f64 = 0.0;
        let mut worst_normal: f64 = 0.0;
        for j in 0..nv {
            for i in (0..nu).step_by(7) {
                let u = std::f64::consts::TAU * i as f64 / nu as f64;
                let v = std::f64::consts::TAU * j as f64 / nv as f64;
                let exact = t.curvature(u, v).unwrap();
                let est = surf.vertex_curvature(j * nu + i).unwrap();
                let scale = exact.k1.abs().max(exact.k2.abs());
                worst = worst
                    .max((est.k1 - exact.k1).abs() / scale)
                    .max((est.k2 - exact.k2).abs() / scale);
                worst_normal = worst_normal.max((est.normal - exact.normal).norm());
            }
        }
        eprintln!(
            "mesh torus: worst relative curvature error {worst:.3e}, normal error {worst_normal:.3e}"
        );
        assert!(worst_normal < 1e-2, "normal error {worst_normal}");
        assert!(worst < 0.02, "worst relative error {worst}");
    }

    #[test]
    fn closest_point_matches_brute_force() {
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let mesh = torus_triangulation(40, 20, t.major, t.minor);
        let surf = MeshSurface::from_mesh(mesh.clone());
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let p = Vec3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-1.0..1.0),
            );
            let got = surf.closest_point(&p).unwrap();
            let mut best = f64::INFINITY;
            for f in mesh.faces() {
                let q = closest_on_triangle(
                    &p,
                    &mesh.positions[f[0] as usize],
                    &mesh.positions[f[1] as usize],
                    &mesh.positions[f[2] as usize],
                );
                best = best.min((q - p).norm());
            }
            assert!((got.distance - best).abs() < 1e-12);
        }
        assert_eq!(
            surf.closest_point(&Vec3::new(f64::NAN, 0.0, 0.0)),
            Err(MeshSurfaceError::NonFinite)
        );
        assert!(matches!(
            surf.vertex_curvature(100_000),
            Err(MeshSurfaceError::NoSuchVertex { .. })
        ));
    }

    #[test]
    fn closest_on_triangle_regions() {
        let (a, b, c) = (
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let q = |x: f64, y: f64, z: f64| closest_on_triangle(&Vec3::new(x, y, z), &a, &b, &c);
        assert!((q(0.2, 0.2, 5.0) - Vec3::new(0.2, 0.2, 0.0)).norm() < 1e-15);
        assert_eq!(q(-1.0, -1.0, 0.0), a);
        assert_eq!(q(2.0, -0.5, 0.0), b);
        assert!((q(0.5, -1.0, 0.0) - Vec3::new(0.5, 0.0, 0.0)).norm() < 1e-15);
        assert!((q(1.0, 1.0, 0.0) - Vec3::new(0.5, 0.5, 0.0)).norm() < 1e-15);
        // Degenerate triangle.
        let d = closest_on_triangle(&Vec3::new(0.5, 1.0, 0.0), &a, &b, &b);
        assert!((d - Vec3::new(0.5, 0.0, 0.0)).norm() < 1e-15);
    }
}
