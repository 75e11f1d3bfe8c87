//! Offsets of conical meshes (conical paper, Sec. 4): shift every face plane by a distance d
//! along its unit normal and intersect the shifted planes at each vertex. For a conical mesh
//! the planes around an interior valence-4 vertex still meet in one point, on the vertex's cone
//! axis, so the offset has the same connectivity and is again conical.
//!
//! Input: a mesh with planar faces (ideally conical), the distance. Output: the offset mesh.

use crate::conical::{cone_axes, face_normals};
use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::mesh_topology::{MeshTopology, TopologyError};
use thiserror::Error;

/// Why an offset could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OffsetError {
    /// The mesh is not an oriented manifold.
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// The distance is NaN or infinite.
    #[error("offset distance {0} is not finite")]
    BadDistance(f64),
    /// A face has no normal (all vertices collinear).
    #[error("face {0} is degenerate (no normal)")]
    DegenerateFace(usize),
}

/// The face-offset mesh at distance `distance` (positive along the face normals).
///
/// Interior valence-4 vertices move along their cone axis ([`crate::cone_axes`]) by
/// `d / cos θ`, θ the angle between axis and face normals. Other vertices satisfy the shifted
/// planes of their faces in the least-squares sense; when
/// they do not determine it (boundary vertices in one or two faces) the remaining freedom is
/// fixed by the point nearest to `v + d m`, m the mean face normal. At interior conical
/// vertices all shifted planes pass through the result exactly.
pub fn offset_mesh(mesh: &PolyMesh, distance: f64) -> Result<PolyMesh, OffsetError> {
    if !distance.is_finite() {
        return Err(OffsetError::BadDistance(distance));
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
            if l > 1e-10 * top {
                let e = eig.eigenvectors.column(k);
                x += e * (e.dot(&r) / l);
            }
        }
        *out = x;
    }
    PolyMesh::new(positions, mesh.faces()).map_err(|_| OffsetError::DegenerateFace(0))
}
