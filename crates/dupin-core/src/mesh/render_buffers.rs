//! Plain triangle buffers for renderers (lyon's idea: the core hands out buffers and never
//! knows who draws them).

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::surface::Surface;

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

/// Samples `surface` on an `nu` x `nv` grid of its domain into a triangle mesh with analytic
/// vertex normals. Periodic directions are closed (the seam shares its vertices).
///
/// `nu` and `nv` are clamped to at least 2 cells (3 when the direction is periodic).
pub fn sample_surface(surface: &dyn Surface, nu: usize, nv: usize) -> TriangleBuffers {
    let d = surface.domain();
    let nu = nu.max(if d.periodic_u { 3 } else { 2 });
    let nv = nv.max(if d.periodic_v { 3 } else { 2 });
    // Number of distinct vertex columns/rows: a periodic direction reuses the first one.
    let cu = if d.periodic_u { nu } else { nu + 1 };
    let cv = if d.periodic_v { nv } else { nv + 1 };
    let mut out = TriangleBuffers::default();
    out.positions.reserve(cu * cv * 3);
    out.normals.reserve(cu * cv * 3);
    for j in 0..cv {
        let v = d.v.0 + (d.v.1 - d.v.0) * j as f64 / nv as f64;
        for i in 0..cu {
            let u = d.u.0 + (d.u.1 - d.u.0) * i as f64 / nu as f64;
            let p = surface.position(u, v);
            let n = surface.normal(u, v);
            out.positions.extend([p.x as f32, p.y as f32, p.z as f32]);
            out.normals.extend([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    let id = |i: usize, j: usize| ((j % cv) * cu + (i % cu)) as u32;
    out.indices.reserve(nu * nv * 6);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, e) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // (u, v) is right-handed with Pu x Pv as normal, so this order is counter-clockwise.
            out.indices.extend([a, b, c, a, c, e]);
        }
    }
    out
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
    use crate::surface::Torus;

    #[test]
    fn torus_sampling_is_closed_and_oriented() {
        let t = Torus {
            major: 2.0,
            minor: 0.5,
        };
        let b = sample_surface(&t, 32, 16);
        assert_eq!(b.vertex_count(), 32 * 16);
        assert_eq!(b.triangle_count(), 2 * 32 * 16);
        // Closed surface: every directed edge appears once, its reverse once.
        let mut edges = std::collections::HashMap::new();
        for tri in b.indices.chunks(3) {
            for k in 0..3 {
                *edges.entry((tri[k], tri[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, c), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(c, a)), Some(&1));
        }
        // Face normals agree with the vertex normals.
        let p = |i: u32| {
            let i = i as usize * 3;
            Vec3::new(
                b.positions[i] as f64,
                b.positions[i + 1] as f64,
                b.positions[i + 2] as f64,
            )
        };
        for tri in b.indices.chunks(3) {
            let fnorm = (p(tri[1]) - p(tri[0])).cross(&(p(tri[2]) - p(tri[0])));
            let i = tri[0] as usize * 3;
            let vn = Vec3::new(
                b.normals[i] as f64,
                b.normals[i + 1] as f64,
                b.normals[i + 2] as f64,
            );
            assert!(fnorm.dot(&vn) > 0.0);
        }
        // Every vertex lies on the torus.
        for k in 0..b.vertex_count() {
            let q = p(k as u32);
            let rho = (q.x * q.x + q.y * q.y).sqrt() - 2.0;
            assert!(((rho * rho + q.z * q.z).sqrt() - 0.5).abs() < 1e-6);
        }
    }
    #[test]
    fn polymesh_buffers_fan_faces_and_list_edges_once() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.5, 0.0),
        ];
        let m = crate::PolyMesh::new(p, [vec![0u32, 1, 2, 3], vec![1, 4, 2]]).unwrap();
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
