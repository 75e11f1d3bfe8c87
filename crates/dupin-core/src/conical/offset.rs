//! Offsets of conical meshes (conical paper, Sec. 4): shift every face plane by a distance d
//! along its unit normal and intersect the shifted planes at each vertex. For a conical mesh
//! the planes around an interior valence-4 vertex still meet in one point, on the vertex's cone
//! axis, so the offset has the same connectivity and is again conical.
//!
//! Input: a mesh with planar faces (ideally conical), the distance. Output: the offset mesh.

use crate::Vec3;
use crate::conical::{cone_axes, face_normals};
use crate::math::Num;
use crate::mesh::PolyMesh;
use crate::mesh::{MeshTopology, TopologyError};
use thiserror::Error;

/// Why an offset could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OffsetError {
    /// The mesh is not an oriented manifold.
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// The distance is NaN or infinite.
    #[error("offset distance {} is not finite", Num(*.0))]
    BadDistance(f64),
    /// The distance is so large against the mesh that the offset would lose the design's
    /// precision (and, near f64::MAX, overflow to nothing).
    #[error(
        "offset distance {} is more than {} times the mesh's size (bounding-box diagonal {}); \
         use a distance within +-{}",
        Num(*.distance), MAX_OFFSET_TO_SIZE, Num(*.size), Num(MAX_OFFSET_TO_SIZE * *.size)
    )]
    DistanceTooLarge {
        /// The distance asked for.
        distance: f64,
        /// The mesh's bounding-box diagonal.
        size: f64,
    },
    /// A face has no normal (all vertices collinear).
    #[error("face {0} is degenerate (no normal)")]
    DegenerateFace(usize),
}

/// The largest offset distance, in bounding-box diagonals of the mesh: far beyond any beam or
/// glazing depth, and near the limit where the offset planes' intersections keep the input's
/// precision (each step of 10x costs a digit).
pub const MAX_OFFSET_TO_SIZE: f64 = 1e3;

/// Face distance of the offset a viewer shows when none is given: visible but thin against
/// the conical scenes, which are about 5 units across (conical paper, section 4).
pub const DEFAULT_OFFSET_DISTANCE: f64 = 0.15;

/// The face-offset mesh at distance `distance` (positive along the face normals).
///
/// Interior valence-4 vertices move along their cone axis ([`crate::conical::cone_axes`]) by
/// `d / cos θ`, θ the angle between axis and face normals. Other vertices satisfy the shifted
/// planes of their faces in the least-squares sense; when the planes do not determine them
/// (boundary vertices in one or two faces) the remaining freedom is used to make every offset
/// edge parallel to its original (least squares over the free directions), which makes the
/// support beams of boundary edges planar; what is still free after that goes to the point
/// nearest to `v + d m`, m the mean face normal. At interior conical vertices all shifted planes pass
/// through the result exactly.
pub fn offset_mesh(mesh: &PolyMesh, distance: f64) -> Result<PolyMesh, OffsetError> {
    if !distance.is_finite() {
        return Err(OffsetError::BadDistance(distance));
    }
    let size = mesh.bbox_diagonal();
    if distance.abs() > MAX_OFFSET_TO_SIZE * size {
        return Err(OffsetError::DistanceTooLarge { distance, size });
    }
    let topo = MeshTopology::new(mesh)?;
    let normals = face_normals(mesh);
    if let Some(f) = normals.iter().position(|n| n.norm_squared() == 0.0) {
        return Err(OffsetError::DegenerateFace(f));
    }
    let centroid: Vec<Vec3> = mesh
        .faces()
        .map(|f| f.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / f.len() as f64)
        .collect();
    let axes = cone_axes(mesh, &topo);
    let mut positions = mesh.positions.clone();
    // Per vertex not placed on its cone axis: the directions its shifted planes leave free.
    let mut free: Vec<Vec<Vec3>> = vec![Vec::new(); positions.len()];
    for (v, out) in positions.iter_mut().enumerate() {
        let star = topo.star(v);
        if star.is_empty() {
            continue;
        }
        // Interior valence-4 vertex: move along the cone axis by d / cos(angle to the faces);
        // well conditioned even when the four planes are nearly parallel.
        if let Some(a) = axes[v] {
            let cos = star
                .iter()
                .map(|&c| a.dot(&normals[topo.face_of(c) as usize]))
                .sum::<f64>()
                / star.len() as f64;
            if cos > 1e-6 {
                *out = mesh.positions[v] + a * (distance / cos);
                continue;
            }
        }
        let p = mesh.positions[v];
        let mut a = nalgebra::Matrix3::zeros();
        let mut b = Vec3::zeros();
        let mut m = Vec3::zeros();
        for &c in star {
            let f = topo.face_of(c) as usize;
            let n = normals[f];
            // Shifted plane n·x = n·centroid + d (the face plane through its centroid).
            let rhs = n.dot(&centroid[f]) + distance;
            a += n * n.transpose();
            b += n * rhs;
            m += n;
        }
        let y = p + distance * m.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        let eig = nalgebra::SymmetricEigen::new(a);
        let top = eig.eigenvalues.max();
        let r = b - a * y;
        let mut x = y;
        for k in 0..3 {
            let l = eig.eigenvalues[k];
            let e = eig.eigenvectors.column(k).into_owned();
            if l > 1e-10 * top {
                x += e * (e.dot(&r) / l);
            } else {
                free[v].push(e);
            }
        }
        *out = x;
    }
    parallel_boundary(mesh, &topo, &mut positions, &free);
    PolyMesh::new(positions, mesh.faces()).map_err(|_| OffsetError::DegenerateFace(0))
}

