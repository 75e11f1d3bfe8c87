//! A smooth surface sampled into triangle buffers for drawing (the page's surface preview).

use crate::mesh::TriangleBuffers;
use crate::surface::Surface;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
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
}
