//! Halfedge adjacency of a [`PolyMesh`] with the checks every optimisation needs first: each
//! edge in at most two faces, consistently oriented neighbours, vertex stars that are single
//! fans, no zero-length edges.
//!
//! Halfedges are the face corners: corner `k` of face `f` is the halfedge from `face(f)[k]` to
//! `face(f)[k + 1]`.

use crate::mesh::PolyMesh;
use std::collections::HashMap;
use thiserror::Error;

const NONE: u32 = u32::MAX;

/// Why a mesh is not an oriented 2-manifold (with boundary) the optimisers can work on.
///
/// Messages number vertices and faces from 1, as OBJ files do; the fields are 0-based.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TopologyError {
    /// An edge is shared by more than two faces.
    #[error(
        "the edge between vertices {} and {} is shared by more than two faces (non-manifold)",
        .a + 1,
        .b + 1
    )]
    NonManifoldEdge {
        /// One endpoint (0-based vertex index).
        a: usize,
        /// The other endpoint.
        b: usize,
    },
    /// Two faces traverse a shared edge in the same direction.
    #[error(
        "the faces on both sides of the edge from vertex {} to {} are inconsistently oriented \
         (one of them lists its vertices the other way round)",
        .a + 1,
        .b + 1
    )]
    InconsistentOrientation {
        /// Start of the edge traversed twice in the same direction.
        a: usize,
        /// End of that edge.
        b: usize,
    },
    /// The faces around a vertex do not form one fan (e.g. two cones touching at a vertex).
    #[error("vertex {} is non-manifold: its faces do not form a single fan", .vertex + 1)]
    NonManifoldVertex {
        /// The vertex (0-based).
        vertex: usize,
    },
    /// Two faces list the same vertices in the same cyclic order.
    #[error("face {} repeats face {} (the same vertices in the same order)", .face + 1, .first + 1)]
    DuplicateFace {
        /// The later face (0-based).
        face: usize,
        /// The earlier face it repeats.
        first: usize,
    },
    /// An edge has (numerically) zero length.
    #[error("the edge between vertices {} and {} has zero length", .a + 1, .b + 1)]
    ZeroLengthEdge {
        /// One endpoint.
        a: usize,
        /// The other endpoint.
        b: usize,
    },
}

/// Whether two faces list the same vertices in the same cyclic order.
fn same_cycle(f: &[u32], g: &[u32]) -> bool {
    f.len() == g.len()
        && g.iter()
            .position(|&v| v == f[0])
            .is_some_and(|s| (0..f.len()).all(|k| f[k] == g[(s + k) % g.len()]))
}

/// Halfedge adjacency of a polygon mesh; build with [`MeshTopology::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeshTopology {
    face_start: Vec<u32>,
    corner_face: Vec<u32>,
    corner_vertex: Vec<u32>,
    opposite: Vec<u32>,
    /// Per vertex: outgoing corners in rotation order (start of fan first for boundary vertices).
    fan_start: Vec<u32>,
    fans: Vec<u32>,
    boundary: Vec<bool>,
}

