//! Conical meshes (conical paper, Sec. 4): at every interior vertex of valence four the four
//! face planes touch one oriented cone of revolution, equivalently (Geometry Fact 1) the
//! interior angles ω1..ω4 of the four faces at the vertex balance, ω1 + ω3 = ω2 + ω4.

use crate::Vec3;
use crate::conical::discrete_terms::angle_grad;
use crate::mesh::MeshTopology;
use crate::mesh::PolyMesh;

/// One interior angle at a vertex: value, (vertex, previous, next) and their gradients.
pub(crate) type VertexAngle = (f64, [u32; 3], [Vec3; 3]);

/// The four interior angles ω1..ω4 at an interior valence-4 vertex `v`, in rotation order,
/// with their gradients (with respect to v, the previous and the next vertex of each face).
/// `None` for other vertices.
pub(crate) fn vertex_angles(
    mesh: &PolyMesh,
    topo: &MeshTopology,
    v: usize,
) -> Option<[VertexAngle; 4]> {
    let star = topo.star(v);
    if topo.is_boundary(v) || star.len() != 4 {
        return None;
    }
    let p = &mesh.positions;
    let mut out = [(0.0, [0u32; 3], [Vec3::zeros(); 3]); 4];
    for (k, &c) in star.iter().enumerate() {
        let a = topo.source(topo.prev(c));
        let b = topo.target(c);
        let (w, g) = angle_grad(p[v], p[a as usize], p[b as usize]);
        out[k] = (w, [v as u32, a, b], g);
    }
    Some(out)
}

/// The angle balance ω1 - ω2 + ω3 - ω4 (radians) at interior valence-4 vertex `v`; `None` for
/// other vertices. Zero exactly when the vertex is conical (Geometry Fact 1).
pub fn angle_balance(mesh: &PolyMesh, topo: &MeshTopology, v: usize) -> Option<f64> {
    vertex_angles(mesh, topo, v).map(|a| a[0].0 - a[1].0 + a[2].0 - a[3].0)
}

/// The contract's `conical_residual`: max over interior valence-4 vertices of
/// |ω1 + ω3 - ω2 - ω4| in radians (0 when there is no such vertex).
pub fn conical_residual(mesh: &PolyMesh, topo: &MeshTopology) -> f64 {
    topo.interior_valence4()
        .into_iter()
        .filter_map(|v| angle_balance(mesh, topo, v))
        .fold(0.0, |m, b| m.max(b.abs()))
}

/// Geometric type of a conical mesh vertex (conical paper, Sec. 4): where the four edges at the
/// vertex point to on a small sphere around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexType {
    /// The four edge directions lie in one hemisphere and form a convex spherical quad.
    Elliptic,
    /// The four edge directions cannot be contained in one hemisphere.
    Hyperbolic,
    /// The four edge directions lie in one hemisphere but their spherical quad is not convex.
    Parabolic,
}

/// Unit edge directions from interior valence-4 vertex `v` to its neighbours, in rotation
/// order.
fn edge_directions(mesh: &PolyMesh, topo: &MeshTopology, v: usize) -> Option<[Vec3; 4]> {
    if topo.is_boundary(v) || topo.star(v).len() != 4 {
        return None;
    }
    let nb = topo.neighbors(v);
    let p = &mesh.positions;
    let mut out = [Vec3::zeros(); 4];
    for k in 0..4 {
        out[k] = (p[nb[k] as usize] - p[v]).try_normalize(0.0)?;
    }
    Some(out)
}

/// The type of interior valence-4 vertex `v` (`None` for other vertices or degenerate stars).
pub fn vertex_type(mesh: &PolyMesh, topo: &MeshTopology, v: usize) -> Option<VertexType> {
    let u = edge_directions(mesh, topo, v)?;
    // The directions fit in an open hemisphere iff the origin is outside their convex hull.
    let m = nalgebra::Matrix3::from_columns(&[u[1] - u[0], u[2] - u[0], u[3] - u[0]]);
    let in_hull = match m.try_inverse() {
        Some(inv) => {
            let l = inv * (-u[0]);
            let l0 = 1.0 - l.sum();
            l.iter().all(|&x| x >= 0.0) && l0 >= 0.0
        }
        // Coplanar directions: the origin is in the hull only if it lies in their plane.
        None => m.column(0).cross(&m.column(1)).dot(&u[0]).abs() < 1e-14,
    };
    if in_hull {
        return Some(VertexType::Hyperbolic);
    }
    let signs: Vec<f64> = (0..4)
        .map(|i| u[(i + 3) % 4].cross(&u[i]).dot(&u[(i + 1) % 4]))
        .collect();
    if signs.iter().all(|&s| s > 0.0) || signs.iter().all(|&s| s < 0.0) {
        Some(VertexType::Elliptic)
    } else {
        Some(VertexType::Parabolic)
    }
}

