//! Circular meshes (conical paper, Sec. 5, eq. (7)): a planar convex quad has a circumcircle
//! exactly when its opposite angles sum to π, φ1 + φ3 = π and φ2 + φ4 = π.

use crate::Vec3;
use crate::conical::discrete_terms::corner_angle;
use crate::mesh::PolyMesh;

/// The two circularity terms φ1 + φ3 - π and φ2 + φ4 - π of a quad face; `None` for other
/// face sizes.
pub fn quad_circularity(mesh: &PolyMesh, face: usize) -> Option<[f64; 2]> {
    let f = mesh.face(face);
    if f.len() != 4 {
        return None;
    }
    let pts: Vec<Vec3> = f.iter().map(|&v| mesh.positions[v as usize]).collect();
    let a: Vec<f64> = (0..4).map(|k| corner_angle(&pts, k)).collect();
    Some([
        a[0] + a[2] - std::f64::consts::PI,
        a[1] + a[3] - std::f64::consts::PI,
    ])
}

/// The contract's `circular_residual`: max over quad faces of |φ1 + φ3 - π| and |φ2 + φ4 - π|
/// in radians (0 when there is no quad).
pub fn circular_residual(mesh: &PolyMesh) -> f64 {
    (0..mesh.num_faces())
        .filter_map(|f| quad_circularity(mesh, f))
        .fold(0.0, |m, c| m.max(c[0].abs()).max(c[1].abs()))
}