impl MeshTopology {
    /// Builds the adjacency, or says why the mesh is not an oriented manifold.
    ///
    /// Vertices used by no face are allowed (they have an empty star). Edges shorter than
    /// `1e-12` times the bounding-box diagonal count as zero-length.
    pub fn new(mesh: &PolyMesh) -> Result<Self, TopologyError> {
        let mut face_start = Vec::with_capacity(mesh.num_faces() + 1);
        let mut corner_face = Vec::new();
        let mut corner_vertex = Vec::new();
        face_start.push(0u32);
        for (f, face) in mesh.faces().enumerate() {
            for &v in face {
                corner_face.push(f as u32);
                corner_vertex.push(v);
            }
            face_start.push(corner_vertex.len() as u32);
        }
        let nc = corner_vertex.len();
        let tiny = 1e-12 * mesh.bbox_diagonal();
        let mut topo = MeshTopology {
            face_start,
            corner_face,
            corner_vertex,
            opposite: vec![NONE; nc],
            fan_start: Vec::new(),
            fans: Vec::new(),
            boundary: vec![false; mesh.num_vertices()],
        };
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(nc);
        let mut undirected: HashMap<(u32, u32), u8> = HashMap::with_capacity(nc);
        for c in 0..nc as u32 {
            let (a, b) = (topo.source(c), topo.target(c));
            if (mesh.positions[a as usize] - mesh.positions[b as usize]).norm() <= tiny {
                return Err(TopologyError::ZeroLengthEdge {
                    a: a as usize,
                    b: b as usize,
                });
            }
            let count = undirected.entry((a.min(b), a.max(b))).or_insert(0);
            *count += 1;
            if *count > 2 {
                return Err(TopologyError::NonManifoldEdge {
                    a: a.min(b) as usize,
                    b: a.max(b) as usize,
                });
            }
            if let Some(other) = directed.insert((a, b), c) {
                let (f, g) = (
                    topo.corner_face[c as usize],
                    topo.corner_face[other as usize],
                );
                if same_cycle(mesh.face(f as usize), mesh.face(g as usize)) {
                    return Err(TopologyError::DuplicateFace {
                        face: f.max(g) as usize,
                        first: f.min(g) as usize,
                    });
                }
                return Err(TopologyError::InconsistentOrientation {
                    a: a as usize,
                    b: b as usize,
                });
            }
        }
        for c in 0..nc as u32 {
            if let Some(&o) = directed.get(&(topo.target(c), topo.source(c))) {
                topo.opposite[c as usize] = o;
            }
        }
        // Outgoing corners per vertex.
        let nv = mesh.num_vertices();
        let mut out_count = vec![0u32; nv + 1];
        for c in 0..nc {
            out_count[topo.corner_vertex[c] as usize + 1] += 1;
        }
        for v in 0..nv {
            out_count[v + 1] += out_count[v];
        }
        let mut out_any = vec![NONE; nv];
        let mut out_boundary = vec![NONE; nv];
        for c in 0..nc as u32 {
            let v = topo.source(c) as usize;
            out_any[v] = c;
            if topo.opposite[c as usize] == NONE {
                if out_boundary[v] != NONE {
                    // Two boundary edges leave v: two fans meet there.
                    return Err(TopologyError::NonManifoldVertex { vertex: v });
                }
                out_boundary[v] = c;
            }
        }
        topo.fan_start.push(0);
        for v in 0..nv {
            let expected = (out_count[v + 1] - out_count[v]) as usize;
            if expected > 0 {
                let start = if out_boundary[v] != NONE {
                    topo.boundary[v] = true;
                    out_boundary[v]
                } else {
                    out_any[v]
                };
                let mut c = start;
                let mut n = 0;
                loop {
                    topo.fans.push(c);
                    n += 1;
                    let o = topo.opposite[topo.prev(c) as usize];
                    if o == NONE || o == start || n > expected {
                        break;
                    }
                    c = o;
                }
                if n != expected {
                    return Err(TopologyError::NonManifoldVertex { vertex: v });
                }
            }
            topo.fan_start.push(topo.fans.len() as u32);
        }
        Ok(topo)
    }

    /// Vertex a corner (halfedge) starts at.
    #[inline]
    pub fn source(&self, c: u32) -> u32 {
        self.corner_vertex[c as usize]
    }

    /// Face of a corner.
    #[inline]
    pub fn face_of(&self, c: u32) -> u32 {
        self.corner_face[c as usize]
    }

    /// The next corner in the same face.
    #[inline]
    pub fn next(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c + 1 == self.face_start[f + 1] {
            self.face_start[f]
        } else {
            c + 1
        }
    }

    /// The previous corner in the same face.
    #[inline]
    pub fn prev(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c == self.face_start[f] {
            self.face_start[f + 1] - 1
        } else {
            c - 1
        }
    }

    /// Vertex a corner (halfedge) ends at.
    #[inline]
    pub fn target(&self, c: u32) -> u32 {
        self.corner_vertex[self.next(c) as usize]
    }

    /// The opposite halfedge, `None` on the boundary.
    #[inline]
    pub fn opposite(&self, c: u32) -> Option<u32> {
        let o = self.opposite[c as usize];
        (o != NONE).then_some(o)
    }

    /// Whether vertex `v` lies on the boundary.
    #[inline]
    pub fn is_boundary(&self, v: usize) -> bool {
        self.boundary[v]
    }

    /// Outgoing corners of `v` in rotation order (for a boundary vertex, starting with the
    /// outgoing boundary edge). Its faces are `face_of(c)`, its edge neighbours `target(c)`.
    pub fn star(&self, v: usize) -> &[u32] {
        &self.fans[self.fan_start[v] as usize..self.fan_start[v + 1] as usize]
    }

    /// Number of edges at `v`: the star size, plus one for a boundary vertex.
    pub fn valence(&self, v: usize) -> usize {
        self.star(v).len() + usize::from(self.boundary[v])
    }