/// Unit normal (along the Newell normal) of every face.
pub fn face_normals(mesh: &PolyMesh) -> Vec<Vec3> {
    mesh.faces()
        .map(|f| {
            let n = f.len();
            let mut s = Vec3::zeros();
            for k in 0..n {
                s += mesh.positions[f[k] as usize].cross(&mesh.positions[f[(k + 1) % n] as usize]);
            }
            s.try_normalize(0.0).unwrap_or_else(Vec3::zeros)
        })
        .collect()
}

/// The cone axis (discrete unit normal) at every interior valence-4 vertex: the unit vector
/// making equal angles with the four face normals (the spherical centre of the circle through
/// them), oriented like the normals. `None` at other vertices and where the normals are
/// degenerate. For a non-conical vertex the axis is fitted to the first three normals.
pub fn cone_axes(mesh: &PolyMesh, topo: &MeshTopology) -> Vec<Option<Vec3>> {
    let normals = face_normals(mesh);
    (0..mesh.num_vertices())
        .map(|v| {
            if topo.is_boundary(v) || topo.star(v).len() != 4 {
                return None;
            }
            let n: Vec<Vec3> = topo
                .star(v)
                .iter()
                .map(|&c| normals[topo.face_of(c) as usize])
                .collect();
            // Least-squares: a ⟂ (n_i - n_0) for i = 1..3, i.e. smallest eigenvector.
            let mut m = nalgebra::Matrix3::zeros();
            for k in 1..4 {
                let d = n[k] - n[0];
                m += d * d.transpose();
            }
            let eig = nalgebra::SymmetricEigen::new(m);
            let mut a: Vec3 = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
            let mean = n.iter().sum::<Vec3>();
            if a.dot(&mean) < 0.0 {
                a = -a;
            }
            a.try_normalize(1e-300)
        })
        .collect()
}

/// Discrete focal points (conical paper, Sec. 4): for every edge between two vertices with
/// cone axes, the intersection of the two axes (midpoint of their closest points; `None`
/// for parallel axes). Returned as `(a, b, point)`.
pub fn focal_points(mesh: &PolyMesh, topo: &MeshTopology) -> Vec<(u32, u32, Option<Vec3>)> {
    let axes = cone_axes(mesh, topo);
    let p = &mesh.positions;
    topo.edges()
        .into_iter()
        .filter_map(|(a, b)| {
            let (da, db) = (axes[a as usize]?, axes[b as usize]?);
            let (pa, pb) = (p[a as usize], p[b as usize]);
            let w = pa - pb;
            let (aa, ab, bb) = (da.dot(&da), da.dot(&db), db.dot(&db));
            let den = aa * bb - ab * ab;
            if den.abs() < 1e-14 {
                return Some((a, b, None));
            }
            let s = (ab * db.dot(&w) - bb * da.dot(&w)) / den;
            let t = (aa * db.dot(&w) - ab * da.dot(&w)) / den;
            Some((a, b, Some(0.5 * ((pa + s * da) + (pb + t * db)))))
        })
        .collect()
}

/// The spherical image (conical paper, Sec. 4): one vertex per face at its unit normal, one
/// face per interior vertex through the normals of its faces in rotation order. For a conical
/// mesh it is a circular mesh.
pub fn spherical_image(mesh: &PolyMesh, topo: &MeshTopology) -> PolyMesh {
    let normals = face_normals(mesh);
    let faces: Vec<Vec<u32>> = (0..mesh.num_vertices())
        .filter(|&v| !topo.is_boundary(v) && topo.star(v).len() >= 3)
        .map(|v| topo.star(v).iter().map(|&c| topo.face_of(c)).collect())
        .collect();
    PolyMesh::new(normals, faces).unwrap_or_default()
}
