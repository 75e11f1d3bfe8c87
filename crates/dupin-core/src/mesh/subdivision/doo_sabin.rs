//! One step of Doo-Sabin subdivision on a polygon mesh with boundary (conical paper, Sec. 3:
//! "polygon meshes with boundary"). Each face corner gets a new vertex, the average of the
//! corner, the face centroid and the two edge midpoints at the corner. New faces: a shrunken
//! copy of every face, a quad for every edge and a polygon for every vertex.
//!
//! At the boundary each edge (a, b) gets the two Chaikin points `3/4 a + 1/4 b` and
//! `1/4 a + 3/4 b`; the boundary edge's quad runs between the face's two new corners and these
//! points, and a boundary vertex's polygon runs through its corners in its faces and the
//! Chaikin points on its two boundary edges. So no face is dropped (F + E + V faces in all)
//! and the new boundary polygon is exactly Chaikin's refinement of the old one (converging to
//! its quadratic B-spline, the boundary curve of the Doo-Sabin limit).
//!
//! Input: a manifold oriented mesh. Output: the refined mesh, same orientation.

use crate::Vec3;
use crate::mesh::PolyMesh;
use crate::mesh::{MeshTopology, TopologyError};

/// One Doo-Sabin step. The first new vertices are indexed by face corner (face-major order),
/// followed by two Chaikin points per boundary edge (in corner order).
pub fn doo_sabin(mesh: &PolyMesh) -> Result<PolyMesh, TopologyError> {
    let topo = MeshTopology::new(mesh)?;
    let p = &mesh.positions;
    let mut positions = Vec::new();
    for face in mesh.faces() {
        let n = face.len();
        let c = face.iter().map(|&v| p[v as usize]).sum::<Vec3>() / n as f64;
        for k in 0..n {
            let v = p[face[k] as usize];
            let m1 = (v + p[face[(k + 1) % n] as usize]) * 0.5;
            let m0 = (v + p[face[(k + n - 1) % n] as usize]) * 0.5;
            positions.push((v + c + m0 + m1) / 4.0);
        }
    }
    // Topology corners are numbered face-major, like the new corner vertices: corner c's new
    // vertex is c. Per boundary halfedge c (a -> b): Chaikin points near a and near b.
    let nc = positions.len() as u32;
    let mut chaikin = vec![(u32::MAX, u32::MAX); nc as usize];
    for c in 0..nc {
        if topo.opposite(c).is_none() {
            let (a, b) = (p[topo.source(c) as usize], p[topo.target(c) as usize]);
            let i = positions.len() as u32;
            positions.push(0.75 * a + 0.25 * b);
            positions.push(0.25 * a + 0.75 * b);
            chaikin[c as usize] = (i, i + 1);
        }
    }
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut first = 0u32;
    for face in mesh.faces() {
        faces.push((first..first + face.len() as u32).collect());
        first += face.len() as u32;
    }
    for c in 0..nc {
        // c: a -> b in face f.
        let (af, bf) = (c, topo.next(c));
        match topo.opposite(c) {
            // o: b -> a in face g.
            Some(o) if o > c => faces.push(vec![bf, af, topo.next(o), o]),
            Some(_) => {}
            None => {
                let (na, nb) = chaikin[c as usize];
                faces.push(vec![bf, af, na, nb]);
            }
        }
    }
    for v in 0..mesh.num_vertices() {
        let star = topo.star(v);
        if star.is_empty() {
            continue;
        }
        let mut poly: Vec<u32> = star.to_vec();
        if topo.is_boundary(v) {
            // The star starts with the outgoing boundary halfedge and ends with the face of
            // the incoming one: close the polygon through the two Chaikin points next to v.
            let incoming = topo.prev(*star.last().expect("non-empty star"));
            poly.push(chaikin[incoming as usize].1);
            poly.push(chaikin[star[0] as usize].0);
        } else if star.len() < 3 {
            continue;
        }
        faces.push(poly);
    }
    Ok(PolyMesh::new(positions, faces).expect("subdivision indices are valid"))
}