/// Moves the offset vertices that have free directions (`free[v]`, orthonormal; they keep
/// every shifted plane of the vertex) so that each offset edge touching them is parallel to
/// its original edge: `(b' - a') × (b - a) = 0`. An edge and its offset lie in the shifted
/// plane pair of a face, so they span a planar support quad exactly when they are parallel.
/// The conditions are linear in the free coordinates `t`; the minimum-norm least-squares `t`
/// (SVD, one connected group of coupled vertices at a time, typically one boundary loop)
/// satisfies them and otherwise stays at the nearest-point choice. Dense SVD because the
/// groups are boundary-sized (hundreds of unknowns) and may be rank deficient, e.g. the
/// symmetric trapezoids of a surface of revolution leave one direction free.
fn parallel_boundary(mesh: &PolyMesh, topo: &MeshTopology, pos: &mut [Vec3], free: &[Vec<Vec3>]) {
    let edges = topo.edges();
    let touches =
        |&(a, b): &(u32, u32)| !free[a as usize].is_empty() || !free[b as usize].is_empty();
    // Union-find over vertices with free directions, joined by the edges they share.
    let mut parent: Vec<usize> = (0..pos.len()).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for &(a, b) in &edges {
        if !free[a as usize].is_empty() && !free[b as usize].is_empty() {
            let (ra, rb) = (root(&mut parent, a as usize), root(&mut parent, b as usize));
            parent[ra] = rb;
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<(u32, u32)>> = Default::default();
    for e in edges.iter().filter(|e| touches(e)) {
        let v = if free[e.0 as usize].is_empty() {
            e.1
        } else {
            e.0
        };
        groups
            .entry(root(&mut parent, v as usize))
            .or_default()
            .push(*e);
    }
    for group in groups.values() {
        // Column of the first free coordinate of each vertex in this group.
        let mut col = std::collections::BTreeMap::new();
        let mut n = 0;
        for &(a, b) in group {
            for v in [a, b] {
                let k = free[v as usize].len();
                if k > 0 && !col.contains_key(&v) {
                    col.insert(v, n);
                    n += k;
                }
            }
        }
        let mut c = nalgebra::DMatrix::<f64>::zeros(3 * group.len(), n);
        let mut rhs = nalgebra::DVector::<f64>::zeros(3 * group.len());
        for (i, &(a, b)) in group.iter().enumerate() {
            let Some(e) =
                (mesh.positions[b as usize] - mesh.positions[a as usize]).try_normalize(0.0)
            else {
                continue;
            };
            let r0 = (pos[b as usize] - pos[a as usize]).cross(&e);
            for (v, sign) in [(a, -1.0), (b, 1.0)] {
                if let Some(&j) = col.get(&v) {
                    for (k, d) in free[v as usize].iter().enumerate() {
                        let g = d.cross(&e) * sign;
                        for r in 0..3 {
                            c[(3 * i + r, j + k)] = g[r];
                        }
                    }
                }
            }
            for r in 0..3 {
                rhs[3 * i + r] = -r0[r];
            }
        }
        let svd = c.svd(true, true);
        // Null directions show up at ~1e-12 relative (the input is conical to ~1e-12): treat
        // everything below 1e-8 as null, so the minimum-norm choice leaves them alone.
        let eps = 1e-8 * svd.singular_values.max();
        let Ok(t) = svd.solve(&rhs, eps) else {
            continue;
        };
        for (&v, &j) in &col {
            for (k, d) in free[v as usize].iter().enumerate() {
                pos[v as usize] += d * t[j + k];
            }
        }
    }
}
