//! Quad meshes along principal curvature lines of analytic surfaces, the starting meshes for
//! conical and circular optimisation (conical paper, Sec. 5: "it is a good choice to use a
//! quad mesh extracted from principal curvature lines").
//!
//! For a surface of revolution the meridians and parallels are the principal curvature lines,
//! so the parameter grid is a principal mesh. [`SurfaceOfRevolution`] is a small local surface
//! type for this (to be unified with the surface library later).

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::surface::{Domain, Surface, SurfaceDerivatives};

/// A surface of revolution about the z axis: (r(v) cos u, r(v) sin u, z(v)).
#[derive(Debug, Clone, Copy)]
pub struct SurfaceOfRevolution {
    /// The profile: v -> \[r, r', r'', z, z', z''\].
    pub profile: fn(f64) -> [f64; 6],
    /// Range of the profile parameter v.
    pub v_range: (f64, f64),
}

impl SurfaceOfRevolution {
    /// A vase-like profile r(v) = 1 + 0.3 sin(2v), z(v) = v, v in \[-1, 1\]: elliptic and
    /// hyperbolic regions.
    pub fn vase() -> Self {
        SurfaceOfRevolution {
            profile: |v| {
                let (s, c) = (2.0 * v).sin_cos();
                [1.0 + 0.3 * s, 0.6 * c, -1.2 * s, v, 1.0, 0.0]
            },
            v_range: (-1.0, 1.0),
        }
    }
}

impl SurfaceOfRevolution {
    /// The footpoint of `q` on the surface (nearest point over the profile range), the
    /// reference-surface projection of the conical paper's closeness term. The nearest point
    /// lies in q's meridian plane, so this is a 1D search over the profile: the best of 64
    /// samples, then Newton on the squared distance, clamped to `v_range`. Returns the
    /// parameters (u, v) and the point.
    pub fn closest_point(&self, q: Vec3) -> (f64, f64, Vec3) {
        let u = q.y.atan2(q.x);
        let rho = q.x.hypot(q.y);
        let (v0, v1) = self.v_range;
        let dist2 = |v: f64| {
            let [r, _, _, z, _, _] = (self.profile)(v);
            (r - rho).powi(2) + (z - q.z).powi(2)
        };
        let mut v = (0..=64)
            .map(|k| v0 + (v1 - v0) * k as f64 / 64.0)
            .min_by(|a, b| dist2(*a).total_cmp(&dist2(*b)))
            .unwrap_or(v0);
        for _ in 0..30 {
            let [r, r1, r2, z, z1, z2] = (self.profile)(v);
            let g = (r - rho) * r1 + (z - q.z) * z1;
            let h = r1 * r1 + z1 * z1 + (r - rho) * r2 + (z - q.z) * z2;
            if h <= 0.0 || !g.is_finite() {
                break;
            }
            let next = (v - g / h).clamp(v0, v1);
            let done = (next - v).abs() <= 1e-15 * (1.0 + v.abs());
            v = next;
            if done {
                break;
            }
        }
        (u, v, self.position(u, v))
    }
}

impl Surface for SurfaceOfRevolution {
    fn domain(&self) -> Domain {
        Domain {
            u: (0.0, std::f64::consts::TAU),
            v: self.v_range,
            periodic_u: true,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let [r, r1, r2, z, z1, z2] = (self.profile)(v);
        let (su, cu) = u.sin_cos();
        SurfaceDerivatives {
            p: Vec3::new(r * cu, r * su, z),
            pu: Vec3::new(-r * su, r * cu, 0.0),
            pv: Vec3::new(r1 * cu, r1 * su, z1),
            puu: Vec3::new(-r * cu, -r * su, 0.0),
            puv: Vec3::new(-r1 * su, r1 * cu, 0.0),
            pvv: Vec3::new(r2 * cu, r2 * su, z2),
        }
    }
}

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
    let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    let faces: Vec<[u32; 4]> = (0..nv)
        .flat_map(|j| {
            (0..nu).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolyMesh::new(p, faces).expect("grid indices are valid")
}

#[cfg(test)]
mod tests {
    use super::*;

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
