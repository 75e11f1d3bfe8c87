//! Polygon meshes of any face size, stored compactly (one index array plus face offsets).

use crate::Vec3;
use std::collections::BTreeMap;
use thiserror::Error;

/// Why a polygon mesh was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// A face names a vertex index that does not exist.
    #[error("face {face} refers to vertex {index}, but the mesh has only {vertices} vertices")]
    IndexOutOfRange {
        /// Face number (0-based).
        face: usize,
        /// The offending vertex index (0-based).
        index: usize,
        /// Number of vertices in the mesh.
        vertices: usize,
    },
    /// A face has fewer than three corners.
    #[error("face {face} has {size} vertices; a face needs at least 3")]
    FaceTooSmall {
        /// Face number (0-based).
        face: usize,
        /// Its number of corners.
        size: usize,
    },
    /// A face visits the same vertex twice.
    #[error("face {face} repeats vertex {index}")]
    RepeatedVertex {
        /// Face number (0-based).
        face: usize,
        /// The repeated vertex index (0-based).
        index: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Vertex number (0-based).
        vertex: usize,
    },
}

/// A polygon mesh: vertex positions and faces of any size (triangles, quads, hexagons, mixed).
///
/// Faces are stored as one flat index array with offsets, so a mesh of 50k hexagons is two
/// allocations, not 50k.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Where each face starts in `face_verts`, then where the last one ends (so never empty).
    face_start: Vec<u32>,
    face_verts: Vec<u32>,
}

/// The empty mesh, as `PolyMesh::new` builds it from no vertices and no faces.
impl Default for PolyMesh {
    fn default() -> Self {
        PolyMesh {
            positions: Vec::new(),
            face_start: vec![0],
            face_verts: Vec::new(),
        }
    }
}

impl PolyMesh {
    /// Builds a mesh, checking that every face has at least three distinct, existing vertices and
    /// that every coordinate is finite.
    pub fn new<F, I>(positions: Vec<Vec3>, faces: F) -> Result<Self, MeshError>
    where
        F: IntoIterator<Item = I>,
        I: AsRef<[u32]>,
    {
        if let Some(vertex) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFiniteVertex { vertex });
        }
        let mut mesh = PolyMesh {
            positions,
            face_start: vec![0],
            face_verts: Vec::new(),
        };
        for (face, f) in faces.into_iter().enumerate() {
            let f = f.as_ref();
            if f.len() < 3 {
                return Err(MeshError::FaceTooSmall {
                    face,
                    size: f.len(),
                });
            }
            for (k, &i) in f.iter().enumerate() {
                if i as usize >= mesh.positions.len() {
                    return Err(MeshError::IndexOutOfRange {
                        face,
                        index: i as usize,
                        vertices: mesh.positions.len(),
                    });
                }
                if f[..k].contains(&i) {
                    return Err(MeshError::RepeatedVertex {
                        face,
                        index: i as usize,
                    });
                }
            }
            mesh.face_verts.extend_from_slice(f);
            mesh.face_start.push(mesh.face_verts.len() as u32);
        }
        Ok(mesh)
    }

    /// The `nu` x `nv` quad grid over `positions` in row order (vertex (i, j) at
    /// `j * (nu + 1) + i`, so `(nu + 1) * (nv + 1)` of them), quads (i, j), (i + 1, j),
    /// (i + 1, j + 1), (i, j + 1): counter-clockwise where (i, j) is right-handed.
    pub fn quad_grid(positions: Vec<Vec3>, nu: usize, nv: usize) -> Result<Self, MeshError> {
        let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
        let faces: Vec<[u32; 4]> = (0..nv)
            .flat_map(|j| {
                (0..nu).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
            })
            .collect();
        PolyMesh::new(positions, faces)
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_start.len() - 1
    }

    /// The vertex indices of face `i`, in order.
    pub fn face(&self, i: usize) -> &[u32] {
        &self.face_verts[self.face_start[i] as usize..self.face_start[i + 1] as usize]
    }

    /// Iterates over all faces.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        (0..self.num_faces()).map(move |i| self.face(i))
    }

    /// Whether this mesh's first faces are `earlier`'s faces, corner for corner (positions are
    /// not compared): a mesh that grew by faces starts with the faces it had.
    pub fn starts_with_faces_of(&self, earlier: &PolyMesh) -> bool {
        let (starts, corners) = (earlier.face_start.len(), earlier.face_verts.len());
        self.face_start.get(..starts) == Some(&earlier.face_start[..])
            && self.face_verts.get(..corners) == Some(&earlier.face_verts[..])
    }

    /// Histogram of face sizes: polygon size -> number of faces.
    pub fn face_sizes(&self) -> BTreeMap<usize, usize> {
        let mut h = BTreeMap::new();
        for f in self.faces() {
            *h.entry(f.len()).or_insert(0) += 1;
        }
        h
    }

    /// Length of the diagonal of the axis-aligned bounding box (0 for an empty mesh), finite for
    /// any finite coordinates.
    pub fn bbox_diagonal(&self) -> f64 {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in &self.positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if self.positions.is_empty() {
            return 0.0;
        }
        robust_norm(hi - lo)
    }

    /// Mean edge length over all faces, each face's edges counted once per face (an interior
    /// edge twice); 0 for a mesh without faces. The mesh's scale, e.g. to size panels.
    pub fn mean_edge(&self) -> f64 {
        let (sum, n) = self.sum_edge_lengths(0, (0.0, 0));
        if n == 0 { 0.0 } else { sum / n as f64 }
    }

    /// Adds the edge lengths of faces `from..` (each face's edges, in face order) to the
    /// running `(sum, count)`: a mesh that grows by faces keeps [`PolyMesh::mean_edge`]'s sum
    /// bit for bit by adding its new faces.
    pub fn sum_edge_lengths(&self, from: usize, (mut sum, mut n): (f64, usize)) -> (f64, usize) {
        for i in from..self.num_faces() {
            let f = self.face(i);
            for k in 0..f.len() {
                sum += (self.positions[f[(k + 1) % f.len()] as usize]
                    - self.positions[f[k] as usize])
                    .norm();
                n += 1;
            }
        }
        (sum, n)
    }

    /// Mean length of the edges of face `i`.
    pub fn face_mean_edge(&self, i: usize) -> f64 {
        let f = self.face(i);
        let n = f.len();
        (0..n)
            .map(|k| {
                robust_norm(self.positions[f[(k + 1) % n] as usize] - self.positions[f[k] as usize])
            })
            .sum::<f64>()
            / n as f64
    }
}

