//! Plain triangle buffers for renderers (lyon's idea: the core hands out buffers and never
//! knows who draws them).

use crate::Vec3;
use crate::mesh::PolyMesh;

/// An indexed triangle list with per-vertex normals, in `f32` as GPUs want them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleBuffers {
    /// x, y, z per vertex.
    pub positions: Vec<f32>,
    /// Unit normal per vertex.
    pub normals: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise seen from the normal side.
    pub indices: Vec<u32>,
}

impl TriangleBuffers {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len() / 3
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// Flat-shaded triangle buffers of a polygon mesh: each face is fanned from its first vertex
/// with its own vertices (so panels read as flat), the normal being the face's area vector.
/// `face_colors`, if given, holds one linear RGB triple per face; the result's second part is
/// then one RGB triple per output vertex (empty otherwise).
pub fn polymesh_buffers(
    mesh: &PolyMesh,
    face_colors: Option<&[[f32; 3]]>,
) -> (TriangleBuffers, Vec<f32>) {
    let mut out = TriangleBuffers::default();
    let mut colors = Vec::new();
    for (fi, f) in mesh.faces().enumerate() {
        let p: Vec<Vec3> = f.iter().map(|&v| mesh.positions[v as usize]).collect();
        // Newell's normal: robust for non-planar and non-convex polygons.
        let mut n = Vec3::zeros();
        for k in 0..p.len() {
            n += p[k].cross(&p[(k + 1) % p.len()]);
        }
        let n = n.try_normalize(0.0).unwrap_or_else(Vec3::z);
        let base = out.vertex_count() as u32;
        for q in &p {
            out.positions.extend([q.x as f32, q.y as f32, q.z as f32]);
            out.normals.extend([n.x as f32, n.y as f32, n.z as f32]);
            if let Some(c) = face_colors.and_then(|c| c.get(fi)) {
                colors.extend(c);
            }
        }
        for k in 1..p.len() as u32 - 1 {
            out.indices.extend([base, base + k, base + k + 1]);
        }
    }
    (out, colors)
}

/// Every edge of a polygon mesh once, as pairs of `[x, y, z]` endpoints (6 floats an edge), for
/// drawing panel frames.
pub fn polymesh_edges(mesh: &PolyMesh) -> Vec<f32> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for f in mesh.faces() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            if seen.insert((a.min(b), a.max(b))) {
                for v in [a, b] {
                    let q = mesh.positions[v as usize];
                    out.extend([q.x as f32, q.y as f32, q.z as f32]);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polymesh_buffers_fan_faces_and_list_edges_once() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.5, 0.0),
        ];
        let m = crate::mesh::PolyMesh::new(p, [vec![0u32, 1, 2, 3], vec![1, 4, 2]]).unwrap();
        let (b, c) = polymesh_buffers(&m, Some(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
        assert_eq!(b.vertex_count(), 7);
        assert_eq!(b.triangle_count(), 3);
        assert_eq!(c.len(), 21);
        assert_eq!(&c[12..15], &[0.0, 1.0, 0.0]);
        assert!(b.normals.chunks(3).all(|n| n == [0.0, 0.0, 1.0]));
        // 4 + 3 edges, the shared edge 1-2 once.
        assert_eq!(polymesh_edges(&m).len(), 6 * 6);
    }
}
