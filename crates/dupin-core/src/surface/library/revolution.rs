//! Surfaces of revolution given by a profile function: the principal-line test surfaces of the
//! conical paper (Sec. 5: meridians and parallels are principal curvature lines).

use crate::Vec3;
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
