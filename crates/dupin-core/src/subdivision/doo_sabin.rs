//! One step of Doo-Sabin subdivision on a polygon mesh with boundary. Each face corner gets a
//! new vertex, the average of the corner, the face centroid and the two edge midpoints at the
//! corner. New faces: a shrunken copy of every face, a quad for every interior edge and a
//! polygon for every interior vertex; boundary edges and vertices produce no face, so the
//! surface shrinks slightly at its boundary, as the Doo-Sabin limit does.
//!
//! Input: a manifold oriented mesh. Output: the refined mesh, same orientation.

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::mesh_topology::{MeshTopology, TopologyError};

/// One Doo-Sabin step. The new vertices are indexed by face corner (face-major order).
pub fn doo_sabin(mesh: &PolyMesh) -> Result<PolyMesh, TopologyError> {
    let topo = MeshTopology::new(mesh)?;
    let p = &mesh.positions;
    let mut positions = Vec::new();
    let mut corner_base = Vec::with_capacity(mesh.num_faces());
    for face in mesh.faces() {
        let n = face.len();
        corner_base.push(positions.len() as u32);
        let c = face.iter().map(|&v| p[v as usize]).sum::<Vec3>() / n as f64;
        for k in 0..n {
            let v = p[face[k] as usize];
            let m1 = (v + p[face[(k + 1) % n] as usize]) * 0.5;
            let m0 = (v + p[face[(k + n - 1) % n] as usize]) * 0.5;
            positions.push((v + c + m0 + m1) / 4.0);
        }
    }
    // Global corner id: corner c of the topology is the same face-major numbering.
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        faces.push((0..face.len() as u32).map(|k| corner_base[f] + k).collect());
    }
    let new_of = |c: u32| c; // topology corners are numbered face-major, like the new vertices
    let nc = positions.len() as u32;
    for c in 0..nc {
        if let Some(o) = topo.opposite(c)
            && o > c
        {
            // c: a -> b in face f, o: b -> a in face g.
            let (af, bf) = (new_of(c), new_of(topo.next(c)));
            let (bg, ag) = (new_of(o), new_of(topo.next(o)));
            faces.push(vec![bf, af, ag, bg]);
        }
    }
    for v in 0..mesh.num_vertices() {
        if !topo.is_boundary(v) && topo.star(v).len() >= 3 {
            faces.push(topo.star(v).iter().map(|&c| new_of(c)).collect());
        }
    }
    Ok(PolyMesh::new(positions, faces).expect("subdivision indices are valid"))
}
