//! One step of Catmull-Clark subdivision on a polygon mesh with boundary (every face becomes
//! quads). Boundary edges and vertices follow the cubic B-spline curve rule, boundary corners
//! (valence 2) stay fixed, so the boundary is subdivided as a curve.
//!
//! Input: a manifold oriented mesh. Output: the refined quad mesh, same orientation.

use crate::Vec3;
use crate::mesh::PolyMesh;
use crate::mesh::{MeshTopology, TopologyError};
use std::collections::HashMap;

/// One Catmull-Clark step. Vertex `i` of the input keeps index `i` in the output.
pub fn catmull_clark(mesh: &PolyMesh) -> Result<PolyMesh, TopologyError> {
    let topo = MeshTopology::new(mesh)?;
    let p = &mesh.positions;
    let nv = p.len();
    let face_pt: Vec<Vec3> = mesh
        .faces()
        .map(|f| f.iter().map(|&v| p[v as usize]).sum::<Vec3>() / f.len() as f64)
        .collect();
    let mut edge_index: HashMap<(u32, u32), u32> = HashMap::new();
    let mut edge_pts = Vec::new();
    for (a, b) in topo.edges() {
        edge_index.insert((a.min(b), a.max(b)), (nv + edge_pts.len()) as u32);
        edge_pts.push((a, b));
    }
    // Faces on each side of each edge.
    let mut edge_faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, face) in mesh.faces().enumerate() {
        let n = face.len();
        for k in 0..n {
            let (a, b) = (face[k], face[(k + 1) % n]);
            edge_faces.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut positions = Vec::with_capacity(nv + edge_pts.len() + mesh.num_faces());
    for v in 0..nv {
        let star = topo.star(v);
        let nb = topo.neighbors(v);
        let q = if star.is_empty() {
            p[v]
        } else if topo.is_boundary(v) {
            if nb.len() == 2 {
                p[v]
            } else {
                (p[nb[0] as usize] + 6.0 * p[v] + p[nb[nb.len() - 1] as usize]) / 8.0
            }
        } else {
            let n = star.len() as f64;
            let f = star
                .iter()
                .map(|&c| face_pt[topo.face_of(c) as usize])
                .sum::<Vec3>()
                / n;
            let r = nb
                .iter()
                .map(|&u| (p[u as usize] + p[v]) * 0.5)
                .sum::<Vec3>()
                / n;
            (f + 2.0 * r + (n - 3.0) * p[v]) / n
        };
        positions.push(q);
    }
    for &(a, b) in &edge_pts {
        let fs = &edge_faces[&(a.min(b), a.max(b))];
        let mid = (p[a as usize] + p[b as usize]) * 0.5;
        positions.push(if fs.len() == 2 {
            (p[a as usize] + p[b as usize] + face_pt[fs[0]] + face_pt[fs[1]]) / 4.0
        } else {
            mid
        });
    }
    let face_base = positions.len() as u32;
    positions.extend_from_slice(&face_pt);
    let mut faces = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        let n = face.len();
        let e = |i: usize, j: usize| {
            let (a, b) = (face[i], face[j]);
            edge_index[&(a.min(b), a.max(b))]
        };
        #[allow(clippy::needless_range_loop)]
        for k in 0..n {
            faces.push([
                face[k],
                e(k, (k + 1) % n),
                face_base + f as u32,
                e((k + n - 1) % n, k),
            ]);
        }
    }
    Ok(PolyMesh::new(positions, faces).expect("subdivision indices are valid"))
}
