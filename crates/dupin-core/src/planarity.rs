//! The planarity measure of the outside contract: for each face, the largest distance of its
//! vertices from the face's least-squares plane, divided by the face's mean edge length.

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use nalgebra::{Matrix3, SymmetricEigen};

/// Planarity error of face `i` of `mesh` (0 for a triangle, up to rounding).
///
/// The least-squares plane passes through the centroid, with normal the eigenvector of the
/// smallest eigenvalue of the vertices' covariance matrix.
pub fn face_planarity(mesh: &PolyMesh, i: usize) -> f64 {
    let f = mesh.face(i);
    let pts: Vec<Vec3> = f.iter().map(|&v| mesh.positions[v as usize]).collect();
    let c = pts.iter().sum::<Vec3>() / pts.len() as f64;
    let mut cov = Matrix3::zeros();
    for p in &pts {
        let d = p - c;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imin();
    let n = eig.eigenvectors.column(k).into_owned();
    let dmax = pts
        .iter()
        .map(|p| (p - c).dot(&n).abs())
        .fold(0.0, f64::max);
    let e = mesh.face_mean_edge(i);
    if e > 0.0 { dmax / e } else { 0.0 }
}

/// Largest [`face_planarity`] over all faces (0 for a mesh without faces).
pub fn max_planarity(mesh: &PolyMesh) -> f64 {
    (0..mesh.num_faces())
        .map(|i| face_planarity(mesh, i))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planar_and_bent_quads() {
        let mut p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let m = PolyMesh::new(p.clone(), [[0u32, 1, 2, 3]]).unwrap();
        assert!(max_planarity(&m) < 1e-15);
        // Lift one corner by h: the LSQ plane leaves every vertex at distance h/4.
        p[2].z = 0.1;
        let m = PolyMesh::new(p, [[0u32, 1, 2, 3]]).unwrap();
        let edge = (2.0 + 2.0 * (1.0f64 + 0.01).sqrt()) / 4.0;
        let got = max_planarity(&m);
        assert!(got > 0.02 && got < 0.03, "{got} vs edge {edge}");
    }
}