    /// Edge neighbours of `v` in rotation order (boundary vertices: both boundary neighbours
    /// first and last).
    pub fn neighbors(&self, v: usize) -> Vec<u32> {
        let star = self.star(v);
        let mut out: Vec<u32> = star.iter().map(|&c| self.target(c)).collect();
        if self.boundary[v]
            && let Some(&last) = star.last()
        {
            out.push(self.source(self.prev(last)));
        }
        out
    }

    /// Interior vertices of valence 4: the vertices where the conical condition applies.
    pub fn interior_valence4(&self) -> Vec<usize> {
        (0..self.boundary.len())
            .filter(|&v| !self.boundary[v] && self.star(v).len() == 4)
            .collect()
    }

    /// Undirected edges, each once, as (a, b) with the halfedge's direction.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        (0..self.corner_vertex.len() as u32)
            .filter(|&c| self.opposite[c as usize] == NONE || self.opposite[c as usize] > c)
            .map(|c| (self.source(c), self.target(c)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    fn grid(n: usize) -> PolyMesh {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push(Vec3::new(i as f64, j as f64, 0.0));
            }
        }
        PolyMesh::quad_grid(p, n, n).unwrap()
    }

    #[test]
    fn grid_stars_and_boundary() {
        let m = grid(3);
        let t = MeshTopology::new(&m).unwrap();
        assert_eq!(t.interior_valence4(), vec![5, 6, 9, 10]);
        assert_eq!(t.valence(0), 2);
        assert_eq!(t.valence(1), 3);
        assert!(t.is_boundary(1) && !t.is_boundary(5));
        let mut nb = t.neighbors(5);
        nb.sort();
        assert_eq!(nb, vec![1, 4, 6, 9]);
        // Rotation order: consecutive neighbours share a face, so they are not opposite.
        let nb = t.neighbors(5);
        assert!(nb[0].abs_diff(nb[2]) == 2 || nb[0].abs_diff(nb[2]) == 8);
        assert_eq!(t.edges().len(), 24);
    }

    #[test]
    fn rejects_bad_topology() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
        ];
        let flipped = PolyMesh::new(p.clone(), [[0u32, 1, 2], [0, 1, 3]]).unwrap();
        assert!(matches!(
            MeshTopology::new(&flipped),
            Err(TopologyError::InconsistentOrientation { .. })
        ));
        let fin = PolyMesh::new(p.clone(), [[0u32, 1, 2], [1, 0, 3], [1, 0, 4]]).unwrap();
        assert!(MeshTopology::new(&fin).is_err());
        let mut q = p.clone();
        q[2] = q[1];
        let zero = PolyMesh::new(q, [[0u32, 1, 2]]).unwrap();
        assert!(matches!(
            MeshTopology::new(&zero),
            Err(TopologyError::ZeroLengthEdge { .. })
        ));
        // Two triangles touching only at vertex 0.
        let mut r = p.clone();
        r.push(Vec3::new(-1.0, 0.0, 0.0));
        r.push(Vec3::new(0.0, -1.0, 0.5));
        let bowtie = PolyMesh::new(r, [[0u32, 1, 2], [0, 5, 6]]).unwrap();
        assert!(matches!(
            MeshTopology::new(&bowtie),
            Err(TopologyError::NonManifoldVertex { vertex: 0 })
        ));
    }

    /// Messages count from 1 as OBJ files do, a repeated face is named as such, and edges of
    /// huge meshes are not taken for zero-length ones.
    #[test]
    fn messages_name_faces_and_vertices_from_one() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let twice = PolyMesh::new(p.clone(), [[0u32, 1, 2], [1, 2, 0]]).unwrap();
        let e = MeshTopology::new(&twice).unwrap_err();
        assert_eq!(e, TopologyError::DuplicateFace { face: 1, first: 0 });
        assert_eq!(
            e.to_string(),
            "face 2 repeats face 1 (the same vertices in the same order)"
        );
        let zero = PolyMesh::new(vec![p[0], p[0], p[2]], [[0u32, 1, 2]]).unwrap();
        assert_eq!(
            MeshTopology::new(&zero).unwrap_err().to_string(),
            "the edge between vertices 1 and 2 has zero length"
        );
        let huge: Vec<Vec3> = p.iter().map(|q| q * 1e155).collect();
        let m = PolyMesh::new(huge, [[0u32, 1, 2]]).unwrap();
        assert!((m.bbox_diagonal() / (1e155 * 2f64.sqrt()) - 1.0).abs() < 1e-15);
        assert!(MeshTopology::new(&m).is_ok());
    }
}