/// The length of `d`, also where its squared components overflow (past 1e154) or lose digits
/// to subnormals (below 1e-154); the same bits as `d.norm()` in between.
pub(crate) fn robust_norm(d: Vec3) -> f64 {
    let n = d.norm();
    if n.is_finite() && n > 1e-150 {
        return n;
    }
    let s = d.amax();
    if s > 0.0 && s.is_finite() {
        s * (d / s).norm()
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn builds_and_reports_sizes() {
        let m = PolyMesh::new(square(), [[0u32, 1, 2, 3]]).unwrap();
        assert_eq!(m.num_faces(), 1);
        assert_eq!(m.face(0), &[0, 1, 2, 3]);
        assert_eq!(m.face_sizes().get(&4), Some(&1));
        assert!((m.bbox_diagonal() - 2f64.sqrt()).abs() < 1e-15);
        assert!((m.face_mean_edge(0) - 1.0).abs() < 1e-15);
    }

    /// The default mesh is the empty one `new` builds: no faces, no vertices (not a panic).
    #[test]
    fn the_default_mesh_is_the_empty_one() {
        let empty = PolyMesh::default();
        assert_eq!(
            empty,
            PolyMesh::new(vec![], Vec::<[u32; 3]>::new()).unwrap()
        );
        assert_eq!((empty.num_faces(), empty.num_vertices()), (0, 0));
        assert_eq!(empty.faces().count(), 0);
    }

    /// A mesh starts with its own faces, the faces of a first part of them and the empty
    /// mesh's; not with faces that differ in a corner, in size or in number.
    #[test]
    fn starts_with_the_faces_it_grew_from() {
        let p = || {
            let mut p = square();
            p.push(Vec3::new(2.0, 0.5, 0.0));
            p
        };
        let grown = PolyMesh::new(p(), [vec![0u32, 1, 2, 3], vec![1, 4, 2]]).unwrap();
        let first = PolyMesh::new(p(), [[0u32, 1, 2, 3]]).unwrap();
        assert!(grown.starts_with_faces_of(&grown));
        assert!(grown.starts_with_faces_of(&first));
        assert!(grown.starts_with_faces_of(&PolyMesh::default()));
        assert!(!first.starts_with_faces_of(&grown));
        for other in [
            PolyMesh::new(p(), [[0u32, 1, 2, 4]]).unwrap(),
            PolyMesh::new(p(), [[0u32, 1, 2]]).unwrap(),
            PolyMesh::new(p(), [[1u32, 2, 3, 0]]).unwrap(),
        ] {
            assert!(!grown.starts_with_faces_of(&other), "{other:?}");
        }
    }

    #[test]
    fn rejects_bad_faces() {
        assert!(matches!(
            PolyMesh::new(square(), [[0u32, 1, 7]]),
            Err(MeshError::IndexOutOfRange { index: 7, .. })
        ));
        assert!(matches!(
            PolyMesh::new(square(), [[0u32, 1]]),
            Err(MeshError::FaceTooSmall { size: 2, .. })
        ));
        assert!(matches!(
            PolyMesh::new(square(), [[0u32, 1, 0]]),
            Err(MeshError::RepeatedVertex { index: 0, .. })
        ));
        let mut p = square();
        p[2].x = f64::NAN;
        assert!(matches!(
            PolyMesh::new(p, [[0u32, 1, 2]]),
            Err(MeshError::NonFiniteVertex { vertex: 2 })
        ));
    }
}
