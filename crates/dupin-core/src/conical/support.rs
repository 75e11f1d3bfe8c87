//! Support structure of a conical mesh (conical paper, Sec. 4, Fig. 12): for every edge the
//! quad between the edge and the corresponding edge of an offset mesh. Because neighbouring
//! cone axes are coplanar (Geometry Fact 2), these quads are planar: beams of constant height
//! that can be cut from flat stock.

use crate::conical::{OffsetError, offset_mesh};
use crate::mesh::MeshTopology;
use crate::mesh::PolyMesh;

/// The support structure between `mesh` and its offset at distance `distance`: one quad per
/// edge (a, b): a, b, b', a' (primes on the offset), in the order of
/// [`MeshTopology::edges`]. Returns the offset mesh too.
///
/// Beams between two vertices that have cone axes (interior valence-4 vertices of a conical
/// mesh) are planar by Geometry Fact 2. At the boundary no cone fixes the offset vertex:
/// [`offset_mesh`] places it on the shifted planes of its faces such that every offset edge
/// is parallel to its original edge, so the beams touching the boundary are planar too
/// (their "axes" are the lines from each boundary vertex to its offset).
pub fn support_structure(
    mesh: &PolyMesh,
    distance: f64,
) -> Result<(PolyMesh, PolyMesh), OffsetError> {
    let offset = offset_mesh(mesh, distance)?;
    let topo = MeshTopology::new(mesh)?;
    let n = mesh.num_vertices() as u32;
    let mut positions = mesh.positions.clone();
    positions.extend_from_slice(&offset.positions);
    let faces: Vec<[u32; 4]> = topo
        .edges()
        .into_iter()
        .map(|(a, b)| [a, b, b + n, a + n])
        .collect();
    let beams = PolyMesh::new(positions, faces).map_err(|_| OffsetError::DegenerateFace(0))?;
    Ok((beams, offset))
}
