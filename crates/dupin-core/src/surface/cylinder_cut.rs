//! A triangle mesh of cylinder topology (a tube, a vault closed around, an exported surface of
//! revolution: two boundary loops, Euler characteristic 0) cut open into a disk along a seam, so
//! that [`super::fit_mesh_surface`] fits it like a roof: the seam becomes two opposite sides of
//! the parameter square, the loops the other two. The surface is then panelled as an open patch
//! with a seam, as a closed NURBS surface from a CAD tool is.
//!
//! The seam is the shortest edge path from one loop to the other through interior vertices
//! (Dijkstra on edge lengths): a short, straight seam keeps the mean-value map's distortion
//! low. Its vertices are doubled; every triangle on the left of the path (walking from the
//! first loop to the second) takes the copies.
//!
//! Written here rather than taken from a crate: the cut works on this crate's halfedge
//! [`MeshTopology`] (the mesh-processing crates on crates.io bring their own mesh types).

use crate::mesh::{MeshTopology, PolyMesh};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A cylinder cut open into a disk.
pub(crate) struct CutOpen {
    /// The disk: the input's vertices with the same indices, then a copy of every seam vertex.
    pub mesh: PolyMesh,
    /// The input vertex of every disk vertex.
    pub origin: Vec<u32>,
    /// The seam's two ends on the loops and their copies (disk vertex indices): the corners the
    /// parameter square takes.
    pub ends: [u32; 4],
}

/// A distance ordered by `total_cmp` (Dijkstra's heap key; edge lengths are finite).
#[derive(Clone, Copy, PartialEq)]
struct Dist(f64);

impl Eq for Dist {}

impl PartialOrd for Dist {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Dist {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The shortest edge path from a vertex of `from` to a vertex of `to` whose inner vertices are
/// interior (not on any boundary). `None` when there is none.
fn seam_path(mesh: &PolyMesh, topo: &MeshTopology, from: &[u32], to: &[u32]) -> Option<Vec<u32>> {
    let n = mesh.num_vertices();
    let mut goal = vec![false; n];
    for &v in to {
        goal[v as usize] = true;
    }
    let mut dist = vec![f64::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut heap = BinaryHeap::new();
    for &v in from {
        dist[v as usize] = 0.0;
        heap.push(Reverse((Dist(0.0), v)));
    }
    while let Some(Reverse((Dist(d), v))) = heap.pop() {
        let vi = v as usize;
        if d > dist[vi] {
            continue;
        }
        if goal[vi] {
            let mut path = vec![v];
            let mut w = v;
            while parent[w as usize] != u32::MAX {
                w = parent[w as usize];
                path.push(w);
            }
            path.reverse();
            return Some(path);
        }
        // Only the start leaves a boundary vertex: the path crosses the interior.
        if topo.is_boundary(vi) && dist[vi] > 0.0 {
            continue;
        }
        for w in topo.neighbors(vi) {
            let wi = w as usize;
            if topo.is_boundary(wi) && !goal[wi] {
                continue;
            }
            let nd = d + (mesh.positions[wi] - mesh.positions[vi]).norm();
            if nd < dist[wi] {
                dist[wi] = nd;
                parent[wi] = v;
                heap.push(Reverse((Dist(nd), w)));
            }
        }
    }
    None
}

/// Cuts a mesh with the two boundary `loops` open along a seam between them. `None` when no
/// path joins the loops through the interior (then the caller reports the topology).
pub(crate) fn cut_open_cylinder(
    mesh: &PolyMesh,
    topo: &MeshTopology,
    loops: &[Vec<u32>; 2],
) -> Option<CutOpen> {
    let path = seam_path(mesh, topo, &loops[0], &loops[1])?;
    let n = mesh.num_vertices();
    let mut faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
    let mut positions = mesh.positions.clone();
    let mut origin: Vec<u32> = (0..n as u32).collect();
    let k = path.len() - 1;
    for (i, &v) in path.iter().enumerate() {
        // The star in rotation order; face j lies between the edges to target(star[j]) and to
        // target(star[j + 1]). The left side runs from the edge to the next path vertex to the
        // edge to the previous one (a boundary vertex's fan ends at the boundary instead).
        let star = topo.star(v as usize);
        let at = |w: u32| star.iter().position(|&c| topo.target(c) == w);
        let start = if i < k { at(path[i + 1])? } else { 0 };
        let end = if i > 0 { at(path[i - 1])? } else { star.len() };
        let copy = positions.len() as u32;
        positions.push(mesh.positions[v as usize]);
        origin.push(v);
        let mut j = start;
        loop {
            let f = topo.face_of(star[j]) as usize;
            for x in faces[f].iter_mut().filter(|x| **x == v) {
                *x = copy;
            }
            j = (j + 1) % star.len();
            if j == end % star.len() {
                break;
            }
        }
    }
    let copy_of = |i: usize| (n + i) as u32;
    let mesh = PolyMesh::new(positions, faces).ok()?;
    Some(CutOpen {
        mesh,
        origin,
        ends: [path[0], copy_of(0), path[k], copy_of(k)],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    /// An open tube of `nu` x `nv` quads split into triangles, around the z axis.
    fn tube(nu: usize, nv: usize) -> PolyMesh {
        let positions: Vec<Vec3> = (0..=nv)
            .flat_map(|j| {
                (0..nu).map(move |i| {
                    let a = std::f64::consts::TAU * i as f64 / nu as f64;
                    Vec3::new(a.cos(), a.sin(), j as f64 * 0.3)
                })
            })
            .collect();
        let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
        let faces: Vec<Vec<u32>> = (0..nv)
            .flat_map(|j| {
                (0..nu).flat_map(move |i| {
                    [
                        vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                        vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                    ]
                })
            })
            .collect();
        PolyMesh::new(positions, faces).unwrap()
    }

    #[test]
    fn a_tube_cut_open_is_a_disk_with_the_seam_doubled() {
        let mesh = tube(12, 6);
        let topo = MeshTopology::new(&mesh).unwrap();
        let loops = super::super::mesh_fit::boundary_loops(&mesh, &topo);
        assert_eq!(loops.len(), 2);
        let cut = cut_open_cylinder(&mesh, &topo, &[loops[0].clone(), loops[1].clone()]).unwrap();
        let t = MeshTopology::new(&cut.mesh).unwrap();
        let disk_loops = super::super::mesh_fit::boundary_loops(&cut.mesh, &t);
        assert_eq!(disk_loops.len(), 1, "one boundary loop");
        let euler =
            cut.mesh.num_vertices() as i64 - t.edges().len() as i64 + cut.mesh.num_faces() as i64;
        assert_eq!(euler, 1, "a disk");
        // The seam runs straight up (7 vertices, 6 edges of 0.3), and every copy sits on its
        // original; the loops and the seam's two sides make the disk's boundary.
        let seam = cut.mesh.num_vertices() - mesh.num_vertices();
        assert_eq!(seam, 7);
        for (d, &o) in cut.origin.iter().enumerate() {
            assert_eq!(cut.mesh.positions[d], mesh.positions[o as usize]);
        }
        assert_eq!(disk_loops[0].len(), 12 + 1 + 12 + 1 + 2 * 5);
        for e in cut.ends {
            assert!(disk_loops[0].contains(&e));
        }
        assert_eq!(cut.mesh.num_faces(), mesh.num_faces());
    }
}
