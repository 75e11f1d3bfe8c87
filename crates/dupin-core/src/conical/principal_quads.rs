//! Quad meshes along principal curvature lines of analytic surfaces, the starting meshes for
//! conical and circular optimisation (conical paper, Sec. 5: "it is a good choice to use a
//! quad mesh extracted from principal curvature lines").
//!
//! For a surface of revolution the meridians and parallels are the principal curvature lines,
//! so the parameter grid is a principal mesh ([`crate::surface::SurfaceOfRevolution`]).

use crate::mesh::PolyMesh;
use crate::surface::Surface;

/// The `nu x nv` quad grid of parameter lines over `u_range x v_range` of a surface whose
/// parameter lines are principal curvature lines (surfaces of revolution, the torus), oriented
/// along Pu x Pv. Vertex (i, j) has index `j * (nu + 1) + i`.
pub fn principal_quad_mesh(
    surface: &dyn Surface,
    u_range: (f64, f64),
    v_range: (f64, f64),
    nu: usize,
    nv: usize,
) -> PolyMesh {
    let (nu, nv) = (nu.max(1), nv.max(1));
    let mut p = Vec::with_capacity((nu + 1) * (nv + 1));
    for j in 0..=nv {
        for i in 0..=nu {
            let u = u_range.0 + (u_range.1 - u_range.0) * i as f64 / nu as f64;
            let v = v_range.0 + (v_range.1 - v_range.0) * j as f64 / nv as f64;
            p.push(surface.position(u, v));
        }
    }
    PolyMesh::quad_grid(p, nu, nv).expect("grid indices are valid")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::SurfaceOfRevolution;

    #[test]
    fn vase_derivatives_match_finite_differences() {
        let s = SurfaceOfRevolution::vase();
        let h = 1e-6;
        for &(u, v) in &[(0.3, -0.4), (2.0, 0.7)] {
            let d = s.derivatives(u, v);
            let fu = (s.position(u + h, v) - s.position(u - h, v)) / (2.0 * h);
            let fv = (s.position(u, v + h) - s.position(u, v - h)) / (2.0 * h);
            let fvv = (s.derivatives(u, v + h).pv - s.derivatives(u, v - h).pv) / (2.0 * h);
            assert!((fu - d.pu).norm() < 1e-8 && (fv - d.pv).norm() < 1e-8);
            assert!((fvv - d.pvv).norm() < 1e-7);
        }
    }

    #[test]
    fn closest_point_is_the_normal_footpoint() {
        let s = SurfaceOfRevolution::vase();
        for &(u, v, h) in &[(0.3, -0.4, 0.05), (2.0, 0.7, -0.1), (-1.0, 0.0, 0.02)] {
            let d = s.derivatives(u, v);
            let n = d.pu.cross(&d.pv).normalize();
            let (cu, cv, p) = s.closest_point(d.p + h * n);
            assert!(
                (cu - u).abs() < 1e-12 && (cv - v).abs() < 1e-10,
                "{cu} {cv}"
            );
            assert!((p - d.p).norm() < 1e-10);
        }
    }
}
